// SPDX-License-Identifier: MIT
// bench_trivcon: how long reading, preparing and editing take, per mesh, and the peak memory.
//
//   bench_trivcon [--quick] [--cache DIR] [--dragon PATH] [--json FILE] [--meshes a,b,...]
//
// The driver (this program without --child) runs every step in a child process of its own (the same
// executable with --child ...), so that the peak resident set (VmHWM from /proc/self/status) is that of
// one mesh, and prints markdown tables on stdout (progress on stderr):
//   1. prepare: generates the mesh (or reads and converts the dragon) and writes binary PLY, and OBJ for
//      meshes of at most 1M faces, into the cache directory (skipped when the files exist);
//   2. run: `reps` times after `warmup` discarded runs, the whole pipeline from the file: read_mesh
//      (binary PLY), validation + topology (check_finite, build_topology), geometry, cycles, set-up
//      (ConnectionSolver constructor, with its own timings(): assemble / factor / schur), and the field's
//      propagation plan (plan_propagation, built once per mesh); every run
//      starts from nothing (the previous run's objects are freed first). Reading the OBJ (and the
//      dragon's original ASCII PLY) is timed separately. Then `edits` edits after `edit_warmup`
//      discarded ones: new singularities at random vertices (bench/edits.h) → ConnectionSolver::solve →
//      propagate_field with the plan; "whole edit" is the time from the new vertex list to the field in memory.
//      The last edit's connection and field are verified (outside the timings).
//   3. qr (meshes marked for it): our solver and the paper-literal SolverKind::QR in one process, on the
//      same mesh and the same edits; the QR set-up is abandoned, and reported as such, past a time or
//      resident-memory limit (a watchdog thread).
// Times are wall-clock (steady_clock); the statistics are median, min and max over the repetitions.
#include <spawn.h>
#include <sys/wait.h>
#include <unistd.h>

#include <CLI/CLI.hpp>
#include <algorithm>
#include <atomic>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <iostream>
#include <map>
#include <memory>
#include <mutex>
#include <nlohmann/json.hpp>
#include <random>
#include <sstream>
#include <string>
#include <thread>
#include <vector>

#include "edits.h"
#include "trivcon/auto.h"
#include "trivcon/blas.h"
#include "trivcon/tuned_process.h"
#include "trivcon/cycles.h"
#include "trivcon/design.h"
#include "trivcon/error.h"
#include "trivcon/field.h"
#include "trivcon/generate.h"
#include "trivcon/geometry.h"
#include "trivcon/io.h"
#include "trivcon/solver.h"
#include "trivcon/topology.h"

extern char** environ;

