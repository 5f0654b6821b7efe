// SPDX-License-Identifier: MIT
// trivcon solve MESH [options]: the smoothest field with exactly the prescribed singularities.
#include <algorithm>
#include <iomanip>
#include <iostream>
#include <memory>
#include <numeric>
#include <optional>
#include <map>
#include <sstream>

#include "batch.h"
#include "commands.h"
#include "field_options.h"
#include "outputs.h"
#include "report.h"
#include "summary.h"
#include "trivcon/auto.h"
#include "trivcon/constraints.h"
#include "trivcon/design.h"
#include "trivcon/error.h"
#include "trivcon/request.h"
#include "trivcon/features.h"
#include "trivcon/generate.h"
#include "trivcon/matching.h"
#include "trivcon/field_io.h"
#include "trivcon/repair.h"

namespace trivcon::cli {

namespace {

struct SolveOptions {
  std::string mesh;
  FieldOptions field;
  std::string sing_batch;
  OutputPaths out;
  bool quiet = false;
  MeshOptions mesh_options;              // --no-repair, --weld
  double tolerance = kDefaultTolerance;  // --tolerance
};

std::string fmt(double v) {
  std::ostringstream s;
  s << std::setprecision(3) << v;
  return s.str();
}

// The feature alignment's report entry and summary line (printed after the mesh's lines); warns of every
// corner conflict.
void report_features(const SolveOptions& o, const FieldDesigner& designer, const RequestConstraints& c, int N,
                     nlohmann::ordered_json& extra, std::string& summary) {
  const Topology& t = designer.topology();
  const FeatureAlignment& a = c.features;
  nlohmann::ordered_json conflicts = nlohmann::ordered_json::array();
  for (const FeatureConflict& k : a.conflicts)
    conflicts.push_back({{"face", k.face},
                         {"followed", {t.edge_vertices(k.followed, 0), t.edge_vertices(k.followed, 1)}},
                         {"other", {t.edge_vertices(k.other, 0), t.edge_vertices(k.other, 1)}},
                         {"difference", k.difference}});
  nlohmann::ordered_json narrow = nlohmann::ordered_json::array();
  for (const NarrowCorner& k : a.narrow)
    narrow.push_back({{"vertex", k.vertex},
                      {"first", {t.edge_vertices(k.first, 0), t.edge_vertices(k.first, 1)}},
                      {"second", {t.edge_vertices(k.second, 0), t.edge_vertices(k.second, 1)}},
                      {"angle", k.angle},
                      {"faces", k.faces}});
  extra["features"] = {{"sharp_edges", c.sharp_edges.size()},
                       {"convex", c.convex_edges},
                       {"fixed_faces", a.fixed.size()},
                       {"corner_faces", a.corner_faces},
                       {"conflicts", conflicts},
                       {"narrow_corners", narrow},
                       {"boundary_overridden", c.boundary_overridden},
                       {"loose_edges", c.loose_edges.size()}};
  if (o.field.features.degrees_option->count() > 0) extra["features"]["degrees"] = o.field.features.degrees;
  if (o.field.features.file_option->count() > 0) extra["features"]["file"] = o.field.features.file;
  std::ostringstream text;
  text << "features: " << c.sharp_edges.size() << " sharp edges (" << c.convex_edges << " convex), " << a.fixed.size()
       << " faces fixed beside them, " << a.corner_faces << " beside two or more\n";
  if (!c.loose_edges.empty()) text << loose_edges_line(c.loose_edges.size(), o.field.feature_min_length);
  if (!a.narrow.empty())
    text << "features: " << a.narrow.size() << " narrow corners (sharp edges meeting at less than pi/N) turned through by one step, "
         << "so that a map gives each a corner of its own (report: features.narrow_corners)\n";
  if (c.boundary_overridden > 0)
    text << "features: " << c.boundary_overridden << " faces beside both a boundary edge and a sharp edge follow the sharp edge\n";
  summary = text.str();
  if (!a.conflicts.empty()) {
    double worst = 0;
    for (const FeatureConflict& k : a.conflicts) worst = std::max(worst, k.difference);
    std::cerr << "trivcon: warning: " << a.conflicts.size() << " face-edge pairs at corners where sharp edges meet that a field of N = " << N
              << " cannot follow both (largest difference " << fmt(worst) << " rad); each such face follows its longest sharp edge";
    const FeatureConflict& k = a.conflicts.front();
    std::cerr << " (e.g. face " << k.face << " follows (" << t.edge_vertices(k.followed, 0) << ", " << t.edge_vertices(k.followed, 1)
              << "), not (" << t.edge_vertices(k.other, 0) << ", " << t.edge_vertices(k.other, 1) << "); report: features.conflicts)\n";
  }
}

// Writes one design's outputs, prints its summary; returns whether verification passed.
// `extra` holds report entries of the whole run (the "auto" or "sing_from_field" object), added to the report.
// `loaded`: the input and its repair, when the design is on that repair (not on a refined mesh).
bool solve_one(const SolveOptions& o, const MeshData& mesh, const FieldDesigner& designer, const IndexPrescription& prescription,
               const Design& d, const std::string& name, double read_seconds, const nlohmann::ordered_json& extra,
               const std::vector<int>& sharp, const LoadedMesh* loaded = nullptr, const std::map<int, int>& corners = {}) {
  const RepairedMesh* repair = loaded ? loaded->repaired() : nullptr;
  const Connection& c = d.connection;

  // Verification: constraint residuals relative to the right-hand sides, transport, fixed faces, indices.
  const double residual = std::max(c.max_vertex_residual, c.max_cycle_residual);
  const std::vector<int>& unexplained = d.unexplained_mismatch_vertices;
  const bool ok = design_verified(d, o.tolerance);

  auto t1 = Clock::now();
  StagedOutputs staged;
  stage_design_outputs(staged, o.out, name, mesh, designer, prescription, d, sharp, repair, repair ? &loaded->input : nullptr, corners);
  const ReportRun run{o.mesh, name, o.field.weights, o.field.solver, o.field.align_boundary, read_seconds, seconds_since(t1), ok};
  if (!o.out.report.empty()) {
    nlohmann::ordered_json report = solve_report(run, mesh, designer, prescription, d);
    for (const auto& [key, value] : extra.items()) report[key] = value;
    staged.write(output_path(o.out.report, name),
                 [&](const std::string& path) { write_file_atomically(path, [&](std::ostream& out) { out << report.dump(2) << "\n"; }); });
  }
  staged.commit();

  if (!o.quiet) {
    if (!name.empty()) std::cout << "== " << name << "\n";
    std::cout << "N " << prescription.N << ", " << prescription.vertex.size() << " singular vertices, weights " << o.field.weights
              << ", solver " << o.field.solver << "\n"
              << (prescription.fixed.empty()
                      ? std::string()
                      : std::to_string(prescription.fixed.size()) + " fixed faces, max deviation " + fmt(d.max_fixed_error) + " rad, " +
                            std::to_string(d.conflicts.size()) + " sharp turns between adjacent fixed faces\n")
              << "energy " << std::setprecision(10) << c.energy << "\n"
              << "max residual " << fmt(residual) << " rad (vertex " << fmt(c.max_vertex_residual) << ", cycles "
              << fmt(c.max_cycle_residual) << "), transport mismatch " << fmt(d.transport_mismatch) << " rad\n"
              << "indices read back from the field: " << d.index_mismatch_vertices.size() << " differ from the prescription";
    if (!d.index_mismatch_vertices.empty())
      std::cout << " (" << d.index_mismatch_vertices.size() - unexplained.size()
                << " at vertices where the connection turns by pi/N or more across an edge, which a per-face field cannot show)";
    std::cout << "\nfield exact: "
              << (d.field_exact ? "yes (read on its own with the closest matching, the per-face field shows exactly the prescribed singularities)"
                                : "NO (read on its own, the per-face field shows other singularities than prescribed: see the warning)");
    std::cout << "\ntime: solve " << fmt(d.solve_seconds) << " s, field " << fmt(d.field_seconds) << " s\n";
  }
  // Where the connection turns by π/N or more, a tool that pairs directions itself sees other indices.
  const std::vector<int> large = large_turn_edges(designer.topology(), c.x, prescription.N);
  if (!large.empty() && !o.quiet) {
    int consumer = 0, differing = 0;
    for (int v = 0; v < designer.topology().num_vertices; ++v) {
      const auto it = prescription.vertex.find(v);
      consumer += d.indices.vertex[v] != 0;
      differing += d.indices.vertex[v] != (it == prescription.vertex.end() ? 0 : it->second);
    }
    std::cerr << "trivcon: warning" << (name.empty() ? "" : " for " + name) << ": " << large.size()
              << " edges turn by pi/N or more; a tool that matches directions itself (Directional, QuadWild, MIQ) will read " << consumer
              << " singular vertices from this field, " << differing
              << " of them differing from the prescription (report: large_turns, field_exact); give it --matching-out, or refine the mesh "
                 "there (--split-large-turns)\n";
  }
  if (repair) {  // a singularity at a fan's copy: the singularity file can only name the input vertex
    int copies = 0, first = -1;
    for (const auto& [v, n] : prescription.vertex)
      if (v >= repair->input_vertices && copies++ == 0) first = v;
    if (copies > 0)
      std::cerr << "trivcon: warning" << (name.empty() ? "" : " for " + name) << ": " << copies
                << " singularities are at vertices repair appended for a fan (first: " << first << ", a copy of input vertex "
                << repair->vertex_origin[first] << "); the singularity file names the input vertex, the report and the repaired mesh "
                << "(--mesh-out) the copy\n";
  }
  if (!ok)
    std::cerr << "trivcon: verification failed" << (name.empty() ? "" : " for " + name) << ": residual " << residual
              << ", transport mismatch " << d.transport_mismatch << ", fixed faces off by " << d.max_fixed_error << ", "
              << unexplained.size() << " unexplained index mismatches: " << verification_failure(designer, d, o.tolerance) << "\n";
  return ok;
}

void run_solve(const SolveOptions& o) {
  auto t0 = Clock::now();
  const LoadedMesh loaded = load_mesh(o.mesh, o.mesh_options, o.quiet);
  const MeshData& mesh = loaded.mesh;
  const RepairedMesh* repair = loaded.repaired();
  if (repair && o.out.mesh.empty() && (!o.out.connection.empty() || !o.out.matching.empty()))
    throw Error(o.mesh + " was repaired, and the connection and matching files name edges by the vertices of the repaired mesh: " +
                "write it with --mesh-out (or give --no-repair)");
  const double read_seconds = seconds_since(t0);
  SolverOptions solver_options = o.field.solver_options();
  // With --auto alone the field's singularities are the smoothest field's own, and the request layer reads every
  // fixed-face path's turn from that field (docs/solver.md, "A guide for the turns"): the sparse route then makes
  // the dense route's field at a fraction of its cost (BENCHMARKS.md, "Fixed-face paths under --auto"). Where they
  // differ from its own (pairs cancelled, relaxed, a batch of others) its turns need not fit them, and a refined
  // mesh is solved without a guide: the dense route stays.
  if (o.field.auto_place && o.field.auto_cancel == 0 && !o.field.relax && !o.field.split_large_turns && o.sing_batch.empty())
    solver_options.max_dense_paths = 0;
  FieldDesigner designer(mesh.V, mesh.F, solver_options);
  FieldRequest request = o.field.request(designer, repair);
  std::vector<BatchItem> batch;
  if (!o.sing_batch.empty()) batch = read_batch(o.sing_batch, request.prescription);
  if (repair)
    for (BatchItem& item : batch) {
      try {
        item.prescription.vertex = singularities_on_repaired(*repair, item.prescription.vertex);
      } catch (const Error& e) {
        throw Error("batch item '" + item.name + "': " + e.what());
      }
    }
  if (!batch.empty() && request.split_large_turns)
    throw Error("--split-large-turns refines the mesh for one prescription: not with --sing-batch");
  // Set up for the fixed faces now (the one factorization), so that the mesh's line shows its time.
  const RequestConstraints constraints = request_constraints(designer, request);
  designer.set_fixed_faces(constraints.fixed_faces);

  nlohmann::ordered_json extra = nlohmann::ordered_json::object();
  if (repair) extra["repair"] = repair_summary_json(*repair), extra["repair"]["seconds"] = loaded.repair_seconds;
  std::string features_summary;
  if (request.features_given()) report_features(o, designer, constraints, request.prescription.N, extra, features_summary);
  const Topology& t = designer.topology();
  const PrepareTimings& pt = designer.timings();
  if (!o.quiet)
    std::cout << "mesh " << o.mesh << ": " << t.num_vertices << " vertices, " << t.num_faces << " faces, " << t.components.size()
              << " component(s), chi " << t.euler_characteristic() << ", " << designer.cycles().generators.size() << " generator(s), "
              << t.boundary_loops.size() << " boundary loop(s)\n"
              << "time: read " << fmt(loaded.read_seconds) << " s, repair " << fmt(loaded.repair_seconds) << " s, prepared in " << fmt(pt.prepare) << " s (topology " << fmt(pt.topology)
              << " s, geometry " << fmt(pt.geometry) << " s, cycles " << fmt(pt.cycles) << " s, plan " << fmt(pt.plan) << " s, setup "
              << fmt(pt.setup) << " s)\n"
              << features_summary;
  if (!o.field.sing_from_field.empty()) {
    extra["sing_from_field"] = {{"file", o.field.sing_from_field}, {"singularities", request.prescription.vertex.size()}};
    if (!o.quiet)
      std::cout << "sing-from-field: " << o.field.sing_from_field << " has " << request.prescription.vertex.size() << " singularities\n";
  }

  if (!batch.empty()) {  // many prescriptions, one factorization: check every item before writing anything
    for (BatchItem& item : batch) {
      item.prescription.fixed = constraints.fixed;
      try {
        validate_prescription(t, static_cast<int>(designer.cycles().generators.size()), item.prescription);
      } catch (const Error& e) {
        throw Error("batch item '" + item.name + "': " + e.what());
      }
    }
    bool ok = true;
    for (const BatchItem& item : batch)
      ok &= solve_one(o, mesh, designer, item.prescription, request_design(designer, item.prescription, request.roots), item.name,
                      read_seconds, extra, constraints.sharp_edges, &loaded);
    if (!ok) exit_code = kVerificationFailed;
    return;
  }

  const FieldOutcome out = solve_request(designer, mesh.F, request);
  if (out.auto_result) {
    const AutoResult& r = *out.auto_result;
    const AutoTimings& s = r.seconds;
    extra["auto"] = {
        {"found", r.found.size()},
        {"coincident_removed", r.coincident_removed},
        {"boundary_moved", r.boundary_moved},
        {"cancelled_pairs", r.pairs.size()},
        {"used", r.vertex.size()},
        {"cancel_distance", o.field.auto_cancel},
        {"vanishing_faces", r.vanishing_faces},
        {"ordering", r.ordering},
        {"seconds",
         {{"assemble", s.assemble}, {"factor", s.factor}, {"iterate", s.iterate}, {"align", s.align}, {"indices", s.indices},
          {"cancel", s.cancel}}}};
    if (request.auto_options.align_curvature) extra["auto"]["align"] = {{"guidance", "curvature"}, {"t", request.auto_options.curvature_t}};
    if (!o.quiet)
      std::cout << "auto: smoothest field found " << r.found.size() << " singularities, " << r.coincident_removed
                << " removed by summing over coincident vertices, cancelled " << r.pairs.size() << " pairs, using " << r.vertex.size() << "\n";
  }
  if (const std::map<int, int>& corners = out.constraints.features.corners; !corners.empty()) {
    extra["corners"] = nlohmann::ordered_json::array();
    for (auto [v, n] : input_singularities(corners, loaded.repaired())) extra["corners"].push_back({{"vertex", v}, {"index", format_index(n, out.prescription.N)}});
    if (!o.quiet)
      std::cout << "boundary: " << corners.size() << " boundary vertices given an index are corners of the aligned boundary (their fans turned)\n";
  }
  if (out.relax_result) {
    extra["relax"] = relax_summary_json(*out.relax_result);
    if (!o.quiet) std::cout << relax_summary_line(*out.relax_result) << "\n";
  }
  MeshData refined_mesh;
  if (request.split_large_turns) {
    nlohmann::ordered_json rounds = nlohmann::ordered_json::array();
    for (size_t k = 0; k < out.rounds.size(); ++k) {
      const RefineRound& r = out.rounds[k];
      rounds.push_back({{"split_edges", r.split_edges}, {"vertices", r.vertices}, {"faces", r.faces}, {"reweighted", r.reweighted}});
      if (!o.quiet) {
        if (r.reweighted)
          std::cout << "split-large-turns: round " << k + 1 << " lowered the weights of " << r.split_edges
                    << " edges still turning by pi/N or more\n";
        else
          std::cout << "split-large-turns: round " << k + 1 << " split " << r.split_edges << " edges turning by pi/N or more: " << r.vertices
                    << " vertices, " << r.faces << " faces\n";
      }
    }
    extra["split_large_turns"] = {{"rounds", rounds}, {"converged", out.split_converged}, {"max_rounds", request.max_split_rounds}};
    if (!out.split_converged)
      std::cerr << "trivcon: warning: --split-large-turns stopped after " << request.max_split_rounds << " rounds of splitting and "
                << 3 * request.max_split_rounds
                << " of lowering weights with edges still turning by pi/N or more (see large_turns in the report)\n";
    if (out.refined) {  // the refined mesh, each face's polygon that of its parent
      refined_mesh = mesh;
      std::vector<int> polygon(out.parent_face.size());
      for (size_t f = 0; f < polygon.size(); ++f)
        polygon[f] = mesh.polygon_of_triangle.empty() ? out.parent_face[f] : mesh.polygon_of_triangle[out.parent_face[f]];
      refined_mesh.V = out.V, refined_mesh.F = out.F, refined_mesh.polygon_of_triangle = polygon;
    }
  }
  if (!solve_one(o, out.refined ? refined_mesh : mesh, out.designer(designer), out.prescription, out.design, "", read_seconds, extra,
                 out.sharp_edges, out.refined ? nullptr : &loaded, out.constraints.features.corners))
    exit_code = kVerificationFailed;
}

}  // namespace

void register_solve(CLI::App& app) {
  static SolveOptions o;
  auto* cmd = app.add_subcommand("solve", "Compute the smoothest field with exactly the prescribed singularities");
  cmd->add_option("mesh", o.mesh, "Mesh file: .obj .off .ply .stl .gltf .glb, optionally .gz")->required();
  o.field.add_to(cmd);
  auto* batch =
      cmd->add_option("--sing-batch", o.sing_batch,
                      "Solve many singularity sets with one factorization: a directory of singularity files, or a JSON-lines file; "
                      "outputs get the item's name ({name} in a path, or before the extension)");
  o.field.auto_flag->excludes(batch);
  o.field.from_field_option->excludes(batch);
  o.field.relax_flag->excludes(batch);
  cmd->add_option("--field-out", o.out.field,
                  "Field file: .txt (x y z per face), .rawfield (Directional), .rosy (QuadWild, N = 4) or .ply");
  cmd->add_option(
      "--sharp-out", o.out.sharp,
      "QuadWild .sharp file of the sharp edges (--align-features / --features): 'convexity,face,edge' for each face beside one");
  cmd->add_option("--connection-out", o.out.connection, "Connection file: 'i j x' per interior edge");
  cmd->add_option("--lines-out", o.out.lines, "OBJ with a short segment per face and direction");
  cmd->add_option("--mesh-out", o.out.mesh,
                  "The mesh the field was solved on (.ply binary, else .obj): the repaired one when the input needed repair (its faces "
                  "the input's in order without the dropped ones, split vertices appended), with --split-large-turns the refined one");
  cmd->add_option("--matching-out", o.out.matching,
                  "Matching file (Directional's .matching: 'N E', then 'L R i j m' per interior edge): the 2pi/N steps our connection "
                  "pairs the faces' directions with, so that tools read exactly the prescribed singularities");
  cmd->add_option("--sing-out", o.out.singularities, "Singularity file of the singularities used ('VERTEX INDEX' lines, readable by -s)");
  cmd->add_option("--png", o.out.png, "Picture of the field (as `trivcon render` with its defaults)");
  cmd->add_option("--report", o.out.report, "JSON report: sizes, topology, indices used, energy, residuals, timings");
  cmd->add_flag("-q,--quiet", o.quiet, "Print nothing on success");
  add_mesh_options(cmd, o.mesh_options);
  cmd->add_option("--tolerance", o.tolerance,
                  "Verification limit on the holonomy residuals, transport and fixed faces, relative to max(1, right-hand sides) "
                  "(default 1e-9); a solve that misses it exits 3 and says why")
      ->check(CLI::PositiveNumber);
  cmd->callback([] {
    // Usage errors (exit 2) found before any work.
    if (!o.out.sharp.empty() && !o.field.features.given()) throw CLI::ValidationError("--sharp-out", "needs --align-features or --features");
    const std::string& field = o.out.field;
    if (field.size() >= 5 && field.compare(field.size() - 5, 5, ".rosy") == 0 && o.field.prescription.N != 4)
      throw CLI::ValidationError("--field-out", "a .rosy field (QuadWild) is a cross field: give -N 4");
    run_solve(o);
  });
}

}  // namespace trivcon::cli
