// SPDX-License-Identifier: MIT
// trivcon._core: the pybind11 extension behind the `trivcon` Python package (python/trivcon/).
//
// This file holds no numerics: every function converts arrays, calls the library (trivcon/*.h) and converts
// back. The package's Python layer (python/trivcon/__init__.py) checks shapes and dtypes and turns indices
// into the library's "p/q" text before anything reaches here, so the arrays that arrive are already
// C-contiguous float64 (n, 3) and int32 (m, 3); what is left to check (ids against the mesh, the
// prescription, the files) is the library's, with its messages: trivcon::Error becomes trivcon.Error (a
// ValueError) carrying what() unchanged, the text the CLI prints after "trivcon: error: ".
//
// The GIL is released around everything that takes time (reading, set-up and factorization, solves,
// automatic placement, rendering, writing); a FieldDesigner's own mutex keeps two Python threads from
// changing its fixed faces or solving on it at the same moment.
//
// Ctrl-C: the long calls (reading a mesh, a designer's set-up, solves, automatic placement, refinement,
// reading indices, rendering, unpickling) run on a thread of their own (`interruptible`) while the calling
// thread waits in slices of 20 ms; between slices the main thread takes the GIL and runs Python's signal
// handlers (PyErr_CheckSignals), so a KeyboardInterrupt is raised within a slice. The work is then
// abandoned: its flag is set (trivcon/cancel.h), the library stops at its next safe point, and the thread
// frees what it built; it owns copies or shared pointers of everything it reads, never a Python object, so
// nothing it touches goes away under it. The package waits for abandoned work at exit (wait_for_background).
//
// Threads: each such call runs with the thread count of its designer (or the module's default) as OpenMP's
// setting of its own thread (omp_set_num_threads is per calling thread), and with one thread, OpenBLAS
// single-threaded while it runs (trivcon::SingleThreadedBlas: OpenBLAS has one setting per process).
#include <Python.h>
#include <unistd.h>
#include <dlfcn.h>
#include <omp.h>
#include <pybind11/eigen.h>
#include <pybind11/numpy.h>
#include <pybind11/pybind11.h>
#include <pybind11/stl.h>

#include <unistd.h>

#include <algorithm>
#include <atomic>
#include <cctype>
#include <chrono>
#include <condition_variable>
#include <cstdint>
#include <cstring>
#include <exception>
#include <map>
#include <memory>
#include <mutex>
#include <optional>
#include <set>
#include <string>
#include <thread>
#include <tuple>
#include <type_traits>
#include <utility>
#include <vector>

#include "report.h"
#include "trivcon/auto.h"
#include "trivcon/quad.h"
#include "trivcon/blas.h"
#include "trivcon/cancel.h"
#include "trivcon/split_large_turns.h"
#include "trivcon/constraints.h"
#include "trivcon/design.h"
#include "trivcon/repair.h"
#include "trivcon/request.h"
#include "trivcon/features.h"
#include "trivcon/error.h"
#include "trivcon/field.h"
#include "trivcon/field_io.h"
#include "trivcon/generate.h"
#include "trivcon/param.h"
#include "trivcon/indices.h"
#include "trivcon/io.h"
#include "trivcon/matching.h"
#include "trivcon/render.h"

namespace py = pybind11;

namespace trivcon::python {

namespace {

using Int64Array = py::array_t<std::int64_t>;
using DoubleArray = py::array_t<double>;

// --- Long calls on a thread of their own, abandoned on KeyboardInterrupt (see the top of this file).

// Long calls still running (abandoned or not) and their cancellation flags; never destroyed (such work may
// outlive the module's static objects).
struct Background {
  std::mutex mutex;
  std::condition_variable idle;
  int running = 0;
  std::set<std::shared_ptr<std::atomic<bool>>> flags;
};
Background& background() {
  static Background* b = new Background();
  return *b;
}

// The module's default thread count (0: OpenMP's, i.e. OMP_NUM_THREADS or every core); set_threads.
std::atomic<int> default_threads{0};
// Python's main thread: the only one whose waits run signal handlers.
unsigned long main_thread_ident = 0;

// A call's threads, on the thread that makes it: OpenMP's count for this thread only, and OpenBLAS on one
// thread while a one-thread call runs (for the whole process: OpenBLAS has one setting).
class CallThreads {
 public:
  explicit CallThreads(int threads) {
    if (threads > 0) omp_set_num_threads(threads);
    if (threads == 1) blas_.emplace();
  }

