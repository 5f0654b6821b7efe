// trivcon solve MESH [options]   and   trivcon check MESH FIELD [options]
#include <algorithm>
#include <chrono>
#include <filesystem>
#include <sstream>
#include <cmath>
#include <iomanip>
#include <iostream>

#include "commands.h"
#include "trivcon/blas.h"
#include "summary.h"
#include "trivcon/constraints.h"
#include "trivcon/design.h"
#include "trivcon/error.h"
#include "trivcon/field_io.h"
#include "trivcon/render.h"

namespace trivcon::cli {

namespace {

using Clock = std::chrono::steady_clock;
double seconds_since(Clock::time_point t0) { return std::chrono::duration<double>(Clock::now() - t0).count(); }

// Options that describe a prescription, shared by solve and check.
struct PrescriptionOptions {
  int N = 1;
  std::vector<std::string> sing_files, sings, generators, loops;
  CLI::Option* N_option = nullptr;
  bool N_given() const { return N_option && N_option->count() > 0; }
  bool empty() const { return sing_files.empty() && sings.empty() && generators.empty() && loops.empty(); }
  void add_to(CLI::App* cmd, bool with_cycles) {
    N_option = cmd->add_option("-N,--symmetry", N, "Symmetry: 1 vectors, 2 lines, 4 crosses, any N >= 1")->check(CLI::Range(1, 1000));
    cmd->add_option("-s,--singularities", sing_files,
                    "Singularity file: 'VERTEX INDEX' per line (INDEX integer or p/q), or Directional's .sings");
    cmd->add_option("--sing", sings, "A singular vertex, V:INDEX (e.g. 12:1/4); repeatable");
    if (with_cycles) {
      cmd->add_option("--generator", generators, "Index of generator G (see info --cycles), G:INDEX; repeatable");
      cmd->add_option("--boundary", loops, "Index of boundary loop L (see info --cycles), L:INDEX; repeatable");
    }
  }
  IndexPrescription build() const {
    IndexPrescription p;
    p.N = N;
    for (const auto& f : sing_files) read_singularities(f, p);
    for (const auto& s : sings) add_vertex_index(s, p);
    for (const auto& s : generators) add_generator_index(s, p);
    for (const auto& s : loops) add_loop_index(s, p);
    return p;
  }
};

struct SolveOptions {
  std::string mesh;
  PrescriptionOptions prescription;
  std::string weights = "cotan", solver = "cholesky";
  std::vector<int> root_faces;
  std::vector<double> root_angles;
  std::vector<std::string> fixes;
  bool align_boundary = false;
  std::string sing_batch;
  std::string field_out, connection_out, lines_out, report, png;
  bool quiet = false;
};

// --fix takes "F:x,y,z" / "F:angle=A" specs and files; a spec starts with a face id and a colon.
bool is_fix_spec(const std::string& s) {
  const size_t colon = s.find(':');
  return colon != std::string::npos && colon > 0 && s.find_first_not_of("0123456789") == colon;
}

std::string fmt(double v) {
  std::ostringstream s;
  s << std::setprecision(3) << v;
  return s.str();
}

// Output paths for one prescription of a batch: "{name}" in a path is replaced by the item's name;
// without it, ".NAME" goes before the extension (field.txt → field.NAME.txt). Single solves keep paths.
std::string output_path(const std::string& path, const std::string& name) {
  if (path.empty() || name.empty()) return path;
  const size_t brace = path.find("{name}");
  if (brace != std::string::npos) return path.substr(0, brace) + name + path.substr(brace + 6);
  const size_t slash = path.find_last_of('/');
  const size_t dot = path.find_last_of('.');
  if (dot == std::string::npos || (slash != std::string::npos && dot < slash)) return path + "." + name;
  return path.substr(0, dot) + "." + name + path.substr(dot);
}

struct BatchItem {
  std::string name;
  IndexPrescription prescription;
};

// --sing-batch: a directory of singularity files (sorted by name; each named by its file name without
// extension), or a JSON-lines file: one object per line, {"name": "a", "sing": {"12": "1/4", ...},
// "generator": {"0": "1"}, "boundary": {"1": "0"}} ("generator"/"boundary" optional). Each item's
// prescription starts from the command line's (-N, --generator, --boundary); its singularities replace
// those of -s/--sing.
std::vector<BatchItem> read_batch(const std::string& path, const IndexPrescription& base) {
  std::vector<BatchItem> items;
  namespace fs = std::filesystem;
  if (fs::is_directory(path)) {
    std::vector<fs::path> files;
    for (const auto& entry : fs::directory_iterator(path))
      if (entry.is_regular_file()) files.push_back(entry.path());
    std::sort(files.begin(), files.end());
    for (const fs::path& f : files) {
      BatchItem item{f.stem().string(), base};
      item.prescription.vertex.clear();
      read_singularities(f.string(), item.prescription);
      items.push_back(std::move(item));
    }
    if (items.empty()) throw Error("--sing-batch " + path + ": the directory has no files");
    return items;
  }
  std::istringstream in(read_file_bytes(path));
  std::string line;
  for (int line_no = 1; std::getline(in, line); ++line_no) {
    const std::string where = path + ":" + std::to_string(line_no);
    if (line.find_first_not_of(" \t\r") == std::string::npos) continue;
    nlohmann::json j;
    try {
      j = nlohmann::json::parse(line);
    } catch (const nlohmann::json::exception& e) {
      throw Error(where + ": not a JSON object (" + std::string(e.what()) + ")");
    }
    if (!j.is_object() || !j.contains("name") || !j["name"].is_string() || !j.contains("sing") || !j["sing"].is_object())
      throw Error(where + ": expected {\"name\": \"...\", \"sing\": {\"VERTEX\": \"INDEX\", ...}}");
    BatchItem item{j["name"].get<std::string>(), base};
    if (item.name.empty() || item.name.find('/') != std::string::npos) throw Error(where + ": the name must be non-empty without '/'");
    item.prescription.vertex.clear();
    auto add = [&](const char* key, void (*adder)(const std::string&, IndexPrescription&)) {
      if (!j.contains(key)) return;
      if (!j[key].is_object()) throw Error(where + ": \"" + key + "\" must be an object");
      for (const auto& [id, index] : j[key].items()) {
        const std::string value = index.is_string() ? index.get<std::string>() : index.dump();
        try {
          adder(id + ":" + value, item.prescription);
        } catch (const Error& e) {
          throw Error(where + ": " + e.what());
        }
      }
    };
    add("sing", add_vertex_index);
    add("generator", add_generator_index);
    add("boundary", add_loop_index);
    items.push_back(std::move(item));
  }
  if (items.empty()) throw Error("--sing-batch " + path + ": no items");
  return items;
}

// The outputs of one solve appear together or not at all: each is written (atomically) beside its final
// path under a temporary name, and all are renamed into place once every one was written.
class StagedOutputs {
 public:
  std::string path(const std::string& final_path) {
    // Same folder (so the rename is atomic) and same ending (writers choose the format by extension).
    const std::filesystem::path p(final_path);
    staged_.emplace_back((p.parent_path() / (".trivcon-partial." + p.filename().string())).string(), final_path);
    return staged_.back().first;
  }
  void commit() {
    for (const auto& [temp, final_path] : staged_) {
      std::error_code error;
      std::filesystem::rename(temp, final_path, error);
      if (error) throw Error("cannot write '" + final_path + "': " + error.message());
    }
    staged_.clear();
  }
  ~StagedOutputs() {
    for (const auto& [temp, final_path] : staged_) {
      std::error_code ignored;
      std::filesystem::remove(temp, ignored);
    }
  }

