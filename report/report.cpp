// SPDX-License-Identifier: MIT
#include "report.h"

#include <cmath>

#include "summary.h"
#include "trivcon/matching.h"
#include "trivcon/blas.h"
#include "trivcon/tuned_process.h"

#include <cstdlib>
#include <string>

namespace trivcon::cli {

nlohmann::ordered_json solve_report(const ReportRun& run, const MeshData& mesh, const FieldDesigner& designer,
                                    const IndexPrescription& prescription, const Design& d) {
  const Topology& t = designer.topology();
  const Connection& c = d.connection;
  nlohmann::ordered_json report;
  report["mesh"] = mesh_summary(run.mesh_path, mesh, t, designer.geometry());
  if (!run.name.empty()) report["name"] = run.name;
  report["N"] = prescription.N;
  report["weights"] = run.weights;
  report["solver"] = run.solver;
  report["blas_kernels"] = blas_kernels();
  {  // huge pages for malloc's large blocks (trivcon/tuned_process.h)
    const char* tunables = std::getenv("GLIBC_TUNABLES");
    const std::string t = tunables ? tunables : "";
    report["huge_pages"] = {{"kernel", transparent_huge_pages_mode()},
                            {"malloc", t.find("glibc.malloc.hugetlb=1") != std::string::npos || t.find("glibc.malloc.hugetlb=2") != std::string::npos}};
  }
  {  // how long OpenBLAS's idle threads spin (trivcon/tuned_process.h): null where OPENBLAS_THREAD_TIMEOUT is unset
    const char* timeout = std::getenv("OPENBLAS_THREAD_TIMEOUT");
    report["blas_thread_timeout"] = timeout ? nlohmann::ordered_json(timeout) : nlohmann::ordered_json(nullptr);
  }
  {  // how long OpenMP's idle threads spin (trivcon/tuned_process.h): null where GOMP_SPINCOUNT is unset
    const char* spin = std::getenv("GOMP_SPINCOUNT");
    report["openmp_spin_count"] = spin ? nlohmann::ordered_json(spin) : nlohmann::ordered_json(nullptr);
  }
  report["ordering"] = designer.solver().ordering();
  nlohmann::ordered_json sing = nlohmann::ordered_json::array();
  for (auto [v, n] : prescription.vertex) sing.push_back({{"vertex", v}, {"index", format_index(n, prescription.N)}});
  report["singularities"] = sing;
  nlohmann::ordered_json gens = nlohmann::ordered_json::array();
  for (size_t g = 0; g < c.generator_index.size(); ++g)
    gens.push_back({{"id", g},
                    {"component", designer.cycles().generators[g].component},
                    {"index", format_index(c.generator_index[g], prescription.N)},
                    {"chosen", static_cast<bool>(c.generator_chosen[g])}});
  report["generators"] = gens;
  nlohmann::ordered_json loops = nlohmann::ordered_json::array();
  for (size_t l = 0; l < c.loop_index.size(); ++l)
    loops.push_back({{"id", l}, {"index", format_index(c.loop_index[l], prescription.N)}, {"chosen", static_cast<bool>(c.loop_chosen[l])}});
  report["boundary_loops"] = loops;
  nlohmann::ordered_json conflicts = nlohmann::ordered_json::array();
  for (const FixedConflict& k : d.conflicts) conflicts.push_back({{"face_a", k.face_a}, {"face_b", k.face_b}, {"turn", k.turn}});
  report["fixed"] = {{"faces", prescription.fixed.size()},
                     {"align_boundary", run.align_boundary},
                     {"paths", designer.solver().fixed_paths().size()},
                     // How each path's whole turns were chosen (docs/solver.md, "Fixed-face paths").
                     {"path_turns", c.path_turns == Connection::PathTurns::WithTheCycles ? "with the cycles"
                                    : c.path_turns == Connection::PathTurns::FromTheGuide ? "from the guide"
                                                                                         : "smallest"},
                     {"regularized_edges", designer.solver().regularized_edges()},
                     {"max_error", d.max_fixed_error},
                     {"conflicts", conflicts}};
  // The weight policy's work on this solve (the mesh's part is in "mesh"): edges given the small
  // regularization weight, and steps of iterative refinement.
  report["weight_policy"] = {
      {"mollified_faces", designer.geometry().mollified_faces},       {"mollify_epsilon", designer.geometry().mollify_epsilon},
      {"clamped_cotangents", designer.geometry().clamped_cotangents}, {"zero_weight_edges", designer.geometry().zero_weight_edges},
      {"regularized_edges", designer.solver().regularized_edges()},   {"weight_floor", designer.solver_options().weight_floor},
      {"floored_edges", designer.solver().floored_edges()},           {"refinements", c.refinements}};
  report["energy"] = c.energy;
  report["residuals"] = {{"max_vertex", c.max_vertex_residual},
                         {"max_cycle", c.max_cycle_residual},
                         {"rhs_scale", c.rhs_scale},
                         {"transport_mismatch", d.transport_mismatch}};
  nlohmann::ordered_json mism = nlohmann::ordered_json::array();
  for (int v : d.index_mismatch_vertices)
    mism.push_back({{"vertex", v}, {"field_index", format_index(d.indices.vertex[v], prescription.N)}});
  report["indices"] = {{"singular_vertices", prescription.vertex.size()},
                       {"field_mismatches", mism},
                       {"unexplained_mismatches", d.unexplained_mismatch_vertices.size()},
                       {"large_turn_edges", d.large_turn_edges}};
  // Edges turning by π/N or more, and what a tool with its own (principal) matching reads from the field.
  nlohmann::ordered_json turns = nlohmann::ordered_json::array(), consumer = nlohmann::ordered_json::array();
  for (int e : large_turn_edges(t, c.x, prescription.N))
    turns.push_back({{"i", t.edge_vertices(e, 0)}, {"j", t.edge_vertices(e, 1)}, {"x", c.x(e)}});
  for (int v = 0; v < t.num_vertices; ++v)
    if (d.indices.vertex[v] != 0) consumer.push_back({{"vertex", v}, {"index", format_index(d.indices.vertex[v], prescription.N)}});
  report["large_turns"] = {{"edges", turns}, {"principal_matching_singularities", consumer}};
  const PrepareTimings& pt = designer.timings();
  const SetupTimings& st = designer.solver().timings();
  report["symbolic_analysis"] = st.analysis_adopted ? "concurrent" : "in set-up";
  report["seconds"] = {{"read", run.read_seconds},
                       {"topology", pt.topology},
                       {"geometry", pt.geometry},
                       {"cycles", pt.cycles},
                       {"plan", pt.plan},
                       {"analysis", pt.analysis},
                       {"setup", pt.setup},
                       {"setup_assemble", st.assemble},
                       {"setup_analysis_wait", st.analysis_wait},
                       {"setup_factor", st.factor},
                       {"setup_schur", st.schur},
                       {"prepare", pt.prepare},
                       {"solve", d.solve_seconds},
                       {"field", d.field_seconds},
                       {"verify", d.verify_seconds},
                       {"write", run.write_seconds}};
  report["verified"] = run.verified;
  // Whether a reader of the per-face field (closest matching) sees exactly the prescription (Design::field_exact).
  report["field_exact"] = d.field_exact;
  return report;
}

nlohmann::ordered_json param_report(const Parametrization& param) {
  const ParamQuality& q = param.quality;
  auto finite = [](double v) { return std::isfinite(v) ? nlohmann::ordered_json(v) : nlohmann::ordered_json(nullptr); };
  return {{"edge_length", param.edge_length},
          {"seamless", q.seamless},
          {"cones", q.cones},
          {"cut_edges", q.cut_edges},
          {"integer_unknowns", q.integer_unknowns},
          {"rounding_rounds", q.rounding_rounds},
          {"factorizations", q.factorizations},
          {"sizing", sizing_name(q.sizing)},
          {"sizing_rounds", q.sizing_rounds},
          {"small_components", q.small_components},
          {"tiny_components", q.tiny_components},
          {"half_turn_edges", q.half_turn_edges},
          {"first_tiny_face", q.first_tiny_face},
          {"stiffening_rounds", q.stiffening_rounds},
          {"folds_real_valued", q.folds_real_valued},
          {"folds_rounded", q.folds_rounded},
          {"cones_moved", q.cones_moved},
          {"integers_moved", q.integers_moved},
          {"integers_descended", q.integers_descended},
          {"segments_opened", q.segments_opened},
          {"strip_widths", q.strip_widths},
          {"turned_boundary_points", q.turned_boundary_points},
          {"untangled_faces", q.untangled_faces},
          {"untangling_regions", q.untangling_regions},
          {"rewound_regions", q.rewound_regions},
          {"relieved_regions", q.relieved_regions},
          {"shaped_faces", q.shaped_faces},
          {"flipped_faces", q.flipped_faces},
          {"degenerate_faces", q.degenerate_faces},
          {"collapsed_faces", q.collapsed_faces},
          {"winding_errors", q.winding_errors},
          {"attempts", q.attempts},
          {"first_flipped", q.first_flipped},
          {"max_transition_residual", q.max_transition_residual},
          {"max_cone_offset", q.max_cone_offset},
          {"max_cone_angle_error", q.max_cone_angle_error},
          {"aligned_edges", q.aligned_edges},
          {"unaligned_edges", q.unaligned_edges},
          {"max_alignment_error", q.max_alignment_error},
          {"mean_distortion", q.mean_distortion},
          {"max_distortion", finite(q.max_distortion)},  // null: a degenerate (u, v) triangle
          {"unit_squares", q.unit_squares},
          {"target_squares", q.target_squares},
          {"non_unimodular", q.non_unimodular},
          {"seconds", {{"cut", q.seconds_cut}, {"setup", q.seconds_setup}, {"rounding", q.seconds_rounding},
                       {"untangling", q.seconds_untangling}, {"stiffening", q.seconds_stiffening}, {"check", q.seconds_check},
                       {"retries", q.seconds_retries}}}};
}

nlohmann::ordered_json quad_report(const QuadMesh& quads) {
  const QuadQuality& q = quads.quality;
  return {{"quads", q.quads},
          {"vertices", q.vertices},
          {"edges", q.edges},
          {"euler_characteristic", q.euler_characteristic},
          {"input_euler_characteristic", q.input_euler_characteristic},
          {"boundary_loops", q.boundary_loops},
          {"input_boundary_loops", q.input_boundary_loops},
          {"components", q.components},
          {"input_components", q.input_components},
          {"manifold", q.manifold},
          {"oriented", q.oriented},
          {"non_manifold_edges", q.non_manifold_edges},
          {"non_manifold_vertices", q.non_manifold_vertices},
          {"irregular_vertices", q.irregular_vertices},
          {"singular_mismatches", q.singular_mismatches},
          {"inverted_quads", q.inverted_quads},
          {"nonconvex_quads", q.nonconvex_quads},
          {"min_scaled_jacobian", q.min_scaled_jacobian},
          {"mean_scaled_jacobian", q.mean_scaled_jacobian},
          {"hausdorff_relative", q.hausdorff_relative},
          {"target_quads", q.target_quads},
          {"other_faces", quads.other_faces.size()},
          {"extraction",
           {{"integer_points", q.integer_points},
            {"dropped_points", q.dropped_points},
            {"traces", q.traces},
            {"failed_traces", q.failed_traces},
            {"abandoned_traces", q.abandoned_traces},
            {"unmatched_traces", q.unmatched_traces},
            {"non_quad_faces", q.non_quad_faces},
            {"filled_faces", q.filled_faces},
            {"open_faces", q.open_faces},
            {"unused_vertices", q.unused_vertices},
            {"unclosed_vertices", q.unclosed_vertices},
            {"map_folds", q.map_folds},
            {"relaxed_vertices", q.relaxed_vertices}}},
          {"problems", q.problems},
          {"seconds", {{"extract", q.seconds_extract}, {"check", q.seconds_check}}}};
}

}  // namespace trivcon::cli
