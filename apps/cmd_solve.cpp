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
#include "feature_options.h"
#include "outputs.h"
#include "prescription_options.h"
#include "report.h"
#include "summary.h"
#include "trivcon/auto.h"
#include "trivcon/constraints.h"
#include "trivcon/design.h"
#include "trivcon/error.h"
#include "trivcon/split_large_turns.h"
#include "trivcon/features.h"
#include "trivcon/generate.h"
#include "trivcon/matching.h"
#include "trivcon/field_io.h"

namespace trivcon::cli {

namespace {

struct SolveOptions {
  std::string mesh;
  PrescriptionOptions prescription;
  std::string weights = "cotan", solver = "cholesky", factorization = "own";
  double weight_floor = 0;
  std::vector<int> root_faces;
  std::vector<double> root_angles;
  std::vector<std::string> fixes;
  bool align_boundary = false;
  FeatureOptions features;  // --align-features, --features
  std::string sing_batch;
  bool auto_place = false;  // --auto
  double auto_cancel = 0;   // --auto-cancel, in mean edge lengths
  std::string align;        // --align curvature[:t]
  std::string sing_from_field;
  OutputPaths out;
  bool quiet = false;
  double tolerance = kDefaultTolerance;  // --tolerance
  bool split_large_turns = false;        // --split-large-turns
};

// Rounds of --split-large-turns before it gives up (each splits every edge still turning by π/N or more).
constexpr int kMaxSplitRounds = 8;

// The strength T of --align curvature[:T] (0 when not given), or nothing when the text is not of that form.
std::optional<double> alignment_strength(const std::string& text) {
  if (text == "curvature") return 0.0;
  const std::string prefix = "curvature:";
  if (text.compare(0, prefix.size(), prefix) != 0 || text.size() == prefix.size()) return std::nullopt;
  const std::string number = text.substr(prefix.size());
  size_t used = 0;
  double t = 0;
  try {
    t = std::stod(number, &used);
  } catch (const std::exception&) {
    return std::nullopt;
  }
  if (used != number.size() || !std::isfinite(t) || !(t < 1)) return std::nullopt;
  return t;
}

std::string fmt(double v) {
  std::ostringstream s;
  s << std::setprecision(3) << v;
  return s.str();
}

// --align-features / --features: every face beside a sharp edge fixed to it (trivcon/features.h), over
// --align-boundary on the same face (--fix, merged later, wins over both). Returns the sharp edges; when
// `extra` is given, reports what was fixed there and in `summary` (printed after the mesh's lines), and
// warns of every corner conflict.
std::vector<int> apply_features(const SolveOptions& o, const FieldDesigner& designer, IndexPrescription& prescription,
                                nlohmann::ordered_json* extra, std::string* summary) {
  if (!o.features.given()) return {};
  const Topology& t = designer.topology();
  const std::vector<int> edges = o.features.edges(designer.V(), t, designer.geometry());
  const FeatureAlignment a = feature_alignment(designer.V(), t, designer.geometry(), edges, prescription.N);
  int boundary_overridden = 0;  // faces --align-boundary fixed to another direction (modulo 2π/N)
  for (auto [f, angle] : a.fixed) {
    const auto it = prescription.fixed.find(f);
    if (it != prescription.fixed.end() && std::abs(reduce_angle(it->second - angle, prescription.N)) > kFeatureAngleTolerance)
      ++boundary_overridden;
    prescription.fixed[f] = angle;
  }
  if (!extra) return edges;
  int convex = 0;
  for (int e : edges) convex += is_convex_edge(designer.V(), t, designer.geometry(), e);
  nlohmann::ordered_json conflicts = nlohmann::ordered_json::array();
  for (const FeatureConflict& c : a.conflicts)
    conflicts.push_back({{"face", c.face},
                         {"followed", {t.edge_vertices(c.followed, 0), t.edge_vertices(c.followed, 1)}},
                         {"other", {t.edge_vertices(c.other, 0), t.edge_vertices(c.other, 1)}},
                         {"difference", c.difference}});
  (*extra)["features"] = {{"sharp_edges", edges.size()},    {"convex", convex},       {"fixed_faces", a.fixed.size()},
                          {"corner_faces", a.corner_faces}, {"conflicts", conflicts}, {"boundary_overridden", boundary_overridden}};
  if (o.features.degrees_option->count() > 0) (*extra)["features"]["degrees"] = o.features.degrees;
  if (o.features.file_option->count() > 0) (*extra)["features"]["file"] = o.features.file;
  std::ostringstream text;
  text << "features: " << edges.size() << " sharp edges (" << convex << " convex), " << a.fixed.size() << " faces fixed beside them, "
       << a.corner_faces << " beside two or more\n";
  if (boundary_overridden > 0)
    text << "features: " << boundary_overridden << " faces beside both a boundary edge and a sharp edge follow the sharp edge\n";
  *summary = text.str();
  if (!a.conflicts.empty()) {
    double worst = 0;
    for (const FeatureConflict& c : a.conflicts) worst = std::max(worst, c.difference);
    std::cerr << "trivcon: warning: " << a.conflicts.size()
              << " face-edge pairs at corners where sharp edges meet that a field of N = " << prescription.N
              << " cannot follow both (largest difference " << fmt(worst) << " rad); each such face follows its longest sharp edge";
    const FeatureConflict& c = a.conflicts.front();
    std::cerr << " (e.g. face " << c.face << " follows (" << t.edge_vertices(c.followed, 0) << ", " << t.edge_vertices(c.followed, 1)
              << "), not (" << t.edge_vertices(c.other, 0) << ", " << t.edge_vertices(c.other, 1) << "); report: features.conflicts)\n";
  }
  return edges;
}

// Solves one prescription on the prepared designer, writes its outputs, prints its summary; returns
// whether verification passed.
// `extra` holds report entries of the whole run (the "auto" or "sing_from_field" object), added to the report.
// `guide` (--auto's smoothest field, on this designer's faces): components without a root or fixed face take
// their rotation from it (roots_toward, trivcon/auto.h) instead of starting at angle 0.
bool solve_one(const SolveOptions& o, const MeshData& mesh, FieldDesigner& designer, const IndexPrescription& prescription,
               const std::vector<std::pair<int, double>>& given_roots, const std::string& name, double read_seconds,
               const nlohmann::ordered_json& extra, const std::vector<int>& sharp, const Field* guide = nullptr) {
  std::vector<std::pair<int, double>> roots = given_roots;
  if (guide) roots = roots_toward(designer, designer.design(prescription, roots).field, *guide, roots, prescription.fixed);
  const Design d = designer.design(prescription, roots);
  const Connection& c = d.connection;

  // Verification: constraint residuals relative to the right-hand sides, transport, fixed faces, indices.
  const double residual = std::max(c.max_vertex_residual, c.max_cycle_residual);
  const std::vector<int>& unexplained = d.unexplained_mismatch_vertices;
  const bool ok = design_verified(d, o.tolerance);

  auto t1 = Clock::now();
  StagedOutputs staged;
  stage_design_outputs(staged, o.out, name, mesh, designer, prescription, d, sharp);
  const ReportRun run{o.mesh, name, o.weights, o.solver, o.align_boundary, read_seconds, seconds_since(t1), ok};
  if (!o.out.report.empty()) {
    nlohmann::ordered_json report = solve_report(run, mesh, designer, prescription, d);
    for (const auto& [key, value] : extra.items()) report[key] = value;
    staged.write(output_path(o.out.report, name),
                 [&](const std::string& path) { write_file_atomically(path, [&](std::ostream& out) { out << report.dump(2) << "\n"; }); });
  }
  staged.commit();

  if (!o.quiet) {
    if (!name.empty()) std::cout << "== " << name << "\n";
    std::cout << "N " << prescription.N << ", " << prescription.vertex.size() << " singular vertices, weights " << o.weights << ", solver "
              << o.solver << "\n"
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
    int consumer = 0, extra = 0;
    for (int v = 0; v < designer.topology().num_vertices; ++v) {
      const auto it = prescription.vertex.find(v);
      consumer += d.indices.vertex[v] != 0;
      extra += d.indices.vertex[v] != (it == prescription.vertex.end() ? 0 : it->second);
    }
    std::cerr << "trivcon: warning" << (name.empty() ? "" : " for " + name) << ": " << large.size()
              << " edges turn by pi/N or more; a tool that matches directions itself (Directional, QuadWild, MIQ) will read " << consumer
              << " singular vertices from this field, " << extra
              << " of them differing from the prescription (report: large_turns, field_exact); give it --matching-out, or refine the mesh "
                 "there (--split-large-turns)\n";
  }
  if (!ok)
    std::cerr << "trivcon: verification failed" << (name.empty() ? "" : " for " + name) << ": residual " << residual
              << ", transport mismatch " << d.transport_mismatch << ", fixed faces off by " << d.max_fixed_error << ", "
              << unexplained.size() << " unexplained index mismatches: " << verification_failure(designer, d, o.tolerance) << "\n";
  return ok;
}

void run_solve(const SolveOptions& o) {
  auto t0 = Clock::now();
  const MeshData mesh = load_mesh(o.mesh);
  const double read_seconds = seconds_since(t0);
  IndexPrescription prescription = o.prescription.build();
  if (o.root_angles.size() > o.root_faces.size()) throw Error("--root-angle given without a matching --root-face");
  std::vector<std::pair<int, double>> roots;
  for (size_t i = 0; i < o.root_faces.size(); ++i) roots.emplace_back(o.root_faces[i], i < o.root_angles.size() ? o.root_angles[i] : 0.0);
  std::vector<BatchItem> batch;
  if (!o.sing_batch.empty()) batch = read_batch(o.sing_batch, prescription);

  SolverOptions options;
  options.weights = o.weights == "unit" ? WeightKind::Unit : WeightKind::Cotan;
  options.weight_floor = o.weight_floor;
  options.solver = o.solver == "qr" ? SolverKind::QR : SolverKind::Cholesky;
  options.factorization = o.factorization == "cholmod" ? Factorization::Cholmod : Factorization::Parallel;
  FieldDesigner designer(mesh.V, mesh.F, options);
  if (o.align_boundary) prescription.fixed = boundary_alignment(designer.V(), designer.topology(), designer.geometry());
  nlohmann::ordered_json extra = nlohmann::ordered_json::object();
  std::string features_summary;
  std::vector<int> sharp = apply_features(o, designer, prescription, &extra, &features_summary);
  std::map<int, double> explicit_fixed;  // --fix wins over --align-boundary on the same face
  add_fix_options(o.fixes, designer.topology(), designer.geometry(), explicit_fixed);
  for (auto [f, angle] : explicit_fixed) prescription.fixed[f] = angle;
  std::vector<int> fixed_faces;
  for (auto [f, angle] : prescription.fixed) fixed_faces.push_back(f);
  designer.set_fixed_faces(fixed_faces);  // the one factorization

  const Topology& t = designer.topology();
  const PrepareTimings& pt = designer.timings();
  if (!o.quiet)
    std::cout << "mesh " << o.mesh << ": " << t.num_vertices << " vertices, " << t.num_faces << " faces, " << t.components.size()
              << " component(s), chi " << t.euler_characteristic() << ", " << designer.cycles().generators.size() << " generator(s), "
              << t.boundary_loops.size() << " boundary loop(s)\n"
              << "time: read " << fmt(read_seconds) << " s, prepared in " << fmt(pt.prepare) << " s (topology " << fmt(pt.topology)
              << " s, geometry " << fmt(pt.geometry) << " s, cycles " << fmt(pt.cycles) << " s, plan " << fmt(pt.plan) << " s, setup "
              << fmt(pt.setup) << " s)\n"
              << features_summary;
  // Singularities found for the user: from the smoothest field (--auto), or from another field's indices.
  std::optional<Field> auto_field;  // --auto's smoothest field: the final field takes its rotation from it
  if (o.auto_place) {
    AutoOptions ao;
    ao.N = prescription.N;
    ao.cancel_distance = o.auto_cancel;
    ao.fixed = prescription.fixed;  // --align-boundary, --align-features and --fix: Dirichlet values of the smoothest field
    if (!o.align.empty()) ao.align_curvature = true, ao.curvature_t = *alignment_strength(o.align);  // checked by CLI11
    const AutoResult r = auto_singularities(designer, ao);
    prescription.vertex = r.vertex;
    auto_field = r.field;
    const AutoTimings& s = r.seconds;
    extra["auto"] = {
        {"found", r.found.size()},
        {"coincident_removed", r.coincident_removed},
        {"boundary_moved", r.boundary_moved},
        {"cancelled_pairs", r.pairs.size()},
        {"used", r.vertex.size()},
        {"cancel_distance", o.auto_cancel},
        {"vanishing_faces", r.vanishing_faces},
        {"ordering", r.ordering},
        {"seconds",
         {{"assemble", s.assemble}, {"factor", s.factor}, {"iterate", s.iterate}, {"align", s.align}, {"indices", s.indices},
          {"cancel", s.cancel}}}};
    if (ao.align_curvature) extra["auto"]["align"] = {{"guidance", "curvature"}, {"t", ao.curvature_t}};
    if (!o.quiet)
      std::cout << "auto: smoothest field found " << r.found.size() << " singularities, " << r.coincident_removed
                << " removed by summing over coincident vertices, cancelled " << r.pairs.size() << " pairs, using " << r.vertex.size() << "\n";
  }
  if (!o.sing_from_field.empty()) {
    const MatrixX3d directions = o.prescription.read_field_file(o.sing_from_field, designer.topology().num_faces, prescription.N);
    const Field field = field_from_directions(designer.geometry(), directions, prescription.N);
    const FieldIndices idx = field_indices(designer.topology(), designer.geometry(), designer.cycles(), field);
    for (int v = 0; v < designer.topology().num_vertices; ++v)
      if (idx.vertex[v] != 0) prescription.vertex[v] = idx.vertex[v];
    extra["sing_from_field"] = {{"file", o.sing_from_field}, {"singularities", prescription.vertex.size()}};
    if (!o.quiet) std::cout << "sing-from-field: " << o.sing_from_field << " has " << prescription.vertex.size() << " singularities\n";
  }

  // --split-large-turns: split the edges turning by π/N or more (and the faces beside them), re-solve with
  // the same singularities on the refined mesh, until none is left or the rounds run out.
  std::unique_ptr<FieldDesigner> refined_designer;
  MeshData refined_mesh;
  if (o.split_large_turns) {
    if (!batch.empty()) throw Error("--split-large-turns refines the mesh for one prescription: not with --sing-batch");
    if (!prescription.generator.empty() || !prescription.loop.empty())
      throw Error(
          "--split-large-turns makes new generators and boundary loops: leave their indices to be chosen (no --generator, --boundary)");
    if (o.features.file_option->count() > 0)
      throw Error("--split-large-turns splits edges, which a --features file names by their vertices: use --align-features instead");
    std::map<int, Eigen::Vector3d> fixed_world;  // --fix directions in world space, per input face
    for (auto [f, angle] : explicit_fixed) fixed_world[f] = designer.geometry().direction_in_face(f, angle);
    // Each refined mesh's fixed faces: --align-boundary and the sharp edges found again on it, and the
    // --fix directions passed to the children of their faces (they win, as on the input mesh).
    auto constraints = [&](const FieldDesigner& refined, const std::vector<int>& parent) {
      IndexPrescription q;
      q.N = prescription.N;
      if (o.align_boundary) q.fixed = boundary_alignment(refined.V(), refined.topology(), refined.geometry());
      sharp = apply_features(o, refined, q, nullptr, nullptr);  // the split faces beside a sharp edge are fixed to it again
      for (int f = 0; f < static_cast<int>(parent.size()); ++f) {
        const auto it = fixed_world.find(parent[f]);
        if (it != fixed_world.end()) q.fixed[f] = refined.geometry().angle_in_face(f, it->second);
      }
      return q.fixed;
    };
    RefinedDesign refined = split_large_turns(designer, mesh.F, prescription, options, constraints, kMaxSplitRounds, roots);
    nlohmann::ordered_json rounds = nlohmann::ordered_json::array();
    for (size_t k = 0; k < refined.rounds.size(); ++k) {
      const RefineRound& r = refined.rounds[k];
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
    const bool converged = refined.converged;
    MeshData current_mesh = mesh;
    if (refined.designer) {
      std::vector<int> polygon(refined.parent_face.size());
      for (size_t f = 0; f < polygon.size(); ++f)
        polygon[f] = mesh.polygon_of_triangle.empty() ? refined.parent_face[f] : mesh.polygon_of_triangle[refined.parent_face[f]];
      current_mesh.V = refined.V, current_mesh.F = refined.F, current_mesh.polygon_of_triangle = polygon;
      refined_designer = std::move(refined.designer);
    }
    IndexPrescription p = refined.prescription;
    extra["split_large_turns"] = {{"rounds", rounds}, {"converged", converged}, {"max_rounds", kMaxSplitRounds}};
    if (!converged)
      std::cerr << "trivcon: warning: --split-large-turns stopped after " << kMaxSplitRounds << " rounds of splitting and "
                << 3 * kMaxSplitRounds << " of lowering weights with edges still turning by pi/N or more (see large_turns in the report)\n";
    if (refined_designer) {
      if (auto_field) {  // the guide on the refined faces: each child lies in its parent's plane
        Field guide{auto_field->N, Eigen::VectorXd(refined.parent_face.size())};
        for (size_t f = 0; f < refined.parent_face.size(); ++f) {
          const int parent = refined.parent_face[f];
          guide.angle(f) = refined_designer->geometry().angle_in_face(
              static_cast<int>(f), designer.geometry().direction_in_face(parent, auto_field->angle(parent)));
        }
        auto_field = guide;
      }
      refined_mesh = std::move(current_mesh);
      prescription = p;
    }
  }
  const MeshData& out_mesh = refined_designer ? refined_mesh : mesh;
  FieldDesigner& out_designer = refined_designer ? *refined_designer : designer;

  bool ok = true;
  if (batch.empty()) {
    ok = solve_one(o, out_mesh, out_designer, prescription, roots, "", read_seconds, extra, sharp, auto_field ? &*auto_field : nullptr);
  } else {
    for (BatchItem& item : batch) {  // check every item before writing anything
      item.prescription.fixed = prescription.fixed;
      try {
        validate_prescription(t, static_cast<int>(designer.cycles().generators.size()), item.prescription);
      } catch (const Error& e) {
        throw Error("batch item '" + item.name + "': " + e.what());
      }
    }
    for (const BatchItem& item : batch) ok &= solve_one(o, mesh, designer, item.prescription, roots, item.name, read_seconds, extra, sharp);
  }
  if (!ok) exit_code = kVerificationFailed;
}

}  // namespace

void register_solve(CLI::App& app) {
  static SolveOptions o;
  auto* cmd = app.add_subcommand("solve", "Compute the smoothest field with exactly the prescribed singularities");
  cmd->add_option("mesh", o.mesh, "Mesh file: .obj .off .ply, optionally .gz")->required();
  o.prescription.add_to(cmd, true);
  cmd->add_option("--weights", o.weights, "cotan (default: clamped cotangent weights) or unit")->check(CLI::IsMember({"cotan", "unit"}));
  cmd->add_option("--weight-floor", o.weight_floor,
                  "with cotan weights, every interior edge gets at least this fraction of the median weight (default 0: none)")
      ->check(CLI::Range(0.0, 1.0));
  cmd->add_option("--solver", o.solver, "cholesky (default) or qr (the paper's SuiteSparseQR route)")
      ->check(CLI::IsMember({"cholesky", "qr"}));
  cmd->add_option("--factorization", o.factorization,
                  "Cholesky route's numeric factor: own (default: trivcon's, on several threads) or cholmod (CHOLMOD's cholmod_factorize)")
      ->check(CLI::IsMember({"own", "cholmod"}));
  cmd->add_option("--fix", o.fixes,
                  "Fixed direction: F:x,y,z (world, projected to the face), F:angle=A (radians, face frame), or a file with "
                  "'FACE x y z' / 'FACE angle=A' lines; repeatable");
  cmd->add_flag("--align-boundary", o.align_boundary, "Fix every face with a boundary edge to that edge's direction");
  o.features.add_to(cmd, "every face beside one is fixed to its direction (with --auto too)");
  auto* batch =
      cmd->add_option("--sing-batch", o.sing_batch,
                      "Solve many singularity sets with one factorization: a directory of singularity files, or a JSON-lines file; "
                      "outputs get the item's name ({name} in a path, or before the extension)");
  auto* auto_flag = cmd->add_flag("--auto", o.auto_place,
                                  "Find the singularities automatically: those of the globally smoothest field (Knoppel et al. 2013), "
                                  "then solve exactly with them");
  cmd->add_option("--auto-cancel", o.auto_cancel,
                  "With --auto: cancel pairs of opposite singularities at most D mean edge lengths apart (geodesic, along edges), "
                  "closest first")
      ->check(CLI::NonNegativeNumber)
      ->needs(auto_flag);
  auto check_align = [](const std::string& text) -> std::string {
    return alignment_strength(text) ? "" : "expected curvature or curvature:T with a number T < 1, not '" + text + "'";
  };
  cmd->add_option("--align", o.align,
                  "With --auto: guidance for the smoothest field; 'curvature' or 'curvature:T' follows the principal curvature "
                  "directions (N even) with strength T < 1 (default 0; toward 1 smoother, negative closer to the curvature)")
      ->check(CLI::Validator(check_align, "curvature[:T]"))
      ->needs(auto_flag);
  auto* from_field = cmd->add_option("--sing-from-field", o.sing_from_field,
                                     "Use the singularities of a per-face field (.txt, .ply or Directional's .rawfield, as `check` reads)");
  auto_flag->excludes(o.prescription.files_option)->excludes(o.prescription.sing_option)->excludes(batch)->excludes(from_field);
  from_field->excludes(o.prescription.files_option)->excludes(o.prescription.sing_option)->excludes(batch);
  cmd->add_option("--root-face", o.root_faces, "Face where propagation starts (one per component at most; repeatable)");
  cmd->add_option("--root-angle", o.root_angles, "Angle (radians, in the root face's frame) of the field at the matching --root-face");
  cmd->add_option("--field-out", o.out.field,
                  "Field file: .txt (x y z per face), .rawfield (Directional), .rosy (QuadWild, N = 4) or .ply");
  cmd->add_option(
      "--sharp-out", o.out.sharp,
      "QuadWild .sharp file of the sharp edges (--align-features / --features): 'convexity,face,edge' for each face beside one");
  cmd->add_option("--connection-out", o.out.connection, "Connection file: 'i j x' per interior edge");
  cmd->add_option("--lines-out", o.out.lines, "OBJ with a short segment per face and direction");
  cmd->add_flag("--split-large-turns", o.split_large_turns,
                "Refine the mesh where the connection turns by pi/N or more (split those edges and their faces; input ids kept, new "
                "vertices and faces appended) and solve again, until no edge does, so that any tool's own matching reads exactly the "
                "prescribed singularities; write the refined mesh with --mesh-out");
  cmd->add_option("--mesh-out", o.out.mesh,
                  "The mesh the field belongs to (.ply binary, else .obj): with --split-large-turns the refined one");
  cmd->add_option("--matching-out", o.out.matching,
                  "Matching file (Directional's .matching: 'N E', then 'L R i j m' per interior edge): the 2pi/N steps our connection "
                  "pairs the faces' directions with, so that tools read exactly the prescribed singularities");
  cmd->add_option("--sing-out", o.out.singularities, "Singularity file of the singularities used ('VERTEX INDEX' lines, readable by -s)");
  cmd->add_option("--png", o.out.png, "Picture of the field (as `trivcon render` with its defaults)");
  cmd->add_option("--report", o.out.report, "JSON report: sizes, topology, indices used, energy, residuals, timings");
  cmd->add_flag("-q,--quiet", o.quiet, "Print nothing on success");
  cmd->add_option("--tolerance", o.tolerance,
                  "Verification limit on the holonomy residuals, transport and fixed faces, relative to max(1, right-hand sides) "
                  "(default 1e-9); a solve that misses it exits 3 and says why")
      ->check(CLI::PositiveNumber);
  cmd->callback([] {
    // Usage errors (exit 2) found before any work.
    if (!o.out.sharp.empty() && !o.features.given()) throw CLI::ValidationError("--sharp-out", "needs --align-features or --features");
    const std::string& field = o.out.field;
    if (field.size() >= 5 && field.compare(field.size() - 5, 5, ".rosy") == 0 && o.prescription.N != 4)
      throw CLI::ValidationError("--field-out", "a .rosy field (QuadWild) is a cross field: give -N 4");
    run_solve(o);
  });
}

}  // namespace trivcon::cli