 private:
  std::vector<std::pair<std::string, std::string>> staged_;
};

// Solves one prescription on the prepared designer, writes its outputs, prints its summary; returns
// whether verification passed.
bool solve_one(const SolveOptions& o, const MeshData& mesh, FieldDesigner& designer, const IndexPrescription& prescription,
               const std::vector<std::pair<int, double>>& roots, const std::string& name, double read_seconds) {
  const Design d = designer.design(prescription, roots);
  const Topology& t = designer.topology();
  const Connection& c = d.connection;

  // Verification: constraint residuals relative to the right-hand sides, transport, fixed faces, indices.
  const double tolerance = 1e-9 * std::max(1.0, c.rhs_scale);
  const double residual = std::max(c.max_vertex_residual, c.max_cycle_residual);
  const std::vector<int>& unexplained = d.unexplained_mismatch_vertices;
  const bool ok = residual <= tolerance && d.transport_mismatch <= tolerance && d.max_fixed_error <= tolerance && unexplained.empty();

  auto t1 = Clock::now();
  StagedOutputs staged;
  if (!o.field_out.empty()) write_field(staged.path(output_path(o.field_out, name)), mesh.V, mesh.F, designer.geometry(), d.field);
  if (!o.connection_out.empty()) write_connection(staged.path(output_path(o.connection_out, name)), t, c.x, prescription.N);
  if (!o.lines_out.empty()) write_field_lines(staged.path(output_path(o.lines_out, name)), mesh.V, mesh.F, designer.geometry(), d.field);
  if (!o.png.empty()) {  // the prescription's singularities, drawn with the default view of `trivcon render`
    std::vector<std::pair<int, int>> singular(prescription.vertex.begin(), prescription.vertex.end());
    write_png(staged.path(output_path(o.png, name)), render_field(mesh.V, t, designer.geometry(), d.field, singular));
  }
  const double write_seconds = seconds_since(t1);

  nlohmann::ordered_json report;
  report["mesh"] = mesh_summary(o.mesh, mesh, t, designer.geometry());
  if (!name.empty()) report["name"] = name;
  report["N"] = prescription.N;
  report["weights"] = o.weights;
  report["solver"] = o.solver;
  report["blas_kernels"] = blas_kernels();
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
                     {"align_boundary", o.align_boundary},
                     {"paths", designer.solver().fixed_paths().size()},
                     {"regularized_edges", designer.solver().regularized_edges()},
                     {"max_error", d.max_fixed_error},
                     {"conflicts", conflicts}};
  report["energy"] = c.energy;
  report["residuals"] = {{"max_vertex", c.max_vertex_residual},
                         {"max_cycle", c.max_cycle_residual},
                         {"rhs_scale", c.rhs_scale},
                         {"transport_mismatch", d.transport_mismatch}};
  nlohmann::ordered_json mism = nlohmann::ordered_json::array();
  for (int v : d.index_mismatch_vertices) mism.push_back({{"vertex", v}, {"field_index", format_index(d.indices.vertex[v], prescription.N)}});
  report["indices"] = {{"singular_vertices", prescription.vertex.size()},
                       {"field_mismatches", mism},
                       {"unexplained_mismatches", unexplained.size()},
                       {"large_turn_edges", d.large_turn_edges}};
  const PrepareTimings& pt = designer.timings();
  const SetupTimings& st = designer.solver().timings();
  report["symbolic_analysis"] = st.analysis_adopted ? "concurrent" : "in set-up";
  report["seconds"] = {{"read", read_seconds},
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
                       {"write", write_seconds}};
  report["verified"] = ok;
  if (!o.report.empty())
    write_file_atomically(staged.path(output_path(o.report, name)), [&](std::ostream& out) { out << report.dump(2) << "\n"; });
  staged.commit();