namespace {

using json = nlohmann::json;
using Clock = std::chrono::steady_clock;
namespace fs = std::filesystem;
using namespace trivcon;

double seconds_since(Clock::time_point t0) { return std::chrono::duration<double>(Clock::now() - t0).count(); }

// ---------------------------------------------------------------------------------------------------
// Measurements

struct Samples {
  std::vector<double> v;
  void add(double x) { v.push_back(x); }
  double median() const {
    if (v.empty()) return NAN;
    std::vector<double> s = v;
    std::sort(s.begin(), s.end());
    const size_t n = s.size();
    return n % 2 ? s[n / 2] : 0.5 * (s[n / 2 - 1] + s[n / 2]);
  }
  json to_json() const {
    if (v.empty()) return nullptr;
    return json{{"median", median()},
                {"min", *std::min_element(v.begin(), v.end())},
                {"max", *std::max_element(v.begin(), v.end())},
                {"n", v.size()},
                {"samples", v}};
  }
};

// kB values of /proc/self/status lines "VmHWM:" and "VmRSS:", in bytes.
double proc_status_bytes(const char* key) {
  std::ifstream in("/proc/self/status");
  std::string line;
  const size_t k = std::string(key).size();
  while (std::getline(in, line))
    if (line.compare(0, k, key) == 0) return std::stod(line.substr(k)) * 1024.0;
  return NAN;
}
double peak_rss() { return proc_status_bytes("VmHWM:"); }
double current_rss() { return proc_status_bytes("VmRSS:"); }

void log(const std::string& s) { std::cerr << s << std::endl; }

// ---------------------------------------------------------------------------------------------------
// Meshes

struct MeshSpec {
  std::string name, family, spec;  // spec: cube:N | torus:NU:NV | uv:R:S | ico:L | file:PATH | subdiv:PATH
  bool qr = false;
};

std::vector<std::string> split(const std::string& s, char sep) {
  std::vector<std::string> out;
  std::stringstream ss(s);
  std::string item;
  while (std::getline(ss, item, sep)) out.push_back(item);
  return out;
}

Mesh make_mesh(const std::string& spec) {
  const size_t colon = spec.find(':');
  const std::string kind = spec.substr(0, colon), rest = colon == std::string::npos ? "" : spec.substr(colon + 1);
  const std::vector<std::string> a = split(rest, ':');
  if (kind == "cube") return make_cube_sphere(std::stoi(a.at(0)), true);
  if (kind == "torus") return make_torus(std::stoi(a.at(0)), std::stoi(a.at(1)));
  if (kind == "uv") return make_uv_sphere(std::stoi(a.at(0)), std::stoi(a.at(1)));
  if (kind == "ico") return make_icosphere(std::stoi(a.at(0)));
  if (kind == "file" || kind == "subdiv") {
    MeshData d = read_mesh(rest);
    Mesh m{std::move(d.V), std::move(d.F)};
    return kind == "subdiv" ? subdivide_midpoint(m) : m;
  }
  throw std::runtime_error("unknown mesh spec " + spec);
}

// Cache file stem for a spec: the spec with its path reduced to the file name (and a hash of the path).
std::string cache_stem(const std::string& spec) {
  std::string s = spec;
  const size_t colon = s.find(':');
  if (colon != std::string::npos && (s.substr(0, colon) == "file" || s.substr(0, colon) == "subdiv")) {
    const std::string path = s.substr(colon + 1);
    s = s.substr(0, colon) + "_" + fs::path(path).filename().string() + "_" +
        std::to_string(std::hash<std::string>{}(fs::weakly_canonical(path).string()) % 100000);
  }
  for (char& c : s)
    if (!std::isalnum(static_cast<unsigned char>(c)) && c != '.' && c != '-') c = '_';
  return s;
}

constexpr long kObjMaxFaces = 1000000;
constexpr long kFewRepsFaces = 2000000;  // above this: at most 3 pipeline runs and 10 edits

// ---------------------------------------------------------------------------------------------------
// Child: prepare (write the cache files)

int child_prepare(const std::string& spec, const std::string& ply, const std::string& obj) {
  const bool need_ply = !fs::exists(ply), need_obj = !obj.empty() && !fs::exists(obj);
  if (!need_ply && !need_obj) return 0;
  auto t0 = Clock::now();
  Mesh m = make_mesh(spec);
  log("  prepared " + spec + ": " + std::to_string(m.F.rows()) + " faces in " + std::to_string(seconds_since(t0)) + " s");
  if (need_ply) write_ply(ply, m.V, m.F);
  if (need_obj && m.F.rows() <= kObjMaxFaces) write_obj(obj, m.V, m.F);
  return 0;
}

// ---------------------------------------------------------------------------------------------------
// Child: run (our pipeline)

struct RunOptions {
  std::string name, ply, obj, ascii, out, weights = "cotan";
  int warmup = 1, reps = 5, edit_warmup = 2, edits = 20, N = 4, count = 8;
  int qr_reps = 3;
  double qr_time_limit = 120, qr_mem_limit_gb = 16;
};

void write_json(const std::string& path, const json& j) {
  const std::string tmp = path + ".tmp";
  {
    std::ofstream out(tmp);
    out << j.dump(1) << "\n";
  }
  fs::rename(tmp, path);
}

SolverOptions solver_options(const RunOptions& o) {
  SolverOptions s;
  s.weights = o.weights == "unit" ? WeightKind::Unit : WeightKind::Cotan;
  return s;
}

// Everything the pipeline holds, freed between repetitions.
// A mesh prepared as a user of the library gets it: FieldDesigner (its second thread included).
struct Pipeline {
  MeshData mesh;
  std::unique_ptr<FieldDesigner> designer;
  const Topology& topology() const { return designer->topology(); }
  const Geometry& geometry() const { return designer->geometry(); }
  const Cycles& cycles() const { return designer->cycles(); }
  const PropagationPlan& plan() const { return designer->plan(); }
  void clear() {
    designer.reset();
    mesh = MeshData{};
  }
};

struct EditResult {
  Connection connection;
  Field field;
  double solve = 0, field_time = 0, whole = 0;
};

EditResult timed_edit(const ConnectionSolver& solver, const Pipeline& p, const bench::EditGenerator& gen, const std::string& name,
                      int index) {
  EditResult r;
  std::mt19937_64 rng(bench::edit_seed(name, index));
  const auto t0 = Clock::now();
  const IndexPrescription prescription = gen.next(rng);
  const auto t1 = Clock::now();
  r.connection = solver.solve(prescription);
  const auto t2 = Clock::now();
  r.field = propagate_field(p.topology(), p.geometry(), p.plan(), r.connection.x, prescription.N);
  const auto t3 = Clock::now();
  r.solve = std::chrono::duration<double>(t2 - t1).count();
  r.field_time = std::chrono::duration<double>(t3 - t2).count();
  r.whole = std::chrono::duration<double>(t3 - t0).count();
  return r;
}

json mesh_summary(const Pipeline& p) {
  const Topology& t = p.topology();
  int max_genus = 0;
  for (const auto& c : t.components) max_genus = std::max(max_genus, c.genus);
  return json{{"vertices", t.num_vertices},
              {"faces", t.num_faces},
              {"edges", t.num_edges},
              {"components", t.components.size()},
              {"boundary_loops", t.boundary_loops.size()},
              {"generators", p.cycles().generators.size()},
              {"max_genus", max_genus},
              {"euler_characteristic", t.euler_characteristic()},
              {"negative_cotan_edges", p.geometry().negative_cotan_edges},
              {"degenerate_faces", p.geometry().degenerate_faces}};
}

// Verification of one edit (outside the timings): the solver's residuals and the indices read back.
json verify_edit(const Pipeline& p, const bench::EditGenerator& gen, const std::string& name, int index, const EditResult& r,
                 Samples* verify_time) {
  std::mt19937_64 rng(bench::edit_seed(name, index));
  const IndexPrescription prescription = gen.next(rng);
  const auto t0 = Clock::now();
  const FieldIndices idx = field_indices(p.topology(), p.geometry(), p.cycles(), r.field);
  const double mismatch = max_transport_mismatch(p.topology(), p.geometry(), r.connection.x, r.field);
  int wrong = 0;
  for (int v = 0; v < p.topology().num_vertices; ++v) {
    if (!p.topology().is_interior_vertex(v)) continue;
    auto it = prescription.vertex.find(v);
    wrong += idx.vertex[v] != (it == prescription.vertex.end() ? 0 : it->second);
  }
  if (verify_time) verify_time->add(seconds_since(t0));
  int large_turns = 0;
  for (int e = 0; e < p.topology().num_edges; ++e) large_turns += std::abs(r.connection.x(e)) >= trivcon::kPi / prescription.N;
  return json{{"max_vertex_residual", r.connection.max_vertex_residual},
              {"max_cycle_residual", r.connection.max_cycle_residual},
              {"rhs_scale", r.connection.rhs_scale},
              {"transport_mismatch", mismatch},
              {"index_mismatch_vertices", wrong},
              {"large_turn_edges", large_turns},
              {"energy", r.connection.energy}};
}

int child_run(const RunOptions& o) {
  json result;
  result["name"] = o.name;
  result["status"] = "running";
  Samples read_ply, read_obj, read_ascii, topo, geom, cyc, plan, analysis, setup, assemble, wait, factor, schur, prepare, to_setup;
  bool adopted = true;
  Pipeline p;
  json rss;
  rss["start"] = peak_rss();
  int reps = o.reps, edits = o.edits;
  for (int r = 0; r < o.warmup + reps; ++r) {
    const bool keep = r >= o.warmup;
    p.clear();
    auto t0 = Clock::now();
    p.mesh = read_mesh(o.ply);
    const double t_read = seconds_since(t0);
    if (r == 0) rss["after_read"] = peak_rss();
    t0 = Clock::now();
    p.designer = std::make_unique<FieldDesigner>(p.mesh.V, p.mesh.F, solver_options(o));
    p.designer->set_fixed_faces({});  // sets up (factors) the solver now
    const double t_prepare = seconds_since(t0);
    if (r == 0) rss["after_setup"] = peak_rss();
    const PrepareTimings& pt = p.designer->timings();
    const SetupTimings& st = p.designer->solver().timings();
    // Fewer repetitions on the largest meshes, where one run takes tens of seconds.
    if (r == 0 && p.topology().num_faces > kFewRepsFaces) reps = std::min(reps, 3), edits = std::min(edits, 10);
    log("  " + o.name + (keep ? " rep " : " warm-up ") + std::to_string(r) + ": read " + std::to_string(t_read) + " prepare " +
        std::to_string(t_prepare) + " s (topology " + std::to_string(pt.topology) + " geometry " + std::to_string(pt.geometry) +
        " cycles " + std::to_string(pt.cycles) + " field plan " + std::to_string(pt.plan) + " analysis " + std::to_string(pt.analysis) +
        " set-up " + std::to_string(pt.setup) + (st.analysis_adopted ? "" : ", own analysis") + ")");
    if (!keep) continue;
    read_ply.add(t_read), topo.add(pt.topology), geom.add(pt.geometry), cyc.add(pt.cycles), plan.add(pt.plan), analysis.add(pt.analysis);
    setup.add(pt.setup), assemble.add(st.assemble), wait.add(st.analysis_wait), factor.add(st.factor), schur.add(st.schur);
    prepare.add(t_prepare);
    to_setup.add(t_read + t_prepare);
    adopted = adopted && st.analysis_adopted;
  }
  result["mesh"] = mesh_summary(p);
  result["format"] = p.mesh.format;

  // Other file formats, read and dropped (the pipeline's mesh stays in memory meanwhile).
  auto time_reads = [&](const std::string& path, Samples& s) {
    if (path.empty() || !fs::exists(path)) return;
    for (int r = 0; r < o.warmup + reps; ++r) {
      auto t0 = Clock::now();
      MeshData m = read_mesh(path);
      const double t = seconds_since(t0);
      if (m.F.rows() != p.topology().num_faces) throw std::runtime_error(path + ": face count differs from the binary PLY");
      if (r >= o.warmup) s.add(t);
    }
  };
  time_reads(o.obj, read_obj);
  time_reads(o.ascii, read_ascii);
  rss["after_reads"] = peak_rss();

  // Edits.
  const bench::EditGenerator gen(p.topology(), o.N, o.count);
  Samples solve, field, whole, verify_time;
  EditResult last;
  for (int i = 0; i < o.edit_warmup + edits; ++i) {
    EditResult r = timed_edit(p.designer->solver(), p, gen, o.name, i);
    if (i >= o.edit_warmup) solve.add(r.solve), field.add(r.field_time), whole.add(r.whole);
    if (i + 1 == o.edit_warmup + edits) result["check"] = verify_edit(p, gen, o.name, i, r, &verify_time);
  }
  log("  " + o.name + ": edit solve " + std::to_string(solve.median() * 1e3) + " ms, field " + std::to_string(field.median() * 1e3) +
      " ms, whole " + std::to_string(whole.median() * 1e3) + " ms");
  // Automatic placement (solve --auto) on the prepared mesh: the smoothest field and its singularities,
  // `reps` times (after one warm-up).
  Samples auto_total, auto_assemble, auto_factor, auto_iterate, auto_indices;
  size_t auto_found = 0;
  std::string auto_ordering;
  for (int r = 0; r < 1 + reps; ++r) {
    AutoOptions ao;
    ao.N = o.N;
    auto t0 = Clock::now();
    const AutoResult a = auto_singularities(*p.designer, ao);
    const double t = seconds_since(t0);
    auto_found = a.vertex.size(), auto_ordering = a.ordering;
    if (r == 0) continue;
    auto_total.add(t), auto_assemble.add(a.seconds.assemble), auto_factor.add(a.seconds.factor), auto_iterate.add(a.seconds.iterate);
    auto_indices.add(a.seconds.indices);
  }
  log("  " + o.name + ": auto " + std::to_string(auto_total.median()) + " s, " + std::to_string(auto_found) + " singularities");
  result["auto"] = json{{"total", auto_total.to_json()},     {"assemble", auto_assemble.to_json()}, {"factor", auto_factor.to_json()},
                        {"iterate", auto_iterate.to_json()}, {"indices", auto_indices.to_json()},   {"singularities", auto_found},
                        {"ordering", auto_ordering}};
  rss["peak"] = peak_rss();
  result["rss"] = rss;
  result["N"] = o.N;
  result["weights"] = o.weights;
  result["singularities"] = gen.singularities();
  result["ordering"] = p.designer->solver().ordering();
  result["analysis_concurrent"] = adopted;
  result["stages"] = json{{"read_ply", read_ply.to_json()}, {"read_obj", read_obj.to_json()},  {"read_ascii", read_ascii.to_json()},
                          {"topology", topo.to_json()},     {"geometry", geom.to_json()},      {"cycles", cyc.to_json()},
                          {"plan", plan.to_json()},         {"analysis", analysis.to_json()},  {"setup", setup.to_json()},
                          {"assemble", assemble.to_json()}, {"analysis_wait", wait.to_json()}, {"factor", factor.to_json()},
                          {"schur", schur.to_json()},       {"prepare", prepare.to_json()},    {"read_to_setup", to_setup.to_json()}};
  result["edits"] =
      json{{"solve", solve.to_json()}, {"field", field.to_json()}, {"whole", whole.to_json()}, {"verify", verify_time.to_json()}};
  result["status"] = "ok";
  write_json(o.out, result);
  return 0;
}

// ---------------------------------------------------------------------------------------------------
// Child: qr (ours against SolverKind::QR, same process, same edits)

std::mutex g_partial_mutex;
json g_partial;
std::string g_partial_path;

// Watches the QR set-up: past the time or memory limit, writes the partial result and ends the process.
class Watchdog {
 public:
  Watchdog(double seconds, double bytes, std::string what) : limit_s_(seconds), limit_b_(bytes), what_(std::move(what)) {
    thread_ = std::thread([this] { run(); });
  }
  ~Watchdog() {
    stop_ = true;
    thread_.join();
  }
  double peak_seen() const { return peak_; }