 private:
  std::optional<SingleThreadedBlas> blas_;
};

// Lines a task posts for the calling thread to pass to a Python callable (post_line; the map search's progress).
struct JobLines {
  std::mutex mutex;
  std::vector<std::string> lines;
};
// The lines of the job running on this thread (null: none wanted).
thread_local JobLines* current_job_lines = nullptr;

// From a task: queues `line` for its caller's callable, which gets it the next time the caller wakes (every 20 ms
// while it waits, and once more when the task ends). Nothing without a callable.
void post_line(const std::string& line) {
  if (JobLines* lines = current_job_lines) {
    std::lock_guard<std::mutex> lock(lines->mutex);
    lines->lines.push_back(line);
  }
}

template <class T>
struct Job {
  std::mutex mutex;
  std::condition_variable finished;
  bool done = false, abandoned = false;
  std::shared_ptr<std::atomic<bool>> cancel = std::make_shared<std::atomic<bool>>(false);
  std::optional<T> value;
  std::exception_ptr error;
  std::shared_ptr<JobLines> lines = std::make_shared<JobLines>();
};

// Runs task() on a new thread with `threads` threads (0: the module's default, negative: OpenMP's) and returns its value; the
// caller must hold the GIL. KeyboardInterrupt (or whatever a Python signal handler raises) abandons the
// task: it is cancelled and frees its results itself. The task must own what it reads (copies, shared
// pointers) and must not touch Python objects. With `on_line` (not None), the lines the task posts (post_line)
// are passed to it on the calling thread, in order; what it raises abandons the task the same way.
template <class Task>
std::invoke_result_t<Task&> interruptible(int threads, Task task, py::object on_line = py::none()) {
  using T = std::invoke_result_t<Task&>;
  if (threads == 0) threads = default_threads.load();
  auto job = std::make_shared<Job<T>>();
  Background& bg = background();
  {
    std::lock_guard<std::mutex> lock(bg.mutex);
    ++bg.running;
    bg.flags.insert(job->cancel);
  }
  try {
    const bool wants_lines = !on_line.is_none();
    std::thread([job, threads, wants_lines, work = std::optional<Task>(std::move(task))]() mutable {
      {
        CallThreads setting(threads);
        CancelScope scope(job->cancel);
        const std::shared_ptr<JobLines> lines = job->lines;
        current_job_lines = wants_lines ? lines.get() : nullptr;
        try {
          job->value.emplace((*work)());
        } catch (...) {
          job->error = std::current_exception();
        }
        work.reset();  // its inputs are freed here, before the work counts as finished
      }
      bool abandoned;
      {
        std::lock_guard<std::mutex> lock(job->mutex);
        job->done = true;
        abandoned = job->abandoned;
      }
      job->finished.notify_all();
      if (abandoned) job->value.reset(), job->error = nullptr;
      std::shared_ptr<std::atomic<bool>> flag = job->cancel;
      job.reset();
      Background& b = background();
      {
        std::lock_guard<std::mutex> lock(b.mutex);
        --b.running;
        b.flags.erase(flag);
      }
      b.idle.notify_all();
    }).detach();
  } catch (...) {  // no thread
    std::lock_guard<std::mutex> lock(bg.mutex);
    --bg.running;
    bg.flags.erase(job->cancel);
    throw;
  }
  const bool poll = PyThread_get_thread_ident() == main_thread_ident;
  {
    // The GIL is taken back in the normal flow, not in a destructor: a daemon thread that comes back while the
    // interpreter is finalizing must not try (3.11 ends the thread inside PyEval_RestoreThread, and unwinding
    // through a noexcept destructor terminates the process); it sleeps until the process ends instead.
    struct Release {
      PyThreadState* state = PyEval_SaveThread();
      void restore() {
        if (!state) return;
        if (_Py_IsFinalizing() && !poll_thread)
          for (;;) pause();
        PyEval_RestoreThread(state);
        state = nullptr;
      }
      bool poll_thread = false;
      ~Release() { restore(); }
    } release;
    release.poll_thread = poll;
    auto abandon = [&] {
      std::lock_guard<std::mutex> guard(job->mutex);
      if (!job->done) job->abandoned = true, *job->cancel = true;
    };
    // The task's lines so far to on_line, with the GIL; what it raises abandons the task.
    auto deliver = [&] {
      if (on_line.is_none()) return;
      std::vector<std::string> lines;
      {
        std::lock_guard<std::mutex> guard(job->lines->mutex);
        lines.swap(job->lines->lines);
      }
      if (lines.empty()) return;
      py::gil_scoped_acquire acquire;
      try {
        for (const std::string& line : lines) on_line(line);
      } catch (...) {
        abandon();
        throw;
      }
    };
    std::unique_lock<std::mutex> lock(job->mutex);
    while (!job->finished.wait_for(lock, std::chrono::milliseconds(20), [&] { return job->done; })) {
      lock.unlock();
      deliver();
      if (poll) {
        py::gil_scoped_acquire acquire;
        if (PyErr_CheckSignals() != 0) {
          abandon();
          throw py::error_already_set();
        }
      }
      lock.lock();
    }
    lock.unlock();
    deliver();  // the lines posted before it ended
    release.restore();
  }
  if (job->error) std::rethrow_exception(job->error);
  return std::move(*job->value);
}

// Waits until no long call is running, or `seconds` have passed (negative: no limit); returns whether none
// is left. With `cancel`, the calls still running are cancelled first (at exit: only daemon threads can still
// be in one). Signal handlers run meanwhile (a second Ctrl-C stops the wait).
bool wait_for_background(double seconds, bool cancel) {
  Background& bg = background();
  if (cancel) {
    std::lock_guard<std::mutex> lock(bg.mutex);
    for (const auto& flag : bg.flags) *flag = true;
  }
  const auto end = std::chrono::steady_clock::now() + std::chrono::duration<double>(seconds < 0 ? 1e9 : seconds);
  for (;;) {
    {
      py::gil_scoped_release release;
      std::unique_lock<std::mutex> lock(bg.mutex);
      if (bg.idle.wait_for(lock, std::chrono::milliseconds(20), [&] { return bg.running == 0; })) return true;
    }
    if (std::chrono::steady_clock::now() >= end) return false;
    if (PyErr_CheckSignals() != 0) throw py::error_already_set();
  }
}

// --- Conversions to numpy (copies; the library's arrays stay where they are).

Int64Array int64_matrix(const Eigen::Ref<const Eigen::Matrix<int, Eigen::Dynamic, Eigen::Dynamic, Eigen::RowMajor>>& m) {
  Int64Array out({static_cast<py::ssize_t>(m.rows()), static_cast<py::ssize_t>(m.cols())});
  auto o = out.mutable_unchecked<2>();
  for (Eigen::Index i = 0; i < m.rows(); ++i)
    for (Eigen::Index j = 0; j < m.cols(); ++j) o(i, j) = m(i, j);
  return out;
}

Int64Array int64_vector(const std::vector<int>& v) {
  Int64Array out(static_cast<py::ssize_t>(v.size()));
  std::copy(v.begin(), v.end(), out.mutable_data());
  return out;
}

DoubleArray double_vector(const Eigen::VectorXd& v) {
  DoubleArray out(static_cast<py::ssize_t>(v.size()));
  std::copy(v.data(), v.data() + v.size(), out.mutable_data());
  return out;
}

DoubleArray double_matrix3(const MatrixX3d& m) {
  DoubleArray out({static_cast<py::ssize_t>(m.rows()), static_cast<py::ssize_t>(3)});
  std::copy(m.data(), m.data() + m.size(), out.mutable_data());  // both row-major
  return out;
}

// A report entry (report/report.h) as Python objects, through Python's json module: the dicts of the module and the
// CLI's reports are written once.
py::object json_to_python(const nlohmann::ordered_json& j) { return py::module_::import("json").attr("loads")(j.dump()); }

py::tuple mesh_tuple(const Mesh& mesh) { return py::make_tuple(double_matrix3(mesh.V), int64_matrix(mesh.F)); }

// Whether two ParamOptions ask for the same map (scale, sizing, the same aligned edges in any order).
bool same_map_options(const ParamOptions& a, const ParamOptions& b) {
  std::vector<int> x = a.aligned_edges, y = b.aligned_edges;
  std::sort(x.begin(), x.end()), std::sort(y.begin(), y.end());
  x.erase(std::unique(x.begin(), x.end()), x.end()), y.erase(std::unique(y.begin(), y.end()), y.end());
  return a.edge_length == b.edge_length && a.target_faces == b.target_faces && a.sizing == b.sizing && x == y;
}

// A quad mesh as QuadMesh's arguments: (V, Q, face of each vertex, input vertex under each vertex or -1, quality
// dict (quad's report), warning).
py::tuple quads_tuple(const QuadMesh& q) {
  return py::make_tuple(double_matrix3(q.V), int64_matrix(q.Q),
                        int64_vector(std::vector<int>(q.vertex_face.data(), q.vertex_face.data() + q.vertex_face.size())),
                        int64_vector(std::vector<int>(q.vertex_cone.data(), q.vertex_cone.data() + q.vertex_cone.size())),
                        json_to_python(cli::quad_report(q)), quad_warning(q));
}

// --- Shared pieces.

Image to_image(const py::array_t<std::uint8_t, py::array::c_style | py::array::forcecast>& pixels) {
  if (pixels.ndim() != 3 || pixels.shape(2) != 3) throw Error("write_png: expected an (h, w, 3) uint8 image");
  Image image;
  image.height = static_cast<int>(pixels.shape(0));
  image.width = static_cast<int>(pixels.shape(1));
  image.rgb.assign(pixels.data(), pixels.data() + pixels.size());
  return image;
}

py::array_t<std::uint8_t> from_image(const Image& image) {
  py::array_t<std::uint8_t> out(
      {static_cast<py::ssize_t>(image.height), static_cast<py::ssize_t>(image.width), static_cast<py::ssize_t>(3)});
  std::copy(image.rgb.begin(), image.rgb.end(), out.mutable_data());
  return out;
}

// The render options of the Python API (the CLI's `render` options, same defaults).
struct RenderArgs {
  int width = 1200, height = 900;
  double azimuth = 30, elevation = 20;
  std::string up = "y", style = "hedgehog";
  double spacing = 11;
  bool flat = false, legend = true;
  int supersampling = 3;

  RenderOptions options() const {
    RenderOptions o;
    o.width = width, o.height = height, o.azimuth = azimuth, o.elevation = elevation;
    if (up.size() != 1) throw Error("render: up axis must be x, y or z, not '" + up + "'");
    o.up = up[0];
    if (style != "hedgehog" && style != "streamlines")
      throw Error("render: style must be 'hedgehog' or 'streamlines', not '" + style + "'");
    o.style = style == "streamlines" ? FieldStyle::Streamlines : FieldStyle::Hedgehog;
    o.glyph_spacing = spacing, o.smooth_shading = !flat, o.legend = legend, o.supersampling = supersampling;
    return o;
  }
};

// What `trivcon check` and `trivcon render` build from a mesh and a field file (apps/cmd_check.cpp).
struct PreparedMesh {
  Topology topology;
  Geometry geometry;
  PreparedMesh(const MatrixX3d& V, const MatrixX3i& F) {
    check_finite(V);
    topology = build_topology(F, static_cast<int>(V.rows()));
    geometry = compute_geometry(V, topology);
  }
};

void check_rows(const MatrixX3d& directions, int faces) {
  if (directions.rows() != faces)
    throw Error("the field has " + std::to_string(directions.rows()) + " directions but the mesh has " + std::to_string(faces) + " faces");
}

py::tuple indices_tuple(const FieldIndices& idx) {
  return py::make_tuple(int64_vector(idx.vertex), int64_vector(idx.loop), int64_vector(idx.generator));
}

// --- FieldDesigner.

struct DesignerState {
  MatrixX3d V;  // as given
  MatrixX3i F;  // as given (trivcon::FieldDesigner keeps the oriented copy in its topology)
  std::unique_ptr<FieldDesigner> designer;
  std::vector<int> fixed_faces;   // those the solver is factored for
  std::vector<int> sorted_edges;  // every edge, sorted by (i, j)
  int threads = 0;                // of its calls (0: the module's default)
  // When the mesh given needed repair (trivcon/repair.h): V and F above are the repair; these the input.
  std::shared_ptr<const RepairedMesh> repair;
  MatrixX3d input_V;
  MatrixX3i input_F;
  std::mutex mutex;

  const Topology& topology() const { return designer->topology(); }
  const Geometry& geometry() const { return designer->geometry(); }

  // Every edge, sorted by (i, j) (the order of connection files).
  void sort_edges() {
    const Topology& t = topology();
    sorted_edges.resize(t.num_edges);
    for (int e = 0; e < t.num_edges; ++e) sorted_edges[e] = e;
    std::sort(sorted_edges.begin(), sorted_edges.end(), [&](int a, int b) {
      return std::make_pair(t.edge_vertices(a, 0), t.edge_vertices(a, 1)) < std::make_pair(t.edge_vertices(b, 0), t.edge_vertices(b, 1));
    });
  }