  if (!o.quiet) {
    if (!name.empty()) std::cout << "== " << name << "\n";
    std::cout << "N " << prescription.N << ", " << prescription.vertex.size() << " singular vertices, weights " << o.weights << ", solver "
              << o.solver << "\n"
              << (prescription.fixed.empty() ? std::string()
                                             : std::to_string(prescription.fixed.size()) + " fixed faces, max deviation " + fmt(d.max_fixed_error) +
                                                   " rad, " + std::to_string(d.conflicts.size()) + " sharp turns between adjacent fixed faces\n")
              << "energy " << std::setprecision(10) << c.energy << "\n"
              << "max residual " << fmt(residual) << " rad (vertex " << fmt(c.max_vertex_residual) << ", cycles " << fmt(c.max_cycle_residual)
              << "), transport mismatch " << fmt(d.transport_mismatch) << " rad\n"
              << "indices read back from the field: " << d.index_mismatch_vertices.size() << " differ from the prescription";
    if (!d.index_mismatch_vertices.empty())
      std::cout << " (" << d.index_mismatch_vertices.size() - unexplained.size()
                << " at vertices where the connection turns by pi/N or more across an edge, which a per-face field cannot show)";
    std::cout << "\ntime: solve " << fmt(d.solve_seconds) << " s, field " << fmt(d.field_seconds) << " s\n";
  }
  if (!ok)
    std::cerr << "trivcon: verification failed" << (name.empty() ? "" : " for " + name) << ": residual " << residual << ", transport mismatch "
              << d.transport_mismatch << ", fixed faces off by " << d.max_fixed_error << ", " << unexplained.size()
              << " unexplained index mismatches\n";
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
  options.solver = o.solver == "qr" ? SolverKind::QR : SolverKind::Cholesky;
  FieldDesigner designer(mesh.V, mesh.F, options);
  if (o.align_boundary) prescription.fixed = boundary_alignment(designer.V(), designer.topology(), designer.geometry());
  std::map<int, double> explicit_fixed;  // --fix wins over --align-boundary on the same face
  for (const auto& f : o.fixes) {
    if (is_fix_spec(f)) add_fixed_direction(f, designer.topology(), designer.geometry(), explicit_fixed);
    else read_fixed_directions(f, designer.topology(), designer.geometry(), explicit_fixed);
  }
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
              << fmt(pt.setup) << " s)\n";
  bool ok = true;
  if (batch.empty()) {
    ok = solve_one(o, mesh, designer, prescription, roots, "", read_seconds);
  } else {
    for (BatchItem& item : batch) {  // check every item before writing anything
      item.prescription.fixed = prescription.fixed;
      try {
        validate_prescription(t, static_cast<int>(designer.cycles().generators.size()), item.prescription);
      } catch (const Error& e) {
        throw Error("batch item '" + item.name + "': " + e.what());
      }
    }
    for (const BatchItem& item : batch) ok &= solve_one(o, mesh, designer, item.prescription, roots, item.name, read_seconds);
  }
  if (!ok) exit_code = 3;
}

struct CheckOptions {
  std::string mesh, field;
  PrescriptionOptions prescription;
  bool json = false;
};

void run_check(CheckOptions& o) {
  const MeshData mesh = load_mesh(o.mesh);
  check_finite(mesh.V);
  const Topology t = build_topology(mesh.F, static_cast<int>(mesh.V.rows()));
  const Geometry g = compute_geometry(mesh.V, t);
  const Cycles cycles = compute_cycles(t);
  int file_N = 0;
  const MatrixX3d directions = read_field(o.field, t.num_faces, &file_N);
  if (o.prescription.N_given() && file_N > 0 && file_N != o.prescription.N)
    throw Error("the field file " + o.field + " holds an N = " + std::to_string(file_N) + " field but -N " +
                std::to_string(o.prescription.N) + " was given");
  if (!o.prescription.N_given() && file_N > 0) o.prescription.N = file_N;
  // Without a prescription, check only lists the field's singularities.
  const bool compare = !o.prescription.empty();
  const IndexPrescription p = o.prescription.build();
  if (compare) validate_prescription(t, static_cast<int>(cycles.generators.size()), p);
  const Field field = field_from_directions(g, directions, p.N);
  const FieldIndices idx = field_indices(t, g, cycles, field);
  nlohmann::ordered_json found = nlohmann::ordered_json::array(), differ = nlohmann::ordered_json::array();
  for (int v = 0; v < t.num_vertices; ++v) {
    const int want = p.vertex.count(v) ? p.vertex.at(v) : 0;
    if (idx.vertex[v] != 0) found.push_back({{"vertex", v}, {"index", format_index(idx.vertex[v], p.N)}});
    if (compare && idx.vertex[v] != want)
      differ.push_back({{"vertex", v}, {"found", format_index(idx.vertex[v], p.N)}, {"prescribed", format_index(want, p.N)}});
  }
  nlohmann::ordered_json j;
  j["N"] = p.N;
  j["singularities"] = found;
  if (compare) j["differences"] = differ;
  nlohmann::ordered_json loops = nlohmann::ordered_json::array(), gens = nlohmann::ordered_json::array();
  for (size_t l = 0; l < idx.loop.size(); ++l) loops.push_back({{"id", l}, {"index", format_index(idx.loop[l], p.N)}});
  for (size_t i = 0; i < idx.generator.size(); ++i) gens.push_back({{"id", i}, {"index", format_index(idx.generator[i], p.N)}});
  j["boundary_loops"] = loops;
  j["generators"] = gens;
  if (o.json) {
    std::cout << j.dump(2) << "\n";
  } else {
    std::cout << "N " << p.N << ": " << found.size() << " singular vertices in the field\n";
    for (const auto& s : found) std::cout << "  vertex " << s["vertex"] << " index " << s["index"].get<std::string>() << "\n";
    for (size_t l = 0; l < idx.loop.size(); ++l) std::cout << "  boundary loop " << l << " index " << format_index(idx.loop[l], p.N) << "\n";
    if (compare)
      std::cout << (differ.empty() ? "matches the prescription\n" : std::to_string(differ.size()) + " vertices differ from the prescription\n");
    for (const auto& s : differ)
      std::cout << "  vertex " << s["vertex"] << ": found " << s["found"].get<std::string>() << ", prescribed " << s["prescribed"].get<std::string>() << "\n";
  }
  if (!differ.empty()) exit_code = 4;
}

}  // namespace