 private:
  void run() {
    const auto t0 = Clock::now();
    while (!stop_) {
      std::this_thread::sleep_for(std::chrono::milliseconds(20));
      const double rss = current_rss(), t = seconds_since(t0);
      peak_ = std::max(peak_.load(), rss);
      std::string reason;
      if (rss > limit_b_)
        reason = what_ + " abandoned: resident memory " + std::to_string(rss / 1e9) + " GB > limit " + std::to_string(limit_b_ / 1e9) +
                 " GB after " + std::to_string(t) + " s";
      else if (t > limit_s_)
        reason = what_ + " abandoned: still running after " + std::to_string(limit_s_) + " s (resident memory " +
                 std::to_string(rss / 1e9) + " GB)";
      if (!reason.empty()) {
        std::lock_guard<std::mutex> lock(g_partial_mutex);
        g_partial["qr"]["status"] = "aborted";
        g_partial["qr"]["reason"] = reason;
        g_partial["qr"]["peak_rss"] = peak_rss();
        g_partial["status"] = "ok";
        write_json(g_partial_path, g_partial);
        log("  " + reason);
        std::fflush(nullptr);
        _exit(0);
      }
    }
  }
  double limit_s_, limit_b_;
  std::string what_;
  std::atomic<bool> stop_{false};
  std::atomic<double> peak_{0};
  std::thread thread_;
};

int child_qr(const RunOptions& o) {
  Pipeline p;
  p.mesh = read_mesh(o.ply);
  // Topology, geometry, cycles and plan only (the QR option keeps the designer from analysing on a
  // second thread); both solvers below are built in sequence on one thread, like for like.
  p.designer = std::make_unique<FieldDesigner>(p.mesh.V, p.mesh.F, SolverOptions{solver_options(o).weights, SolverKind::QR});
  std::unique_ptr<ConnectionSolver> ours;
  json result;
  result["name"] = o.name;
  result["mesh"] = mesh_summary(p);

  Samples ours_setup, qr_setup, qr_assemble, qr_factor, qr_schur;
  for (int r = 0; r < o.warmup + o.reps; ++r) {
    ours.reset();
    auto t0 = Clock::now();
    ours = std::make_unique<ConnectionSolver>(p.topology(), p.geometry(), p.cycles(), solver_options(o));
    if (r >= o.warmup) ours_setup.add(seconds_since(t0));
  }
  const double rss_before_qr = current_rss();
  result["ours"]["setup"] = ours_setup.to_json();
  result["qr"]["status"] = "running";
  {
    std::lock_guard<std::mutex> lock(g_partial_mutex);
    g_partial = result;
    g_partial_path = o.out;
  }
  std::unique_ptr<ConnectionSolver> qr;
  double qr_peak = 0;
  for (int r = 0; r < o.qr_reps; ++r) {
    qr.reset();
    Watchdog dog(o.qr_time_limit, o.qr_mem_limit_gb * 1e9, "QR set-up");
    auto t0 = Clock::now();
    qr = std::make_unique<ConnectionSolver>(p.topology(), p.geometry(), p.cycles(),
                                            SolverOptions{solver_options(o).weights, SolverKind::QR});
    const double t = seconds_since(t0);
    qr_peak = std::max(qr_peak, dog.peak_seen());
    qr_setup.add(t);
    const SetupTimings& st = qr->timings();
    qr_assemble.add(st.assemble), qr_factor.add(st.factor), qr_schur.add(st.schur);
    log("  " + o.name + " QR set-up rep " + std::to_string(r) + ": " + std::to_string(t) + " s (factor " + std::to_string(st.factor) +
        " s)");
    if (t > 20) break;  // one is enough to make the point; more would take minutes
  }
  result["qr"]["setup"] = qr_setup.to_json();
  result["qr"]["assemble"] = qr_assemble.to_json();
  result["qr"]["factor"] = qr_factor.to_json();
  result["qr"]["schur"] = qr_schur.to_json();
  result["qr"]["rss_before"] = rss_before_qr;
  result["qr"]["rss_peak_during_setup"] = qr_peak;

  const bench::EditGenerator gen(p.topology(), o.N, o.count);
  Samples ours_solve, ours_whole, qr_solve, qr_whole;
  double max_dx = 0, max_x = 0, max_denergy = 0;
  // All of our edits, then all of QR's (the same edits, seeded by their index): interleaved, each of
  // our edits would start while OpenBLAS's threads still spin after the QR solve before it (they do for
  // a while after every call) and compete with the edit's OpenMP threads for the two cores.
  std::vector<Connection> ours_x;
  for (int i = 0; i < o.edit_warmup + o.edits; ++i) {
    EditResult a = timed_edit(*ours, p, gen, o.name, i);
    if (i >= o.edit_warmup) ours_solve.add(a.solve), ours_whole.add(a.whole);
    ours_x.push_back(std::move(a.connection));
  }
  for (int i = 0; i < o.edit_warmup + o.edits; ++i) {
    const EditResult b = timed_edit(*qr, p, gen, o.name, i);
    if (i >= o.edit_warmup) qr_solve.add(b.solve), qr_whole.add(b.whole);
    const Connection& a = ours_x[i];
    max_dx = std::max(max_dx, (a.x - b.connection.x).cwiseAbs().maxCoeff());
    max_x = std::max(max_x, a.x.cwiseAbs().maxCoeff());
    max_denergy = std::max(max_denergy, std::abs(a.energy - b.connection.energy) / std::max(1e-300, a.energy));
  }
  log("  " + o.name + ": edit ours " + std::to_string(ours_whole.median() * 1e3) + " ms, QR " + std::to_string(qr_whole.median() * 1e3) +
      " ms");
  result["ours"]["solve"] = ours_solve.to_json();
  result["ours"]["whole"] = ours_whole.to_json();
  result["qr"]["solve"] = qr_solve.to_json();
  result["qr"]["whole"] = qr_whole.to_json();
  result["qr"]["status"] = "ok";
  result["agreement"] = json{{"max_abs_dx", max_dx}, {"max_abs_x", max_x}, {"max_rel_energy_difference", max_denergy}};
  result["peak_rss"] = peak_rss();
  result["status"] = "ok";
  write_json(o.out, result);
  return 0;
}

// ---------------------------------------------------------------------------------------------------
// Driver

// 1-minute load average: other work on the machine shows here (2 cores: above ~1 the run was disturbed).
double loadavg() {
  std::ifstream in("/proc/loadavg");
  double l = NAN;
  in >> l;
  return l;
}

int spawn_self(const std::vector<std::string>& args) {
  std::vector<std::string> full{"/proc/self/exe"};
  full.insert(full.end(), args.begin(), args.end());
  std::vector<char*> argv;
  for (auto& a : full) argv.push_back(a.data());
  argv.push_back(nullptr);
  pid_t pid;
  // /proc/self/exe is resolved by the kernel in the parent (posix_spawn execs it as the parent sees it).
  const std::string exe = fs::read_symlink("/proc/self/exe").string();
  if (posix_spawn(&pid, exe.c_str(), nullptr, nullptr, argv.data(), environ) != 0) return -1;
  int status = 0;
  waitpid(pid, &status, 0);
  if (WIFEXITED(status)) return WEXITSTATUS(status);
  if (WIFSIGNALED(status)) return 128 + WTERMSIG(status);
  return -1;
}

std::string fmt(double v, int prec = 3) {
  if (!std::isfinite(v)) return "—";
  char buf[64];
  // prec significant digits, but never scientific notation for the magnitudes we print
  const int digits = v == 0 ? prec : std::max(0, prec - 1 - static_cast<int>(std::floor(std::log10(std::abs(v)))));
  std::snprintf(buf, sizeof buf, "%.*f", std::min(digits, 6), v);
  return buf;
}
double med(const json& j, const char* key) { return j.contains(key) && j[key].is_object() ? j[key]["median"].get<double>() : NAN; }
double jmin(const json& j, const char* key) { return j.contains(key) && j[key].is_object() ? j[key]["min"].get<double>() : NAN; }
double jmax(const json& j, const char* key) { return j.contains(key) && j[key].is_object() ? j[key]["max"].get<double>() : NAN; }
std::string sec(double s) { return std::isfinite(s) ? fmt(s) + " s" : "—"; }
std::string ms(double s) { return std::isfinite(s) ? fmt(s * 1e3) + " ms" : "—"; }
std::string range_s(const json& j, const char* key) {
  return j.contains(key) && j[key].is_object() ? fmt(jmin(j, key)) + "–" + fmt(jmax(j, key)) : "—";
}
std::string range_ms(const json& j, const char* key) {
  return j.contains(key) && j[key].is_object() ? fmt(jmin(j, key) * 1e3) + "–" + fmt(jmax(j, key) * 1e3) : "—";
}
std::string faces_str(long f) {
  if (f >= 1000000) return fmt(f / 1e6, 3) + "M";
  return fmt(f / 1e3, 3) + "k";
}
std::string gb(double b) { return std::isfinite(b) ? fmt(b / 1e9) + " GB" : "—"; }

// Least-squares slope of log y against log x.
double loglog_slope(const std::vector<double>& x, const std::vector<double>& y) {
  const size_t n = x.size();
  if (n < 2) return NAN;
  double mx = 0, my = 0;
  for (size_t i = 0; i < n; ++i) mx += std::log(x[i]), my += std::log(y[i]);
  mx /= n, my /= n;
  double sxy = 0, sxx = 0;
  for (size_t i = 0; i < n; ++i) sxy += (std::log(x[i]) - mx) * (std::log(y[i]) - my), sxx += (std::log(x[i]) - mx) * (std::log(x[i]) - mx);
  return sxy / sxx;
}

std::string label(const json& r) {
  std::string name = r.value("name", std::string("?"));
  if (r.value("weights", std::string("cotan")) == "unit") name += " (unit weights †)";
  return name;
}

void print_auto_table(const json& runs) {
  std::ostream& out = std::cout;
  out << "\n### Automatic placement (`solve --auto`: the smoothest field, trivcon/auto.h), medians\n\n";
  out << "| mesh | faces | prepare (wall) | auto (assemble / factor / iterate / indices) | auto ÷ prepare | singularities | order |\n";
  out << "|---|---:|---:|---:|---:|---:|---|\n";
  for (const json& r : runs) {
    if (r.value("status", "") != "ok" || !r["auto"].is_object()) continue;
    const json& a = r["auto"];
    const double prepare = med(r["stages"], "prepare"), total = med(a, "total");
    out << "| " << label(r) << " | " << r["mesh"]["faces"].get<long>() << " | " << sec(prepare) << " | " << sec(total) << " ("
        << fmt(med(a, "assemble")) << " / " << fmt(med(a, "factor")) << " / " << fmt(med(a, "iterate")) << " / " << fmt(med(a, "indices"))
        << ") | " << fmt(total / prepare, 2) << " | " << a["singularities"].get<long>() << " | " << a.value("ordering", std::string())
        << " |\n";
  }
  out << "\n";
}

void print_tables(const json& runs, const json& qrs, const RunOptions& o, bool quick) {
  print_auto_table(runs);
  std::ostream& out = std::cout;
  out << "### Per mesh (medians; " << o.reps << " runs after " << o.warmup << " warm-up for the stages, " << o.edits << " edits after "
      << o.edit_warmup << " warm-up; above 2M faces at most 3 runs and 10 edits)\n\n";
  out << "| mesh | faces | read (bin. PLY) | read (OBJ) | topology | geometry | cycles ² | field plan | analysis ² | set-up (assemble / "
         "wait / "
         "factor / schur) | prepare (wall) | edit solve | edit field | whole edit | peak RSS |\n";
  out << "|---|---:|---:|---:|---:|---:|---:|---:|---:|---:|---:|---:|---:|---:|---:|\n";
  for (const json& r : runs) {
    if (r.value("status", "") != "ok") {
      out << "| " << label(r) << " | failed: " << r.value("status", std::string("?")) << " |||||||||||||\n";
      continue;
    }
    const json& s = r["stages"];
    const json& e = r["edits"];
    std::string obj = sec(med(s, "read_obj"));
    if (s["read_ascii"].is_object()) obj += " (ASCII PLY " + sec(med(s, "read_ascii")) + ")";
    out << "| " << label(r) << " | " << r["mesh"]["faces"].get<long>() << " | " << sec(med(s, "read_ply")) << " | " << obj << " | "
        << sec(med(s, "topology")) << " | " << sec(med(s, "geometry")) << " | " << sec(med(s, "cycles")) << " | " << sec(med(s, "plan"))
        << " | " << sec(med(s, "analysis")) << " | " << sec(med(s, "setup")) << " (" << fmt(med(s, "assemble")) << " / "
        << fmt(med(s, "analysis_wait")) << " / " << fmt(med(s, "factor")) << " / " << fmt(med(s, "schur")) << ")"
        << " | " << sec(med(s, "prepare")) << " | " << ms(med(e, "solve")) << " | " << ms(med(e, "field")) << " | " << ms(med(e, "whole"))
        << " | " << gb(r["rss"]["peak"].get<double>()) << " |\n";
  }
  out << "\n² On the second thread, while the first computes the geometry and the field plan (trivcon/design.h); *wait* is the "
         "time the set-up waited for that thread's analysis (ordering and symbolic factorization), and *factor* is the numeric "
         "factorization (with the ordering and symbolic factorization where the analysis was not adopted: "
      <<
      [&] {
        std::string own;
        for (const json& r : runs)
          if (r.value("status", "") == "ok" && !r.value("analysis_concurrent", true))
            own += (own.empty() ? "" : ", ") + r["name"].get<std::string>();
        return own.empty() ? std::string("none") : own;
      }()
      << "). *prepare* is the wall time of the whole (less than the sum of the stages).\n";
  for (const json& r : runs)
    if (r.contains("cotan_error"))
      out << "\n† " << r["name"].get<std::string>() << ": with cotangent weights (the default) the set-up fails: \""
          << r["cotan_error"].get<std::string>().substr(7) << "\". Measured with unit weights instead (the same matrix structure, "
          << "except that no edge is dropped for a zero weight).\n";
  out << "\n### Spread (min–max over the same runs; seconds for stages, milliseconds for edits)\n\n";
  out << "| mesh | read | topology | geometry | cycles | field plan | analysis | set-up | prepare | edit solve (ms) | edit field (ms) | "
         "whole edit (ms) |\n";
  out << "|---|---:|---:|---:|---:|---:|---:|---:|---:|---:|---:|---:|\n";
  for (const json& r : runs) {
    if (r.value("status", "") != "ok") continue;
    const json& s = r["stages"];
    const json& e = r["edits"];
    out << "| " << label(r) << " | " << range_s(s, "read_ply") << " | " << range_s(s, "topology") << " | " << range_s(s, "geometry")
        << " | " << range_s(s, "cycles") << " | " << range_s(s, "plan") << " | " << range_s(s, "analysis") << " | " << range_s(s, "setup")
        << " | " << range_s(s, "prepare") << " | " << range_ms(e, "solve") << " | " << range_ms(e, "field") << " | " << range_ms(e, "whole")
        << " |\n";
  }
  out << "\n### Mesh facts and checks (last edit, verified outside the timings)\n\n";
  out << "| mesh | vertices | components | loops | generators | singularities (N) | max vertex residual | max cycle residual | "
         "transport mismatch | index mismatches | edges with \\|x\\| ≥ π/N | verify (not in edit) | fill-reducing order | load avg before "
         "/ after |\n";
  out << "|---|---:|---:|---:|---:|---:|---:|---:|---:|---:|---:|---:|---|---:|\n";
  for (const json& r : runs) {
    if (r.value("status", "") != "ok") continue;
    const json& m = r["mesh"];
    const json& c = r["check"];
    char res[3][32];
    std::snprintf(res[0], 32, "%.1e", c["max_vertex_residual"].get<double>());
    std::snprintf(res[1], 32, "%.1e", c["max_cycle_residual"].get<double>());
    std::snprintf(res[2], 32, "%.1e", c["transport_mismatch"].get<double>());
    out << "| " << label(r) << " | " << m["vertices"].get<long>() << " | " << m["components"].get<long>() << " | "
        << m["boundary_loops"].get<long>() << " | " << m["generators"].get<long>() << " | " << r["singularities"].get<int>() << " ("
        << r["N"].get<int>() << ") | " << res[0] << " | " << res[1] << " | " << res[2] << " | " << c["index_mismatch_vertices"].get<int>()
        << " | " << c.value("large_turn_edges", -1) << " | " << ms(med(r["edits"], "verify")) << " | "
        << r.value("ordering", std::string("?")) << " | " << fmt(r.value("loadavg_before", NAN), 2) << " / "
        << fmt(r.value("loadavg_after", NAN), 2) << " |\n";
  }

  if (!qrs.empty()) {
    out << "\n### Ours against the paper-literal QR solver (SolverKind::QR), same process, same edits\n\n";
    out << "| mesh | faces | set-up ours | set-up QR (factor) | QR / ours | edit ours | edit QR | QR / ours | peak RSS during QR set-up | "
           "max. difference of x (rad) |\n";
    out << "|---|---:|---:|---:|---:|---:|---:|---:|---:|---:|\n";
    for (const json& q : qrs) {
      const std::string name = q["name"].get<std::string>();
      if (q.value("status", "") != "ok") {
        out << "| " << name << " | | failed: " << q.value("status", std::string("?")) << " ||||||||\n";
        continue;
      }
      const double so = med(q["ours"], "setup");
      const json& Q = q["qr"];
      if (Q["status"] != "ok") {
        out << "| " << name << " | " << q["mesh"]["faces"].get<long>() << " | " << sec(so) << " | " << Q.value("reason", std::string(""))
            << " | — | — | — | — | " << gb(Q.value("peak_rss", NAN)) << " | — |\n";
        continue;
      }
      const double sq = med(Q, "setup"), eo = med(q["ours"], "whole"), eq = med(Q, "whole");
      char dx[32];
      std::snprintf(dx, 32, "%.1e", q["agreement"]["max_abs_dx"].get<double>());
      out << "| " << name << " | " << q["mesh"]["faces"].get<long>() << " | " << sec(so) << " | " << sec(sq) << " ("
          << fmt(med(Q, "factor")) << ", n=" << Q["setup"]["n"].get<int>() << ") | " << fmt(sq / so) << "× | " << ms(eo) << " | " << ms(eq)
          << " | " << fmt(eq / eo) << "× | " << gb(Q["rss_peak_during_setup"].get<double>()) << " | " << dx << " |\n";
    }
  }

  // Growth exponents per family.
  std::map<std::string, std::vector<const json*>> families;
  for (const json& r : runs)
    if (r.value("status", "") == "ok" && r.value("family", "") != "" && r.value("fit", false)) families[r["family"]].push_back(&r);
  if (!families.empty()) {
    out << "\n### Growth: exponent b of time ∝ faces^b (least squares on log–log over the generated sizes)\n\n";
    out << "| family | sizes (faces) | prepare | set-up | factor | edit solve | edit field | whole edit | peak RSS |\n";
    out << "|---|---|---:|---:|---:|---:|---:|---:|---:|\n";
    for (auto& [fam, list] : families) {
      std::vector<double> x;
      std::string sizes;
      for (const json* r : list)
        x.push_back((*r)["mesh"]["faces"].get<double>()),
            sizes += (sizes.empty() ? "" : ", ") + faces_str((*r)["mesh"]["faces"].get<long>());
      auto slope = [&](const char* group, const char* key) {
        std::vector<double> y;
        for (const json* r : list) y.push_back(med((*r)[group], key));
        return fmt(loglog_slope(x, y), 3);
      };
      std::vector<double> mem;
      for (const json* r : list) mem.push_back((*r)["rss"]["peak"].get<double>());
      out << "| " << fam << " | " << sizes << " | " << slope("stages", "prepare") << " | " << slope("stages", "setup") << " | "
          << slope("stages", "factor") << " | " << slope("edits", "solve") << " | " << slope("edits", "field") << " | "
          << slope("edits", "whole") << " | " << fmt(loglog_slope(x, mem), 3) << " |\n";
    }
  }

  // The targets.
  out << "\n### Targets of the issue\n\n| target | mesh | measured (median) | target | met |\n|---|---|---:|---:|---|\n";
  auto find = [&](const std::string& name) -> const json* {
    for (const json& r : runs)
      if (r["name"] == name && r.value("status", "") == "ok") return &r;
    return nullptr;
  };
  auto row = [&](const std::string& what, const std::string& name, double v, double target, bool is_ms, bool is_gb = false) {
    if (!std::isfinite(v)) return;
    const std::string m = is_gb ? gb(v) : is_ms ? ms(v) : sec(v);
    const std::string t = is_gb ? gb(target) : is_ms ? ms(target) : sec(target);
    out << "| " << what << " | " << name << " | " << m << " | ≤ " << t << " | " << (v <= target ? "yes" : "**no**") << " |\n";
  };
  for (const json& r : runs) {
    if (r.value("status", "") != "ok") continue;
    const std::string name = r["name"];
    const long f = r["mesh"]["faces"].get<long>();
    const json& s = r["stages"];
    const json& e = r["edits"];
    if (r.value("target_class", "") == "400k") {
      row("set-up after reading (FieldDesigner: topology, geometry, cycles, field plan, solver)", name, med(s, "prepare"), 1.0, false);
      row("one edit", name, med(e, "whole"), 0.060, true);
      row("read OBJ", name, med(s, "read_obj"), 0.6, false);
      if (r["auto"].is_object()) row("automatic placement (--auto) beyond the set-up", name, med(r["auto"], "total"), 1.0, false);
    } else if (r.value("target_class", "") == "dragon") {
      row("set-up after reading", name, med(s, "prepare"), 2.5, false);
      row("one edit", name, med(e, "whole"), 0.150, true);
      row("read binary PLY", name, med(s, "read_ply"), 0.4, false);
    } else if (r.value("target_class", "") == "3.5M") {
      row("set-up after reading", name + " (" + faces_str(f) + ")", med(s, "prepare"), 12, false);
      row("one edit", name, med(e, "whole"), 0.6, true);
      row("peak memory", name, r["rss"]["peak"].get<double>(), 4e9, false, true);
    }
  }
  (void)find;
  (void)quick;
}

struct Entry {
  MeshSpec mesh;
  std::string target_class;
  bool fit = false;
  std::string ascii;  // the original file, timed as well (the dragon's ASCII PLY)
};

int driver(const std::string& cache, const std::string& dragon, const std::string& json_path, const std::string& only, bool quick,
           RunOptions o, double qr_max_faces) {
  fs::create_directories(cache);
  std::vector<Entry> entries;
  // Generated sizes near 100k, 400k, 1.6M, 6.4M faces: cube-like spheres (12 n² faces) and tori (2 nu nv, nu ≈ 2.5 nv: R/r = 2.5).
  const std::vector<std::pair<std::string, int>> cube = {{"100k", 91}, {"400k", 183}, {"1.6M", 365}, {"6.4M", 730}};
  const std::vector<std::pair<std::string, std::pair<int, int>>> torus = {
      {"100k", {355, 141}}, {"400k", {707, 283}}, {"1.6M", {1413, 566}}, {"6.4M", {2829, 1131}}};
  for (size_t k = 0; k < cube.size(); ++k) {
    if (quick && k >= 2) break;
    const bool qr = (k == 0 || k == 1) && (k == 0 ? 1e5 : 4e5) <= qr_max_faces;
    entries.push_back({{"sphere-" + cube[k].first, "sphere (cube-like)", "cube:" + std::to_string(cube[k].second), qr},
                       cube[k].first == "400k" ? "400k" : "",
                       true,
                       ""});
  }
  for (size_t k = 0; k < torus.size(); ++k) {
    if (quick && k >= 2) break;
    const bool qr = (k == 0 || k == 1) && (k == 0 ? 1e5 : 4e5) <= qr_max_faces;
    entries.push_back({{"torus-" + torus[k].first, "torus",
                        "torus:" + std::to_string(torus[k].second.first) + ":" + std::to_string(torus[k].second.second), qr},
                       torus[k].first == "400k" ? "400k" : "",
                       true,
                       ""});
  }
  if (!quick) {
    if (!dragon.empty() && fs::exists(dragon)) {
      entries.push_back(
          {{"dragon", "", "file:" + fs::weakly_canonical(dragon).string(), false}, "dragon", false, fs::weakly_canonical(dragon).string()});
      entries.push_back({{"dragon-subdivided", "", "subdiv:" + fs::weakly_canonical(dragon).string(), false}, "3.5M", false, ""});
    } else {
      log("dragon not found (" + dragon + "): skipping the dragon meshes");
    }
  }
  if (!only.empty()) {
    const std::vector<std::string> keep = split(only, ',');
    std::vector<Entry> kept;
    for (const Entry& e : entries)
      if (std::find(keep.begin(), keep.end(), e.mesh.name) != keep.end()) kept.push_back(e);
    entries = kept;
  }

  json runs = json::array(), qrs = json::array();
  auto reps_args = [&](const RunOptions& ro) {
    return std::vector<std::string>{"--warmup",      std::to_string(ro.warmup),      "--reps",  std::to_string(ro.reps),
                                    "--edit-warmup", std::to_string(ro.edit_warmup), "--edits", std::to_string(ro.edits),
                                    "--N",           std::to_string(ro.N),           "--count", std::to_string(ro.count)};
  };
  for (const Entry& e : entries) {
    const std::string stem = cache + "/" + cache_stem(e.mesh.spec);
    const std::string ply = stem + ".ply", obj = stem + ".obj";
    log("== " + e.mesh.name + " (" + e.mesh.spec + ")");
    int rc = spawn_self({"--child", "prepare", "--spec", e.mesh.spec, "--ply", ply, "--obj", obj});
    if (rc != 0) {
      runs.push_back(json{{"name", e.mesh.name}, {"status", "prepare failed (exit " + std::to_string(rc) + ")"}});
      continue;
    }
    const RunOptions& ro = o;
    std::error_code ec;
    const std::string out = stem + ".result.json";
    fs::remove(out, ec);
    std::vector<std::string> args{"--child", "run", "--name", e.mesh.name, "--ply", ply, "--out", out};
    if (fs::exists(obj)) args.insert(args.end(), {"--obj", obj});
    if (!e.ascii.empty()) args.insert(args.end(), {"--ascii", e.ascii});
    for (auto& a : reps_args(ro)) args.push_back(a);
    const double load_before = loadavg();
    auto run_child = [&](const std::vector<std::string>& a) {
      fs::remove(out, ec);
      const int code = spawn_self(a);
      json j;
      if (fs::exists(out)) {
        std::ifstream in(out);
        j = json::parse(in);
      }
      if (code != 0 && j.value("status", "") == "ok") j["status"] = "exit " + std::to_string(code);
      if (j.is_null()) j = json{{"name", e.mesh.name}, {"status", "run failed (exit " + std::to_string(code) + ")"}};
      return j;
    };
    json r = run_child(args);
    std::string weights = o.weights;
    if (weights == "cotan" && r.value("status", "").find("--weights unit") != std::string::npos) {
      // The mesh cannot be solved with (clamped) cotangent weights: measure it with unit weights (the same
      // matrix structure, up to the zero-weight edges), and say so.
      log("  cotan weights fail on " + e.mesh.name + "; measuring with unit weights");
      const std::string cotan_error = r["status"];
      args.insert(args.end(), {"--weights", "unit"});
      r = run_child(args);
      r["cotan_error"] = cotan_error;
      weights = "unit";
    }
    r["weights"] = weights;
    r["loadavg_before"] = load_before;
    r["loadavg_after"] = loadavg();
    r["family"] = e.mesh.family;
    r["spec"] = e.mesh.spec;
    r["fit"] = e.fit;
    r["target_class"] = e.target_class;
    runs.push_back(r);
#ifdef TRIVCON_WITH_SUITESPARSE
    const bool with_qr = e.mesh.qr;
#else
    const bool with_qr = false;  // the QR route needs a build with -DTRIVCON_WITH_SUITESPARSE=ON (GPL)
    if (e.mesh.qr) std::cerr << "bench: " << e.mesh.name << ": no QR comparison in a build without -DTRIVCON_WITH_SUITESPARSE=ON\n";
#endif
    if (with_qr) {
      const std::string qout = stem + ".qr.json";
      fs::remove(qout, ec);
      std::vector<std::string> qargs{"--child",
                                     "qr",
                                     "--name",
                                     e.mesh.name,
                                     "--ply",
                                     ply,
                                     "--out",
                                     qout,
                                     "--weights",
                                     weights,
                                     "--qr-reps",
                                     std::to_string(o.qr_reps),
                                     "--qr-time-limit",
                                     std::to_string(o.qr_time_limit),
                                     "--qr-mem-limit-gb",
                                     std::to_string(o.qr_mem_limit_gb)};
      RunOptions qo = o;
      qo.edits = std::min(o.edits, 10), qo.edit_warmup = std::min(o.edit_warmup, 1);
      for (auto& a : reps_args(qo)) qargs.push_back(a);
      log("== " + e.mesh.name + ": ours against QR");
      rc = spawn_self(qargs);
      json q;
      if (rc == 0 && fs::exists(qout)) {
        std::ifstream in(qout);
        q = json::parse(in);
      } else {
        q = json{{"name", e.mesh.name}, {"status", "QR run failed (exit " + std::to_string(rc) + ")"}};
      }
      qrs.push_back(q);
    }
    if (!json_path.empty()) write_json(json_path, json{{"runs", runs}, {"qr", qrs}});
  }
  if (!json_path.empty()) write_json(json_path, json{{"runs", runs}, {"qr", qrs}});
  print_tables(runs, qrs, o, quick);
  return 0;
}

}  // namespace