  // Refactors only when the set of fixed faces changes (their angles are right-hand sides).
  void use_fixed_faces(const std::map<int, double>& fixed) {
    std::vector<int> faces;
    for (const auto& [f, angle] : fixed) faces.push_back(f);
    if (faces != fixed_faces) {
      designer->set_fixed_faces(faces);
      fixed_faces = faces;
    }
  }
};
using DesignerPtr = std::shared_ptr<DesignerState>;

SolverOptions solver_options(const std::string& weights, const std::string& solver, const std::string& factorization,
                             double weight_floor = 0) {
  SolverOptions o;
  if (!(weight_floor >= 0 && weight_floor <= 1))
    throw Error("weight_floor must be in [0, 1] (a fraction of the median weight), not " + std::to_string(weight_floor));
  o.weight_floor = weight_floor;
  if (weights != "cotan" && weights != "unit") throw Error("weights must be 'cotan' or 'unit', not '" + weights + "'");
  if (solver != "cholesky" && solver != "qr") throw Error("solver must be 'cholesky' or 'qr', not '" + solver + "'");
  if (factorization != "own" && factorization != "cholmod")
    throw Error("factorization must be 'own' or 'cholmod', not '" + factorization + "'");
  o.weights = weights == "unit" ? WeightKind::Unit : WeightKind::Cotan;
  o.solver = solver == "qr" ? SolverKind::QR : SolverKind::Cholesky;
  o.factorization = factorization == "cholmod" ? Factorization::Cholmod : Factorization::Parallel;
  return o;
}

int checked_threads(int threads) {
  if (threads < 0) throw Error("threads must be at least 0 (0: OpenMP's default), not " + std::to_string(threads));
  return threads;
}

// A designer on (V, F); factored now when `factor` (the constructor), else on its first solve (unpickling).
// With `repair`, a mesh that needs it is repaired first (the designer is on the repair).
DesignerPtr build_designer(MatrixX3d V, MatrixX3i F, const SolverOptions& options, int threads, bool factor, bool repair = false) {
  return interruptible(threads, [V = std::move(V), F = std::move(F), options, threads, factor, repair]() mutable {
    auto s = std::make_shared<DesignerState>();
    s->threads = threads;
    if (repair) {
      RepairedMesh r = repair_mesh(V, F);
      if (r.changed()) {
        s->input_V = std::move(V), s->input_F = std::move(F);
        V = r.V, F = r.F;
        s->repair = std::make_shared<const RepairedMesh>(std::move(r));
      }
    }
    s->V = std::move(V);
    s->F = std::move(F);
    s->designer = std::make_unique<FieldDesigner>(s->V, s->F, options);
    if (factor) s->designer->set_fixed_faces({});  // the constructor of the Python object validates and factors
    s->sort_edges();
    return s;
  });
}

DesignerPtr make_designer(MatrixX3d V, MatrixX3i F, const std::string& weights, const std::string& solver, const std::string& factorization,
                          double weight_floor, int threads, bool repair) {
  const SolverOptions options = solver_options(weights, solver, factorization, weight_floor);
  return build_designer(std::move(V), std::move(F), options, checked_threads(threads), true, repair);
}

// Pickling (the package's FieldDesigner.__getstate__): the mesh as given and every solver option, including
// the per-edge weight scales a refined designer may carry (trivcon/split_large_turns.h). Not the factorization.
py::dict designer_state(const DesignerState& s) {
  const SolverOptions& o = s.designer->solver_options();
  py::dict d;
  d["V"] = py::array_t<double>({static_cast<py::ssize_t>(s.V.rows()), static_cast<py::ssize_t>(3)}, s.V.data());
  py::array_t<std::int32_t> F({static_cast<py::ssize_t>(s.F.rows()), static_cast<py::ssize_t>(3)}, s.F.data());
  d["F"] = F;
  d["weights"] = o.weights == WeightKind::Unit ? "unit" : "cotan";
  d["solver"] = o.solver == SolverKind::QR ? "qr" : "cholesky";
  d["factorization"] = o.factorization == Factorization::Cholmod ? "cholmod" : "own";
  d["weight_floor"] = o.weight_floor;
  d["edge_weight_scale"] = o.edge_weight_scale;
  d["threads"] = s.threads;
  if (s.repair) {  // the input as given: restoring repairs it again (the same repair: it is deterministic)
    d["V"] = py::array_t<double>({static_cast<py::ssize_t>(s.input_V.rows()), static_cast<py::ssize_t>(3)}, s.input_V.data());
    d["F"] = py::array_t<std::int32_t>({static_cast<py::ssize_t>(s.input_F.rows()), static_cast<py::ssize_t>(3)}, s.input_F.data());
    d["repair"] = true;
  }
  return d;
}

DesignerPtr restore_designer(const py::dict& d) {
  SolverOptions o = solver_options(d["weights"].cast<std::string>(), d["solver"].cast<std::string>(),
                                   d["factorization"].cast<std::string>(), d["weight_floor"].cast<double>());
  o.edge_weight_scale = d["edge_weight_scale"].cast<std::vector<double>>();
  return build_designer(d["V"].cast<MatrixX3d>(), d["F"].cast<MatrixX3i>(), o, checked_threads(d["threads"].cast<int>()), false,
                        d.contains("repair") && d["repair"].cast<bool>());
}

void check_face(const Topology& t, int f, const std::string& what) {
  if (f < 0 || f >= t.num_faces)
    throw Error(what + " " + std::to_string(f) + " out of range (mesh has " + std::to_string(t.num_faces) + " faces)");
}

// --- A design: the library's Design with the prescription it answers.

struct DesignResult {
  DesignerPtr state;
  IndexPrescription prescription;
  std::map<int, int> corners;  // boundary vertices made corners of the aligned boundary (FeatureAlignment::corners)
  Design design;
  bool verified = false;
  // With solve(..., map_target_faces / map_edge_length): the map map_request kept for this field (with its quad
  // mesh) and the options it was made with; parametrize with the same options gives it back (the program's map,
  // not made again). Not pickled.
  std::shared_ptr<const ScaledMap> map;
  ParamOptions map_options;
  int search_maps = 0;          // MapOutcome::maps, stopped (not pickled)
  bool search_stopped = false;

  // Interior edges sorted by (i, j) with their x: the rows of `trivcon solve --connection-out`.
  py::tuple connection() const {
    const Topology& t = state->topology();
    std::vector<int> interior;
    for (int e : state->sorted_edges)
      if (!t.is_boundary_edge(e)) interior.push_back(e);
    Int64Array edges({static_cast<py::ssize_t>(interior.size()), static_cast<py::ssize_t>(2)});
    DoubleArray x(static_cast<py::ssize_t>(interior.size()));
    auto E = edges.mutable_unchecked<2>();
    auto X = x.mutable_unchecked<1>();
    for (size_t k = 0; k < interior.size(); ++k) {
      E(k, 0) = t.edge_vertices(interior[k], 0), E(k, 1) = t.edge_vertices(interior[k], 1);
      X(k) = design.connection.x(interior[k]);
    }
    return py::make_tuple(edges, x);
  }