void register_solve(CLI::App& app) {
  static SolveOptions o;
  auto* cmd = app.add_subcommand("solve", "Compute the smoothest field with exactly the prescribed singularities");
  cmd->add_option("mesh", o.mesh, "Mesh file: .obj .off .ply, optionally .gz")->required();
  o.prescription.add_to(cmd, true);
  cmd->add_option("--weights", o.weights, "cotan (default: clamped cotangent weights) or unit")->check(CLI::IsMember({"cotan", "unit"}));
  cmd->add_option("--solver", o.solver, "cholesky (default) or qr (the paper's SuiteSparseQR route)")->check(CLI::IsMember({"cholesky", "qr"}));
  cmd->add_option("--fix", o.fixes,
                  "Fixed direction: F:x,y,z (world, projected to the face), F:angle=A (radians, face frame), or a file with "
                  "'FACE x y z' / 'FACE angle=A' lines; repeatable");
  cmd->add_flag("--align-boundary", o.align_boundary, "Fix every face with a boundary edge to that edge's direction");
  cmd->add_option("--sing-batch", o.sing_batch,
                  "Solve many singularity sets with one factorization: a directory of singularity files, or a JSON-lines file; "
                  "outputs get the item's name ({name} in a path, or before the extension)");
  cmd->add_option("--root-face", o.root_faces, "Face where propagation starts (one per component at most; repeatable)");
  cmd->add_option("--root-angle", o.root_angles, "Angle (radians, in the root face's frame) of the field at the matching --root-face");
  cmd->add_option("--field-out", o.field_out, "Field file: .txt (x y z per face), .rawfield (Directional) or .ply");
  cmd->add_option("--connection-out", o.connection_out, "Connection file: 'i j x' per interior edge");
  cmd->add_option("--lines-out", o.lines_out, "OBJ with a short segment per face and direction");
  cmd->add_option("--png", o.png, "Picture of the field (as `trivcon render` with its defaults)");
  cmd->add_option("--report", o.report, "JSON report: sizes, topology, indices used, energy, residuals, timings");
  cmd->add_flag("-q,--quiet", o.quiet, "Print nothing on success");
  cmd->callback([] { run_solve(o); });

  static CheckOptions c;
  auto* check = app.add_subcommand("check",
                                   "Compute the indices of a per-face field (any tool's); with -s/--sing, compare them with that prescription");
  check->add_option("mesh", c.mesh, "Mesh file")->required();
  check->add_option("field", c.field, "Field: trivcon's .txt or .ply, or Directional's .rawfield")->required();
  c.prescription.add_to(check, false);
  check->add_flag("--json", c.json, "Print JSON");
  check->callback([] { run_check(c); });
}

}  // namespace trivcon::cli