int main(int argc, char** argv) {
  use_tuned_process(argv);  // as the trivcon program does (trivcon/tuned_process.h); its children inherit it
  CLI::App app{"trivcon benchmark: reading, set-up and edits on generated and real meshes"};
  std::string child, spec, cache = "bench-cache", dragon, json_path, only;
  RunOptions o;
  bool quick = false;
  double qr_max_faces = 5e5;
  app.add_option("--child", child, "internal: prepare | run | qr");
  app.add_option("--spec", spec, "internal: mesh spec");
  app.add_option("--ply", o.ply);
  app.add_option("--obj", o.obj);
  app.add_option("--ascii", o.ascii);
  app.add_option("--out", o.out);
  app.add_option("--name", o.name);
  app.add_option("--cache", cache, "directory for the generated mesh files and per-mesh results")->capture_default_str();
  app.add_option("--dragon", dragon, "the Stanford dragon (dragon_vrip.ply); absent: the dragon rows are skipped");
  app.add_option("--json", json_path, "write all results as JSON here");
  app.add_option("--meshes", only, "only these meshes (comma-separated names, e.g. sphere-400k,dragon)");
  app.add_flag("--quick", quick, "only the meshes up to 400k faces, few repetitions");
  app.add_option("--warmup", o.warmup, "discarded pipeline runs per mesh")->capture_default_str();
  app.add_option("--reps", o.reps, "timed pipeline runs per mesh (3 at most above 2M faces)")->capture_default_str();
  app.add_option("--edit-warmup", o.edit_warmup, "discarded edits per mesh")->capture_default_str();
  app.add_option("--edits", o.edits, "timed edits per mesh (10 at most above 2M faces)")->capture_default_str();
  app.add_option("--weights", o.weights, "cotan | unit (meshes whose cotan weights fail are rerun with unit weights)")
      ->capture_default_str();
  app.add_option("--N", o.N, "symmetry of the edited field")->capture_default_str();
  app.add_option("--count", o.count, "singularities per edit (adjusted for Gauss-Bonnet, see bench/edits.h)")->capture_default_str();
  app.add_option("--qr-reps", o.qr_reps, "QR set-up runs (1 when the first takes over 20 s)")->capture_default_str();
  app.add_option("--qr-max-faces", qr_max_faces, "compare with QR on generated meshes up to this size")->capture_default_str();
  app.add_option("--qr-time-limit", o.qr_time_limit, "seconds before a QR set-up is abandoned")->capture_default_str();
  app.add_option("--qr-mem-limit-gb", o.qr_mem_limit_gb, "resident GB before a QR set-up is abandoned")->capture_default_str();
  bool print_kernels = false;
  app.add_flag("--blas-kernels", print_kernels, "print the BLAS kernels in use (trivcon/blas.h) and exit");
  CLI11_PARSE(app, argc, argv);
  if (print_kernels) {
    std::cout << (blas_kernels().empty() ? "not OpenBLAS" : blas_kernels()) << std::endl;
    return 0;
  }
  try {
    if (child == "prepare") return child_prepare(spec, o.ply, o.obj);
    if (child == "run") return child_run(o);
    if (child == "qr") return child_qr(o);
    if (!child.empty()) throw std::runtime_error("unknown --child " + child);
    if (quick && app.count("--reps") == 0) o.reps = 2;
    if (quick && app.count("--edits") == 0) o.edits = 5;
    if (quick && app.count("--qr-reps") == 0) o.qr_reps = 1;
    if (quick && app.count("--qr-max-faces") == 0) qr_max_faces = 1e5;
    return driver(cache, dragon, json_path, only, quick, o, qr_max_faces);
  } catch (const std::exception& e) {
    std::cerr << "bench_trivcon: " << e.what() << std::endl;
    if (!child.empty() && !o.out.empty()) write_json(o.out, json{{"name", o.name}, {"status", std::string("error: ") + e.what()}});
    return 1;
  }
}