  // The connection's matching (trivcon/matching.h) per interior edge, in the same order as connection().
  Int64Array matching() const {
    const Topology& t = state->topology();
    Eigen::VectorXi m;
    {
      py::gil_scoped_release release;
      m = connection_matching(t, state->geometry(), design.field, design.connection.x);
    }
    std::vector<int> interior;
    for (int e : state->sorted_edges)
      if (!t.is_boundary_edge(e)) interior.push_back(e);
    Int64Array out(static_cast<py::ssize_t>(interior.size()));
    auto M = out.mutable_unchecked<1>();
    for (size_t k = 0; k < interior.size(); ++k) M(k) = m[interior[k]];
    return out;
  }
};
using DesignResultPtr = std::shared_ptr<DesignResult>;

template <class Map>
py::list map_items(const Map& m) {
  py::list out;
  for (const auto& [k, v] : m) out.append(py::make_tuple(k, v));
  return out;
}

template <class K, class V>
std::map<K, V> items_map(const py::handle& items) {
  std::map<K, V> out;
  for (const auto& item : items.cast<std::vector<std::pair<K, V>>>()) out.insert(item);
  return out;
}

// Pickling (the package's Result.__getstate__): the prescription and everything the design computed, so that
// a restored Result gives the same numbers without solving again.
py::dict design_state(const DesignResult& r) {
  const Design& d = r.design;
  const Connection& c = d.connection;
  py::dict s;
  s["N"] = r.prescription.N;
  s["vertex"] = map_items(r.prescription.vertex);
  s["corners"] = map_items(r.corners);
  s["generator"] = map_items(r.prescription.generator);
  s["loop"] = map_items(r.prescription.loop);
  s["fixed"] = map_items(r.prescription.fixed);
  s["x"] = double_vector(c.x);
  s["generator_index"] = c.generator_index;
  s["loop_index"] = c.loop_index;
  s["generator_chosen"] = std::vector<int>(c.generator_chosen.begin(), c.generator_chosen.end());
  s["loop_chosen"] = std::vector<int>(c.loop_chosen.begin(), c.loop_chosen.end());
  s["path_turn"] = c.path_turn;
  s["energy"] = c.energy;
  s["residuals"] = py::make_tuple(c.max_vertex_residual, c.max_cycle_residual, c.rhs_scale);
  s["refinements"] = c.refinements;
  s["angle"] = double_vector(d.field.angle);
  s["indices"] = py::make_tuple(d.indices.vertex, d.indices.loop, d.indices.generator, d.indices.max_rounding);
  s["transport_mismatch"] = d.transport_mismatch;
  s["index_mismatch_vertices"] = d.index_mismatch_vertices;
  s["large_turn_edges"] = d.large_turn_edges;
  s["unexplained_mismatch_vertices"] = d.unexplained_mismatch_vertices;
  s["max_fixed_error"] = d.max_fixed_error;
  py::list conflicts;
  for (const FixedConflict& k : d.conflicts) conflicts.append(py::make_tuple(k.face_a, k.face_b, k.turn));
  s["conflicts"] = conflicts;
  s["seconds"] = py::make_tuple(d.solve_seconds, d.field_seconds, d.verify_seconds);
  s["verified"] = r.verified;
  return s;
}

DesignResultPtr restore_design(const DesignerPtr& state, const py::dict& s) {
  auto r = std::make_shared<DesignResult>();
  r->state = state;
  IndexPrescription& p = r->prescription;
  p.N = s["N"].cast<int>();
  p.vertex = items_map<int, int>(s["vertex"]);
  if (s.contains("corners")) r->corners = items_map<int, int>(s["corners"]);  // absent in states of trivcon before corners
  p.generator = items_map<int, int>(s["generator"]);
  p.loop = items_map<int, int>(s["loop"]);
  p.fixed = items_map<int, double>(s["fixed"]);
  Design& d = r->design;
  Connection& c = d.connection;
  c.N = p.N;
  c.x = s["x"].cast<Eigen::VectorXd>();
  c.generator_index = s["generator_index"].cast<std::vector<int>>();
  c.loop_index = s["loop_index"].cast<std::vector<int>>();
  for (int k : s["generator_chosen"].cast<std::vector<int>>()) c.generator_chosen.push_back(static_cast<char>(k));
  for (int k : s["loop_chosen"].cast<std::vector<int>>()) c.loop_chosen.push_back(static_cast<char>(k));
  c.path_turn = s["path_turn"].cast<std::vector<int>>();
  c.energy = s["energy"].cast<double>();
  std::tie(c.max_vertex_residual, c.max_cycle_residual, c.rhs_scale) = s["residuals"].cast<std::tuple<double, double, double>>();
  c.refinements = s["refinements"].cast<int>();
  d.field.N = p.N;
  d.field.angle = s["angle"].cast<Eigen::VectorXd>();
  std::tie(d.indices.vertex, d.indices.loop, d.indices.generator, d.indices.max_rounding) =
      s["indices"].cast<std::tuple<std::vector<int>, std::vector<int>, std::vector<int>, double>>();
  d.transport_mismatch = s["transport_mismatch"].cast<double>();
  d.index_mismatch_vertices = s["index_mismatch_vertices"].cast<std::vector<int>>();
  d.large_turn_edges = s["large_turn_edges"].cast<int>();
  d.unexplained_mismatch_vertices = s["unexplained_mismatch_vertices"].cast<std::vector<int>>();
  d.max_fixed_error = s["max_fixed_error"].cast<double>();
  for (auto [a, b, turn] : s["conflicts"].cast<std::vector<std::tuple<int, int, double>>>()) d.conflicts.push_back({a, b, turn});
  std::tie(d.solve_seconds, d.field_seconds, d.verify_seconds) = s["seconds"].cast<std::tuple<double, double, double>>();
  r->verified = s["verified"].cast<bool>();
  // A state of another mesh would index out of its arrays: refuse it.
  const Topology& t = state->topology();
  if (p.N < 1 || c.x.size() != t.num_edges || d.field.angle.size() != t.num_faces ||
      d.indices.vertex.size() != static_cast<size_t>(t.num_vertices))
    throw Error("cannot restore a Result: its arrays do not fit its designer's mesh (" + std::to_string(t.num_vertices) + " vertices, " +
                std::to_string(t.num_edges) + " edges, " + std::to_string(t.num_faces) + " faces)");
  for (const auto& [f, angle] : p.fixed) check_face(t, f, "cannot restore a Result: fixed face");
  return r;
}

py::array_t<std::uint8_t> render_design(const DesignResultPtr& r, const RenderArgs& args,
                                        const std::optional<std::vector<std::pair<int, int>>>& singular) {
  const RenderOptions o = args.options();
  const Image image = interruptible(r->state->threads, [r, o, singular] {
    // Default: the prescription's singularities, as `trivcon solve --png` draws them.
    const std::vector<std::pair<int, int>> given(r->prescription.vertex.begin(), r->prescription.vertex.end());
    return render_field(r->state->V, r->state->topology(), r->state->geometry(), r->design.field, singular ? *singular : given, o);
  });
  return from_image(image);
}

// --- Automatic placement.

struct AutoOut {
  DesignerPtr state;
  AutoResult result;
};
using AutoOutPtr = std::shared_ptr<AutoOut>;

py::dict auto_state(const AutoOut& a) {
  const AutoResult& r = a.result;
  py::dict s;
  s["N"] = r.field.N;
  s["angle"] = double_vector(r.field.angle);
  s["found"] = map_items(r.found);
  s["coincident_removed"] = r.coincident_removed;
  s["vertex"] = map_items(r.vertex);
  s["pairs"] = r.pairs;
  s["energy"] = r.energy;
  s["vanishing_faces"] = r.vanishing_faces;
  s["ordering"] = r.ordering;
  const AutoTimings& t = r.seconds;
  s["seconds"] = std::vector<double>{t.assemble, t.factor, t.iterate, t.align, t.indices, t.cancel};
  return s;
}

AutoOutPtr restore_auto(const DesignerPtr& state, const py::dict& s) {
  auto a = std::make_shared<AutoOut>();
  a->state = state;
  AutoResult& r = a->result;
  r.field.N = s["N"].cast<int>();
  r.field.angle = s["angle"].cast<Eigen::VectorXd>();
  r.found = items_map<int, int>(s["found"]);
  r.coincident_removed = s["coincident_removed"].cast<int>();
  r.vertex = items_map<int, int>(s["vertex"]);
  r.pairs = s["pairs"].cast<std::vector<std::pair<int, int>>>();
  r.energy = s["energy"].cast<double>();
  r.vanishing_faces = s["vanishing_faces"].cast<int>();
  r.ordering = s["ordering"].cast<std::string>();
  const auto t = s["seconds"].cast<std::vector<double>>();
  if (t.size() != 6 || r.field.N < 1 || r.field.angle.size() != state->topology().num_faces)
    throw Error("cannot restore an AutoResult: its arrays do not fit its designer's mesh (" +
                std::to_string(state->topology().num_faces) + " faces)");
  r.seconds.assemble = t[0], r.seconds.factor = t[1], r.seconds.iterate = t[2], r.seconds.align = t[3], r.seconds.indices = t[4],
  r.seconds.cancel = t[5];
  return a;
}

}  // namespace

}  // namespace trivcon::python

using namespace trivcon;          // NOLINT: the binding code below names the library's API throughout
using namespace trivcon::python;  // NOLINT

PYBIND11_MODULE(_core, m) {
  m.doc() = "trivcon's C++ library (the pybind11 extension behind the trivcon package; use the package, not this module).";
  py::register_exception<Error>(m, "Error", PyExc_ValueError);
  m.attr("__version__") = TRIVCON_VERSION;
  // Whether solver="qr" and factorization="cholmod" exist in this build (they need SuiteSparse's GPL parts, which a
  // default build does not link: CMakeLists.txt, TRIVCON_WITH_SUITESPARSE).
#ifdef TRIVCON_WITH_SUITESPARSE
  m.attr("with_suitesparse") = true;
#else
  m.attr("with_suitesparse") = false;
#endif
  m.attr("pi") = kPi;
  main_thread_ident = py::module_::import("threading").attr("main_thread")().attr("ident").cast<unsigned long>();

  // --- Threads, and abandoned work (see the top of this file).
  m.def(
      "set_default_threads", [](int threads) { default_threads = checked_threads(threads); }, py::arg("threads"),
      "The thread count of calls that name none (0: OpenMP's default).");
  m.def("default_threads", [] { return default_threads.load(); });
  m.def("omp_default_threads", [] { return interruptible(-1, [] { return std::max(1, omp_get_max_threads()); }); },
        "OpenMP's thread count on a new thread (OMP_NUM_THREADS, or the cores).");
  m.def("blas_threads", &blas_threads, "OpenBLAS's thread count for the process (0 without OpenBLAS).");
  m.def(
      "set_blas_threads", [](int threads) { set_blas_threads(threads); }, py::arg("threads"));
  m.def(
      "probe_threads",
      [](int threads) {
        // What a call with this thread count sees: OpenMP's count on its thread, and OpenBLAS's.
        using Seen = std::pair<int, int>;
        return interruptible(threads, [] {
          const auto get = reinterpret_cast<int (*)()>(dlsym(RTLD_DEFAULT, "openblas_get_num_threads"));
          return Seen(omp_get_max_threads(), get ? get() : 0);
        });
      },
      py::arg("threads"), "(OpenMP threads, OpenBLAS threads) inside a call with `threads` threads (for tests).");
  m.def(
      "sleep_interruptibly",
      [](double seconds) {
        // A long call that polls its cancellation flag every millisecond (for tests of KeyboardInterrupt):
        // returns the seconds slept, or is abandoned.
        return interruptible(0, [seconds] {
          const auto start = std::chrono::steady_clock::now();
          while (std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count() < seconds) {
            check_cancelled();
            std::this_thread::sleep_for(std::chrono::milliseconds(1));
          }
          return seconds;
        });
      },
      py::arg("seconds"));
  m.def("wait_for_background", &wait_for_background, py::arg("seconds") = -1.0, py::arg("cancel") = false,
        "Waits for the long calls still running, abandoned ones included (at most `seconds`, negative: no limit), "
        "cancelling them first with `cancel`; whether none is left.");
  m.def("background_running", [] {
    Background& bg = background();
    std::lock_guard<std::mutex> lock(bg.mutex);
    return bg.running;
  });

  // --- Files.
  m.def(
      "read_mesh",
      [](const std::string& path, double weld) {
        const MeshData mesh = interruptible(0, [path, weld] { return read_mesh(path, weld); });
        return py::make_tuple(double_matrix3(mesh.V), int64_matrix(mesh.F), int64_vector(mesh.polygon_of_triangle), mesh.polygon_count,
                              mesh.format, mesh.repeated_vertex);
      },
      py::arg("path"), py::arg("weld") = 0.0,
      "(V, F, polygon_of_triangle, polygon_count, format, repeated_vertex) of a mesh file (trivcon/io.h).");
  m.def(
      "write_mesh",
      [](const std::string& path, const MatrixX3d& V, const MatrixX3i& F) {
        std::string lower = path;
        std::transform(lower.begin(), lower.end(), lower.begin(), [](unsigned char c) { return std::tolower(c); });
        auto ends = [&](const char* s) {
          return lower.size() >= std::strlen(s) && lower.compare(lower.size() - std::strlen(s), std::string::npos, s) == 0;
        };
        py::gil_scoped_release release;
        if (ends(".obj"))
          write_obj(path, V, F);
        else if (ends(".ply"))
          write_ply(path, V, F);
        else
          throw Error("cannot write '" + path + "': unknown mesh format (use .obj or .ply)");
      },
      py::arg("path"), py::arg("V"), py::arg("F"), "Writes OBJ or binary PLY by extension, atomically (trivcon/io.h).");
  m.def(
      "write_quad_mesh",
      [](const std::string& path, const MatrixX3d& V, const Eigen::MatrixX4i& Q) {
        py::gil_scoped_release release;
        write_quad_mesh(path, V, Q);
      },
      py::arg("path"), py::arg("V"), py::arg("Q"), "Writes a quad mesh: binary PLY when the path ends in .ply, else OBJ (trivcon/io.h).");
  m.def(
      "read_field",
      [](const std::string& path, int num_faces) {
        int N = 0;
        MatrixX3d d;
        {
          py::gil_scoped_release release;
          d = read_field(path, num_faces, &N);
        }
        return py::make_tuple(double_matrix3(d), N);
      },
      py::arg("path"), py::arg("num_faces"), "(directions, N in the file or 0) of a field file (trivcon/field_io.h).");
  m.def(
      "write_field",
      [](const std::string& path, const MatrixX3d& V, const MatrixX3i& F, const MatrixX3d& directions, int N) {
        py::gil_scoped_release release;
        const PreparedMesh p(V, F);
        check_rows(directions, p.topology.num_faces);
        write_field(path, V, F, p.geometry, field_from_directions(p.geometry, directions, N));
      },
      py::arg("path"), py::arg("V"), py::arg("F"), py::arg("directions"), py::arg("N"),
      "Writes a field file by extension (trivcon/field_io.h).");
  m.def(
      "read_singularities",
      [](const std::string& path, int N) {
        IndexPrescription p;
        p.N = N;
        read_singularities(path, p);
        return p.vertex;
      },
      py::arg("path"), py::arg("N"), "{vertex: n} (index n/N) of a singularity file (trivcon/indices.h).");
  m.def("write_singularities", &write_singularities, py::arg("path"), py::arg("vertex"), py::arg("N"),
        "Writes {vertex: n} in the plain singularity format (trivcon/indices.h).");
  m.def("parse_index", &parse_index, py::arg("text"), py::arg("N"), py::arg("where"),
        "n (index n/N) of an index written as an integer or p/q; errors start with `where` (trivcon/indices.h).");
  m.def("format_index", &format_index, py::arg("n"), py::arg("N"), "n/N as a reduced fraction or an integer.");
  m.def(
      "write_png",
      [](const std::string& path, const py::array_t<std::uint8_t, py::array::c_style | py::array::forcecast>& pixels) {
        const Image image = to_image(pixels);
        py::gil_scoped_release release;
        write_png(path, image);
      },
      py::arg("path"), py::arg("image"), "Writes an (h, w, 3) uint8 image as PNG, atomically.");

  // --- Fields on plain (V, F).
  m.def(
      "field_indices",
      [](MatrixX3d V, MatrixX3i F, MatrixX3d directions, int N) {
        const FieldIndices idx = interruptible(0, [V = std::move(V), F = std::move(F), directions = std::move(directions), N] {
          const PreparedMesh p(V, F);
          check_rows(directions, p.topology.num_faces);
          if (N < 1) throw Error("the symmetry N must be at least 1 (got " + std::to_string(N) + ")");
          return field_indices(p.topology, p.geometry, compute_cycles(p.topology), field_from_directions(p.geometry, directions, N));
        });
        return indices_tuple(idx);
      },
      py::arg("V"), py::arg("F"), py::arg("directions"), py::arg("N"),
      "(vertex n, loop n, generator n) read from a per-face field, as `trivcon check` does.");
  m.def(
      "render",
      [](MatrixX3d V, MatrixX3i F, MatrixX3d directions, int N, std::optional<std::vector<std::pair<int, int>>> singular,
         const RenderArgs& args) {
        const RenderOptions o = args.options();
        const Image image = interruptible(0, [V = std::move(V), F = std::move(F), directions = std::move(directions), N,
                                              singular = std::move(singular), o] {
          const PreparedMesh p(V, F);
          check_rows(directions, p.topology.num_faces);
          if (N < 1) throw Error("the symmetry N must be at least 1 (got " + std::to_string(N) + ")");
          const Field field = field_from_directions(p.geometry, directions, N);
          std::vector<std::pair<int, int>> s;
          if (singular) {
            for (auto [v, n] : *singular)
              if (v < 0 || v >= p.topology.num_vertices)
                throw Error("singular vertex " + std::to_string(v) + " out of range (mesh has " + std::to_string(p.topology.num_vertices) +
                            " vertices)");
            s = *singular;
          } else {  // as `trivcon render`: where the field itself is singular
            s = singular_vertices(field_indices(p.topology, p.geometry, compute_cycles(p.topology), field).vertex);
          }
          return render_field(V, p.topology, p.geometry, field, s, o);
        });
        return from_image(image);
      },
      py::arg("V"), py::arg("F"), py::arg("directions"), py::arg("N"), py::arg("singularities"), py::arg("options"),
      "An (h, w, 3) uint8 picture of a per-face field (trivcon/render.h).");

  py::class_<RenderArgs>(m, "RenderArgs", "Options of render (the CLI's `render` options).")
      .def(py::init<>())
      .def_readwrite("width", &RenderArgs::width)
      .def_readwrite("height", &RenderArgs::height)
      .def_readwrite("azimuth", &RenderArgs::azimuth)
      .def_readwrite("elevation", &RenderArgs::elevation)
      .def_readwrite("up", &RenderArgs::up)
      .def_readwrite("style", &RenderArgs::style)
      .def_readwrite("spacing", &RenderArgs::spacing)
      .def_readwrite("flat", &RenderArgs::flat)
      .def_readwrite("legend", &RenderArgs::legend)
      .def_readwrite("supersampling", &RenderArgs::supersampling);

  // --- Meshes built in code (trivcon/generate.h).
  m.def(
      "make_icosphere", [](int level) { return mesh_tuple(make_icosphere(level)); }, py::arg("level"));
  m.def(
      "make_uv_sphere", [](int rings, int segments) { return mesh_tuple(make_uv_sphere(rings, segments)); }, py::arg("rings"),
      py::arg("segments"));
  m.def(
      "make_cube_sphere", [](int n, bool spherical) { return mesh_tuple(make_cube_sphere(n, spherical)); }, py::arg("n"),
      py::arg("spherical"));
  m.def(
      "make_torus", [](int nu, int nv, double R, double r) { return mesh_tuple(make_torus(nu, nv, R, r)); }, py::arg("nu"), py::arg("nv"),
      py::arg("R"), py::arg("r"));
  m.def(
      "make_genus_surface", [](int g, int resolution) { return mesh_tuple(make_genus_surface(g, resolution)); }, py::arg("g"),
      py::arg("resolution"));
  m.def(
      "make_disk", [](int rings, int segments) { return mesh_tuple(make_disk(rings, segments)); }, py::arg("rings"), py::arg("segments"));
  m.def(
      "make_annulus",
      [](int rings, int segments, double r_in, double r_out) { return mesh_tuple(make_annulus(rings, segments, r_in, r_out)); },
      py::arg("rings"), py::arg("segments"), py::arg("r_in"), py::arg("r_out"));
  m.def(
      "make_holed_grid", [](int n, int holes) { return mesh_tuple(make_holed_grid(n, holes)); }, py::arg("n"), py::arg("holes"));

  m.def("blas_kernels", &blas_kernels, "The OpenBLAS kernels in use (trivcon/blas.h).");
  m.def("native_blas_kernels", &native_blas_kernels, "The OpenBLAS kernels this CPU supports best (trivcon/blas.h).");

  // --- FieldDesigner.
  py::class_<DesignerState, DesignerPtr>(m, "Designer", "trivcon::FieldDesigner on (V, F), factored at construction.")
      .def(py::init(&make_designer), py::arg("V"), py::arg("F"), py::arg("weights"), py::arg("solver"), py::arg("factorization"),
           py::arg("weight_floor") = 0.0, py::arg("threads") = 0, py::arg("repair") = false)
      .def_static("restore", &restore_designer, py::arg("state"), "A designer of get_state()'s dict, factored on its first solve.")
      .def("get_state", &designer_state, "The mesh as given and the solver options (for pickling).")
      .def_property(
          "threads", [](const DesignerState& s) { return s.threads; },
          [](DesignerState& s, int threads) { s.threads = checked_threads(threads); })
      .def_property_readonly("V", [](const DesignerState& s) { return double_matrix3(s.V); })
      .def_property_readonly("F_input", [](const DesignerState& s) { return int64_matrix(s.F); })
      .def_property_readonly("repair",
                             [](const DesignerState& s) -> py::object {
                               if (!s.repair) return py::none();
                               const RepairedMesh& r = *s.repair;
                               py::dict d;
                               d["summary"] = repair_summary(r);
                               d["input_vertices"] = r.input_vertices, d["input_faces"] = r.input_faces;
                               d["face_of_input"] = int64_vector(r.face_of_input), d["input_face"] = int64_vector(r.input_face);
                               d["vertex_origin"] = int64_vector(r.vertex_origin), d["degenerate_faces"] = r.degenerate_faces;
                               d["duplicate_faces"] = r.duplicates, d["cut_edges"] = r.cut_edges;
                               d["split_vertices"] = r.split_vertices, d["unpaired_faces"] = r.unpaired_faces;
                               d["unseparated_faces"] = r.unseparated_faces;
                               return d;
                             })
      .def_property_readonly("F", [](const DesignerState& s) { return int64_matrix(s.topology().F); })
      .def_property_readonly("num_vertices", [](const DesignerState& s) { return s.topology().num_vertices; })
      .def_property_readonly("num_faces", [](const DesignerState& s) { return s.topology().num_faces; })
      .def_property_readonly("num_edges", [](const DesignerState& s) { return s.topology().num_edges; })
      .def_property_readonly("euler_characteristic", [](const DesignerState& s) { return s.topology().euler_characteristic(); })
      .def_property_readonly("num_generators", [](const DesignerState& s) { return s.designer->cycles().generators.size(); })
      .def_property_readonly("flipped_faces", [](const DesignerState& s) { return int64_vector(s.topology().flipped_faces); })
      .def_property_readonly("unreferenced_vertices",
                             [](const DesignerState& s) { return int64_vector(s.topology().unreferenced_vertices); })
      .def_property_readonly("boundary_loops",
                             [](const DesignerState& s) {
                               py::list loops;
                               for (const auto& loop : s.topology().boundary_loops) loops.append(int64_vector(loop));
                               return loops;
                             })
      .def_property_readonly("boundary_vertices",
                             [](const DesignerState& s) {
                               std::vector<int> out;
                               for (int v = 0; v < s.topology().num_vertices; ++v)
                                 if (s.topology().is_boundary_vertex(v)) out.push_back(v);
                               return int64_vector(out);
                             })
      .def_property_readonly("components",
                             [](const DesignerState& s) {
                               py::list out;
                               for (const ComponentInfo& c : s.topology().components) {
                                 py::dict d;
                                 d["faces"] = c.faces, d["vertices"] = c.vertices, d["edges"] = c.edges;
                                 d["euler_characteristic"] = c.euler_characteristic, d["genus"] = c.genus;
                                 d["boundary_loops"] = c.boundary_loops, d["first_face"] = c.first_face;
                                 out.append(d);
                               }
                               return out;
                             })
      .def_property_readonly("edges",
                             [](const DesignerState& s) {
                               const Topology& t = s.topology();
                               Int64Array out({static_cast<py::ssize_t>(t.num_edges), static_cast<py::ssize_t>(2)});
                               auto o = out.mutable_unchecked<2>();
                               for (size_t k = 0; k < s.sorted_edges.size(); ++k)
                                 o(k, 0) = t.edge_vertices(s.sorted_edges[k], 0), o(k, 1) = t.edge_vertices(s.sorted_edges[k], 1);
                               return out;
                             })
      .def_property_readonly("edge_faces",
                             [](const DesignerState& s) {
                               const Topology& t = s.topology();
                               Int64Array out({static_cast<py::ssize_t>(t.num_edges), static_cast<py::ssize_t>(2)});
                               auto o = out.mutable_unchecked<2>();
                               for (size_t k = 0; k < s.sorted_edges.size(); ++k)
                                 o(k, 0) = t.edge_faces(s.sorted_edges[k], 0), o(k, 1) = t.edge_faces(s.sorted_edges[k], 1);
                               return out;
                             })
      .def("face_frames",
           [](const DesignerState& s) {
             const Geometry& g = s.geometry();
             return py::make_tuple(double_matrix3(g.frame_x), double_matrix3(g.frame_y), double_matrix3(g.normal));
           })
      .def_property_readonly("fixed_faces", [](const DesignerState& s) { return int64_vector(s.fixed_faces); })
      .def_property_readonly("timings",
                             [](const DesignerState& s) {
                               const PrepareTimings& t = s.designer->timings();
                               py::dict d;
                               d["topology"] = t.topology, d["geometry"] = t.geometry, d["cycles"] = t.cycles, d["plan"] = t.plan;
                               d["analysis"] = t.analysis, d["setup"] = t.setup, d["prepare"] = t.prepare;
                               return d;
                             })
      .def(
          "fixed_angle",
          [](const DesignerState& s, int face, const Eigen::Vector3d& direction) {
            check_face(s.topology(), face, "fixed face");
            return fixed_angle_from_direction(s.geometry(), face, direction);
          },
          py::arg("face"), py::arg("direction"), "Angle in the face's frame of a world direction projected onto it.")
      .def(
          "check_fixed_face", [](const DesignerState& s, int face) { check_face(s.topology(), face, "fixed face"); }, py::arg("face"))
      .def("boundary_alignment", [](const DesignerState& s) { return boundary_alignment(s.V, s.topology(), s.geometry()); })
      .def(
          "solve_request",
          [](const DesignerPtr& s, int N, std::optional<std::map<int, int>> vertex, std::map<int, int> generator, std::map<int, int> loop,
             std::map<int, double> fixed, bool align_boundary, std::optional<double> feature_degrees,
             std::vector<std::pair<int, int>> feature_edges, std::vector<std::pair<int, double>> roots, double auto_cancel, bool auto_cancel_absolute, int auto_iterations,
             std::optional<double> curvature_t, bool split, int max_rounds, bool relax, std::vector<int> relax_pins, int relax_cancel,
             int relax_max_moves, int relax_reach, double relax_periods, double map_edge_length, double map_target_faces,
             std::optional<double> feature_min_length, int map_search_maps, py::object map_progress) {
            // The library's request layer (trivcon/request.h) does the work; here only the conversion.
            FieldRequest q;
            q.prescription.N = N;
            if (vertex) q.prescription.vertex = std::move(*vertex);
            q.prescription.generator = std::move(generator);
            q.prescription.loop = std::move(loop);
            q.prescription.fixed = std::move(fixed);
            q.align_boundary = align_boundary;
            q.feature_degrees = feature_degrees;
            q.feature_min_length = feature_min_length;
            for (size_t k = 0; k < feature_edges.size(); ++k) {  // vertex pairs, as a --features file names them
              const auto [i, j] = feature_edges[k];
              const int e = edge_between(s->topology(), i, j);
              if (e < 0)
                throw Error("feature_edges[" + std::to_string(k) + "]: (" + std::to_string(i) + ", " + std::to_string(j) +
                            ") is not an edge of the mesh");
              q.feature_edges.push_back(e);
            }
            q.roots = std::move(roots);
            q.auto_place = !vertex.has_value();
            q.auto_options.cancel_distance = auto_cancel;
            q.auto_options.cancel_absolute = auto_cancel_absolute;
            q.auto_options.iterations = auto_iterations;
            if (curvature_t) q.auto_options.align_curvature = true, q.auto_options.curvature_t = *curvature_t;
            q.split_large_turns = split;
            q.max_split_rounds = max_rounds;
            q.relax = relax;
            q.relax_options.pins = std::move(relax_pins);
            q.relax_options.cancel_distance = relax_cancel;
            q.relax_options.max_moves = relax_max_moves;
            q.relax_options.reach = relax_reach;
            q.relax_options.period_weight = relax_periods;
            struct Out {
              DesignerPtr designer;
              DesignResultPtr result;
              AutoOutPtr auto_out;
              std::vector<int> parent;
              std::vector<RefineRound> rounds;
              bool converged = true;
              std::vector<int> sharp;
              std::optional<RelaxResult> relaxed;
            };
            Out out = interruptible(s->threads, [s, q = std::move(q), map_edge_length, map_target_faces, map_search_maps] {
              Out o;
              std::lock_guard<std::mutex> lock(s->mutex);
              check_cancelled();  // abandoned while it waited for the designer
              FieldRequest request = q;
              // With a map's scale: the field of map_request, as `param`/`quad` make it (placed again when its map
              // folds; given singularities on feature lines with their sectors turned), and its map.
              std::shared_ptr<const ScaledMap> map;
              ParamOptions map_options;
              FieldOutcome r;
              int search_maps = 0;
              bool search_stopped = false;
              if (map_edge_length > 0 || map_target_faces > 0) {
                MapSearch search;
                search.max_maps = map_search_maps;
                search.progress = post_line;  // to map_progress, on the calling thread (interruptible)
                MapOutcome m = map_request(*s->designer, s->F, request, map_edge_length, map_target_faces, true, search);
                search_maps = m.maps, search_stopped = m.stopped;
                r = std::move(m.field);
                if (r.verified) {
                  map_options = request_param_options(*s->designer, request, r, map_edge_length, map_target_faces);
                  map = std::make_shared<const ScaledMap>(ScaledMap{std::move(m.param), std::move(m.quads), m.scale});
                }
              } else {
                r = solve_request(*s->designer, s->F, request);
              }
              s->fixed_faces = s->designer->fixed_faces();
              o.designer = s;
              if (r.refined) {
                auto refined = std::make_shared<DesignerState>();
                refined->threads = s->threads;
                refined->V = std::move(r.V), refined->F = std::move(r.F);
                refined->designer = std::move(r.refined);
                refined->fixed_faces = refined->designer->fixed_faces();
                refined->sort_edges();
                o.designer = refined;
              }
              if (r.auto_result) {
                o.auto_out = std::make_shared<AutoOut>();
                o.auto_out->state = s;
                o.auto_out->result = std::move(*r.auto_result);
              }
              auto d = std::make_shared<DesignResult>();
              d->state = o.designer;
              d->prescription = std::move(r.prescription);
              d->corners = r.constraints.features.corners;
              d->design = std::move(r.design);
              d->verified = r.verified;
              d->map = std::move(map), d->map_options = std::move(map_options);
              d->search_maps = search_maps, d->search_stopped = search_stopped;
              o.result = d;
              o.parent = std::move(r.parent_face);
              o.rounds = std::move(r.rounds);
              o.converged = r.split_converged;
              o.sharp = std::move(r.sharp_edges);
              o.relaxed = std::move(r.relax_result);
              return o;
            }, map_progress);
            py::list round_list;
            for (const RefineRound& k : out.rounds) {
              py::dict d;
              d["split_edges"] = k.split_edges, d["vertices"] = k.vertices, d["faces"] = k.faces, d["reweighted"] = k.reweighted;
              round_list.append(d);
            }
            py::object auto_out = out.auto_out ? py::cast(out.auto_out) : py::none();
            const Topology& t = out.designer->topology();
            Int64Array sharp({static_cast<py::ssize_t>(out.sharp.size()), static_cast<py::ssize_t>(2)});
            auto S = sharp.mutable_unchecked<2>();
            for (size_t k = 0; k < out.sharp.size(); ++k) S(k, 0) = t.edge_vertices(out.sharp[k], 0), S(k, 1) = t.edge_vertices(out.sharp[k], 1);
            py::object relaxed = py::none();
            if (out.relaxed) {  // the moves as arrays: from, to, n (index n / N), energy after, cancelled
              const RelaxResult& x = *out.relaxed;
              const std::vector<RelaxMove>& m = x.moves;
              std::vector<int> from(m.size()), to(m.size()), n(m.size());
              std::vector<bool> cancelled(m.size());
              for (size_t k = 0; k < m.size(); ++k) from[k] = m[k].from, to[k] = m[k].to, n[k] = m[k].index, cancelled[k] = m[k].cancelled;
              py::dict d;
              d["vertex"] = x.prescription.vertex;
              d["energy_before"] = x.energy_before, d["energy_after"] = x.energy_after;
              d["periods_before"] = x.periods_used ? py::object(py::float_(x.periods_before)) : py::object(py::none());
              d["periods_after"] = x.periods_used ? py::object(py::float_(x.periods_after)) : py::object(py::none());
              d["energies"] = py::array_t<double>(static_cast<py::ssize_t>(x.energies.size()), x.energies.data());
              d["from"] = int64_vector(from), d["to"] = int64_vector(to), d["index"] = int64_vector(n);
              d["cancelled"] = py::array_t<bool>(py::cast(cancelled));
              d["candidates_evaluated"] = x.candidates_evaluated, d["converged"] = x.converged, d["seconds"] = x.seconds;
              relaxed = d;
            }
            return py::make_tuple(out.designer, out.result, auto_out, int64_vector(out.parent), round_list, out.converged, sharp, relaxed);
          },
          py::arg("N"), py::arg("vertex"), py::arg("generator"), py::arg("loop"), py::arg("fixed"), py::arg("align_boundary"),
          py::arg("feature_degrees"), py::arg("feature_edges"), py::arg("roots"), py::arg("auto_cancel"), py::arg("auto_cancel_absolute"),
          py::arg("auto_iterations"), py::arg("curvature_t"), py::arg("split"), py::arg("max_rounds"), py::arg("relax") = false,
          py::arg("relax_pins") = std::vector<int>{}, py::arg("relax_cancel") = 0, py::arg("relax_max_moves") = 10000,
          py::arg("relax_reach") = 1, py::arg("relax_periods") = 0.0, py::arg("map_edge_length") = 0.0, py::arg("map_target_faces") = 0.0,
          py::arg("feature_min_length") = std::nullopt, py::arg("map_search_maps") = 0, py::arg("map_progress") = py::none(),
          "One field request (trivcon/request.h; vertex None: the smoothest field's singularities, chosen for a map at the given "
          "scale as the map commands do when one is > 0, cancel_for_map): (designer of the final mesh, "
          "DesignResult, AutoResult or None, parent face of each face (with split), rounds, converged, sharp edges, relaxation "
          "as a dict or None).")
      .def(
          "sharp_edges",
          [](const DesignerPtr& s, double degrees) {
            const Topology& t = s->topology();
            const std::vector<int> edges = sharp_edges(s->V, t, s->geometry(), degrees);
            Int64Array out({static_cast<py::ssize_t>(edges.size()), static_cast<py::ssize_t>(2)});
            auto o = out.mutable_unchecked<2>();
            for (size_t k = 0; k < edges.size(); ++k) o(k, 0) = t.edge_vertices(edges[k], 0), o(k, 1) = t.edge_vertices(edges[k], 1);
            return out;
          },
          py::arg("degrees"), "(n, 2) vertex pairs (i < j) of the interior edges sharper than `degrees` (trivcon/features.h).")
      .def(
          "auto_singularities",
          [](const DesignerPtr& s, int N, int iterations, double cancel, bool cancel_absolute, std::map<int, double> fixed,
             bool align_curvature, double curvature_t) {
            AutoOptions o;
            o.N = N, o.iterations = iterations, o.cancel_distance = cancel, o.cancel_absolute = cancel_absolute, o.fixed = std::move(fixed);
            o.align_curvature = align_curvature, o.curvature_t = curvature_t;
            return interruptible(s->threads, [s, o] {
              auto out = std::make_shared<AutoOut>();
              out->state = s;
              std::lock_guard<std::mutex> lock(s->mutex);
              check_cancelled();  // abandoned while it waited for the designer
              for (const auto& [f, angle] : o.fixed) check_face(s->topology(), f, "fixed face");
              out->result = auto_singularities(*s->designer, o);
              return out;
            });
          },
          py::arg("N"), py::arg("iterations"), py::arg("cancel"), py::arg("cancel_absolute"), py::arg("fixed"), py::arg("align_curvature"),
          py::arg("curvature_t"), "Singularities of the smoothest field (trivcon/auto.h).")
      .def(
          "field_indices",
          [](const DesignerPtr& s, MatrixX3d directions, int N) {
            const FieldIndices idx = interruptible(s->threads, [s, directions = std::move(directions), N] {
              check_rows(directions, s->topology().num_faces);
              if (N < 1) throw Error("the symmetry N must be at least 1 (got " + std::to_string(N) + ")");
              return field_indices(s->topology(), s->geometry(), s->designer->cycles(), field_from_directions(s->geometry(), directions, N));
            });
            return indices_tuple(idx);
          },
          py::arg("directions"), py::arg("N"), "(vertex n, loop n, generator n) of a per-face field on this mesh.");

  py::class_<DesignResult, DesignResultPtr>(m, "DesignResult", "A trivcon::Design with its prescription.")
      .def("get_state", &design_state, "Everything the design holds (for pickling).")
      .def_static("restore", &restore_design, py::arg("designer"), py::arg("state"), "A DesignResult of get_state()'s dict.")
      .def_property_readonly("N", [](const DesignResult& r) { return r.prescription.N; })
      .def_property_readonly("vertex", [](const DesignResult& r) { return r.prescription.vertex; })
      .def_property_readonly("corners", [](const DesignResult& r) { return r.corners; })
      .def_property_readonly("search", [](const DesignResult& r) {
        py::dict d;
        d["maps"] = r.search_maps, d["stopped"] = r.search_stopped;
        return d;
      })
      .def_property_readonly("fixed", [](const DesignResult& r) { return r.prescription.fixed; })
      .def_property_readonly("directions",
                             [](const DesignResult& r) { return double_matrix3(field_directions(r.state->geometry(), r.design.field)); })
      .def_property_readonly("angles", [](const DesignResult& r) { return double_vector(r.design.field.angle); })
      .def("connection", &DesignResult::connection)
      .def_property_readonly("energy", [](const DesignResult& r) { return r.design.connection.energy; })
      .def_property_readonly("max_vertex_residual", [](const DesignResult& r) { return r.design.connection.max_vertex_residual; })
      .def_property_readonly("max_cycle_residual", [](const DesignResult& r) { return r.design.connection.max_cycle_residual; })
      .def_property_readonly("rhs_scale", [](const DesignResult& r) { return r.design.connection.rhs_scale; })
      .def_property_readonly("transport_mismatch", [](const DesignResult& r) { return r.design.transport_mismatch; })
      .def_property_readonly("generator_index", [](const DesignResult& r) { return r.design.connection.generator_index; })
      .def_property_readonly("generator_chosen",
                             [](const DesignResult& r) {
                               return std::vector<bool>(r.design.connection.generator_chosen.begin(),
                                                        r.design.connection.generator_chosen.end());
                             })
      .def_property_readonly("loop_index", [](const DesignResult& r) { return r.design.connection.loop_index; })
      .def_property_readonly("loop_chosen",
                             [](const DesignResult& r) {
                               return std::vector<bool>(r.design.connection.loop_chosen.begin(), r.design.connection.loop_chosen.end());
                             })
      .def_property_readonly("path_turn", [](const DesignResult& r) { return r.design.connection.path_turn; })
      .def_property_readonly("indices", [](const DesignResult& r) { return indices_tuple(r.design.indices); })
      .def_property_readonly("index_mismatch_vertices",
                             [](const DesignResult& r) { return int64_vector(r.design.index_mismatch_vertices); })
      .def_property_readonly("unexplained_mismatch_vertices",
                             [](const DesignResult& r) { return int64_vector(r.design.unexplained_mismatch_vertices); })
      .def_property_readonly("large_turn_edges", [](const DesignResult& r) { return r.design.large_turn_edges; })
      .def_property_readonly("max_fixed_error", [](const DesignResult& r) { return r.design.max_fixed_error; })
      .def_property_readonly("conflicts",
                             [](const DesignResult& r) {
                               std::vector<std::tuple<int, int, double>> out;
                               for (const FixedConflict& c : r.design.conflicts) out.emplace_back(c.face_a, c.face_b, c.turn);
                               return out;
                             })
      .def_property_readonly("verified", [](const DesignResult& r) { return r.verified; })
      .def_property_readonly("seconds",
                             [](const DesignResult& r) {
                               py::dict d;
                               d["solve"] = r.design.solve_seconds, d["field"] = r.design.field_seconds,
                               d["verify"] = r.design.verify_seconds;
                               return d;
                             })
      .def(
          "write_field",
          [](const DesignResult& r, const std::string& path) {
            py::gil_scoped_release release;
            if (r.state->repair)  // a row per input face, as the CLI writes it
              write_field(path, r.state->input_V, r.state->input_F, r.state->geometry(), r.design.field, r.state->repair->face_of_input);
            else
              write_field(path, r.state->V, r.state->F, r.state->geometry(), r.design.field);
          },
          py::arg("path"))
      .def(
          "write_connection",
          [](const DesignResult& r, const std::string& path) {
            py::gil_scoped_release release;
            write_connection(path, r.state->topology(), r.design.connection.x, r.prescription.N);
          },
          py::arg("path"))
      .def("matching", &DesignResult::matching)
      .def(
          "write_matching",
          [](const DesignResult& r, const std::string& path) {
            py::gil_scoped_release release;
            const Topology& t = r.state->topology();
            write_matching(path, t, connection_matching(t, r.state->geometry(), r.design.field, r.design.connection.x), r.prescription.N);
          },
          py::arg("path"))
      .def(
          "write_lines",
          [](const DesignResult& r, const std::string& path) {
            py::gil_scoped_release release;
            write_field_lines(path, r.state->V, r.state->F, r.state->geometry(), r.design.field);
          },
          py::arg("path"))
      .def(
          "write_singularities",
          [](const DesignResult& r, const std::string& path) {
            py::gil_scoped_release release;
            // The input's ids (a copy repair appended names the vertex it copies), with the corners of the boundary
            // (a boundary vertex given back is one, with the boundary aligned).
            const std::map<int, int> vertex = with_corners(r.prescription.vertex, r.corners);
            write_singularities(path, r.state->repair ? values_on_input(*r.state->repair, vertex) : vertex, r.prescription.N);
          },
          py::arg("path"))
      .def(
          "write_uv_obj",
          [](const DesignResult& r, const std::string& path, const Eigen::MatrixXd& corner_uv) {
            py::gil_scoped_release release;
            if (r.state->repair)  // the input's faces, as `param -o` writes them
              write_uv_obj(path, r.state->input_V, r.state->input_F, corner_rows_on_input(*r.state->repair, r.state->input_F, corner_uv));
            else
              write_uv_obj(path, r.state->V, r.state->F, corner_uv);
          },
          py::arg("path"), py::arg("corner_uv"),
          "The OBJ of `param -o`: the mesh as given (before repair) with (u, v) per corner (corner_uv: F x 6 of the designer's faces).")
      .def(
          "parametrize",
          [](const DesignResultPtr& r, double edge_length, double target_faces, bool align_boundary,
             const std::vector<std::pair<int, int>>& aligned_pairs, const std::string& sizing, bool quads) {
            const Topology& t = r->state->topology();
            ParamOptions o;
            o.edge_length = edge_length, o.target_faces = target_faces;
            o.sizing = sizing_from_name(sizing);
            if (align_boundary)
              for (int e = 0; e < t.num_edges; ++e)
                if (t.is_boundary_edge(e)) o.aligned_edges.push_back(e);
            for (auto [a, b] : aligned_pairs) {
              const int e = edge_between(t, a, b);
              if (e < 0) throw Error("aligned edge (" + std::to_string(a) + ", " + std::to_string(b) + ") is not an edge of the mesh");
              o.aligned_edges.push_back(e);
            }
            // The map solve(..., map_target_faces) kept when asked for with its options, else as every front end
            // keeps it (map_field: at other scales when the one asked for keeps problems).
            ScaledMap map;
            if (r->map && same_map_options(o, r->map_options)) {
              map.param = r->map->param, map.scale = r->map->scale;
              if (quads) map.quads = r->map->quads;
            } else {
              map = interruptible(r->state->threads, [r, o, quads] { return map_field(*r->state->designer, r->design, o, quads); });
            }
            auto p = std::make_shared<Parametrization>(std::move(map.param));
            const Eigen::MatrixXd corners = input_corner_uv(*p, t, r->state->F);
            DoubleArray uv({static_cast<py::ssize_t>(corners.rows()), static_cast<py::ssize_t>(3), static_cast<py::ssize_t>(2)});
            auto U = uv.mutable_unchecked<3>();
            for (Eigen::Index f = 0; f < corners.rows(); ++f)
              for (int k = 0; k < 3; ++k) U(f, k, 0) = corners(f, 2 * k), U(f, k, 1) = corners(f, 2 * k + 1);
            const auto n = static_cast<py::ssize_t>(p->cut_edges.size());
            Int64Array cut({n, static_cast<py::ssize_t>(2)}), rotation(n), translation({n, static_cast<py::ssize_t>(2)});
            auto C = cut.mutable_unchecked<2>();
            auto R = rotation.mutable_unchecked<1>();
            auto T = translation.mutable_unchecked<2>();
            for (py::ssize_t k = 0; k < n; ++k) {
              const int e = p->cut_edges[k];
              C(k, 0) = t.edge_vertices(e, 0), C(k, 1) = t.edge_vertices(e, 1);
              R(k) = p->rotation[e], T(k, 0) = p->translation(e, 0), T(k, 1) = p->translation(e, 1);
            }
            const py::tuple param = py::make_tuple(uv, cut, rotation, translation, int64_vector(p->cones), int64_vector(p->cone_index),
                                                   p->edge_length, json_to_python(cli::param_report(*p)), param_warning(*p), p);
            return py::make_tuple(param, map.scale, map.quads ? quads_tuple(*map.quads) : py::object(py::none()));
          },
          py::arg("edge_length"), py::arg("target_faces"), py::arg("align_boundary"), py::arg("aligned_edges"), py::arg("sizing") = "map",
          py::arg("quads") = false,
          "The integer-grid map as the program keeps it (trivcon/request.h map_field): ((uv (F, 3, 2) in the input's corner order, "
          "cut edges (n, 2), their rotations, translations (n, 2), cone vertices, their numerators (index n/4), edge length, quality "
          "dict (param's report), warning, the map itself for quads), its edge length over the one asked for, and with quads=True the "
          "tuple of quads() for its quad mesh, else None).")
      .def(
          "quads",
          [](const DesignResultPtr& r, const std::shared_ptr<Parametrization>& p) {
            if (!p) throw Error("quads: no map given");
            return quads_tuple(interruptible(r->state->threads, [r, p] { return extract_quads(*r->state->designer, *p); }));
          },
          py::arg("param"),
          "The quad mesh of a map (trivcon/quad.h): (V (n, 3), Q (m, 4), face of each vertex, input vertex under each vertex or -1, "
          "quality dict (quad's report), warning).")
      .def(
          "render",
          [](const DesignResultPtr& r, const std::optional<std::vector<std::pair<int, int>>>& singular, const RenderArgs& args) {
            if (singular)
              for (auto [v, n] : *singular)
                if (v < 0 || v >= r->state->topology().num_vertices)
                  throw Error("singular vertex " + std::to_string(v) + " out of range (mesh has " +
                              std::to_string(r->state->topology().num_vertices) + " vertices)");
            return render_design(r, args, singular);
          },
          py::arg("singularities"), py::arg("options"));

  py::class_<Parametrization, std::shared_ptr<Parametrization>>(m, "ParamCore", "A trivcon::Parametrization, kept for quads.");
  py::class_<AutoOut, AutoOutPtr>(m, "AutoResult", "A trivcon::AutoResult.")
      .def("get_state", &auto_state, "Everything the result holds (for pickling).")
      .def_static("restore", &restore_auto, py::arg("designer"), py::arg("state"), "An AutoResult of get_state()'s dict.")
      .def_property_readonly("N", [](const AutoOut& a) { return a.result.field.N; })
      .def_property_readonly("found", [](const AutoOut& a) { return a.result.found; })
      .def_property_readonly("vertex", [](const AutoOut& a) { return a.result.vertex; })
      .def_property_readonly("pairs", [](const AutoOut& a) { return a.result.pairs; })
      .def_property_readonly("coincident_removed", [](const AutoOut& a) { return a.result.coincident_removed; })
      .def_property_readonly("ordering", [](const AutoOut& a) { return a.result.ordering; })
      .def_property_readonly("energy", [](const AutoOut& a) { return a.result.energy; })
      .def_property_readonly("vanishing_faces", [](const AutoOut& a) { return a.result.vanishing_faces; })
      .def_property_readonly("angles", [](const AutoOut& a) { return double_vector(a.result.field.angle); })
      .def_property_readonly("directions",
                             [](const AutoOut& a) { return double_matrix3(field_directions(a.state->geometry(), a.result.field)); })
      .def_property_readonly("seconds", [](const AutoOut& a) {
        const AutoTimings& s = a.result.seconds;
        py::dict d;
        d["assemble"] = s.assemble, d["factor"] = s.factor, d["iterate"] = s.iterate, d["align"] = s.align, d["indices"] = s.indices;
        d["cancel"] = s.cancel;
        return d;
      });
}
