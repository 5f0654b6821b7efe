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
#include <pybind11/eigen.h>
#include <pybind11/numpy.h>
#include <pybind11/pybind11.h>
#include <pybind11/stl.h>

#include <algorithm>
#include <cctype>
#include <cstdint>
#include <cstring>
#include <map>
#include <memory>
#include <mutex>
#include <optional>
#include <string>
#include <utility>
#include <vector>

#include "trivcon/auto.h"
#include "trivcon/blas.h"
#include "trivcon/refine.h"
#include "trivcon/constraints.h"
#include "trivcon/design.h"
#include "trivcon/error.h"
#include "trivcon/field.h"
#include "trivcon/field_io.h"
#include "trivcon/generate.h"
#include "trivcon/indices.h"
#include "trivcon/io.h"
#include "trivcon/matching.h"
#include "trivcon/render.h"

namespace py = pybind11;

namespace trivcon::python {

namespace {

using Int64Array = py::array_t<std::int64_t>;
using DoubleArray = py::array_t<double>;

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

py::tuple mesh_tuple(const Mesh& mesh) { return py::make_tuple(double_matrix3(mesh.V), int64_matrix(mesh.F)); }

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

DesignerPtr make_designer(const MatrixX3d& V, const MatrixX3i& F, const std::string& weights, const std::string& solver,
                          const std::string& factorization, double weight_floor) {
  const SolverOptions options = solver_options(weights, solver, factorization, weight_floor);
  auto s = std::make_shared<DesignerState>();
  {
    py::gil_scoped_release release;
    s->V = V;
    s->F = F;
    s->designer = std::make_unique<FieldDesigner>(V, F, options);
    s->designer->set_fixed_faces({});  // factor now: the constructor of the Python object validates and factors
    s->sort_edges();
  }
  return s;
}

void check_face(const Topology& t, int f, const std::string& what) {
  if (f < 0 || f >= t.num_faces)
    throw Error(what + " " + std::to_string(f) + " out of range (mesh has " + std::to_string(t.num_faces) + " faces)");
}

// --- A design: the library's Design with the prescription it answers.

struct DesignResult {
  DesignerPtr state;
  IndexPrescription prescription;
  Design design;
  bool verified = false;

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

py::array_t<std::uint8_t> render_design(const DesignResult& r, const RenderArgs& args, const std::vector<std::pair<int, int>>* singular) {
  const RenderOptions o = args.options();
  Image image;
  {
    py::gil_scoped_release release;
    // Default: the prescription's singularities, as `trivcon solve --png` draws them.
    const std::vector<std::pair<int, int>> given(r.prescription.vertex.begin(), r.prescription.vertex.end());
    image = render_field(r.state->V, r.state->topology(), r.state->geometry(), r.design.field, singular ? *singular : given, o);
  }
  return from_image(image);
}

// --- Automatic placement.

struct AutoOut {
  DesignerPtr state;
  AutoResult result;
};

}  // namespace

}  // namespace trivcon::python

using namespace trivcon;          // NOLINT: the binding code below names the library's API throughout
using namespace trivcon::python;  // NOLINT

PYBIND11_MODULE(_core, m) {
  m.doc() = "trivcon's C++ library (the pybind11 extension behind the trivcon package; use the package, not this module).";
  py::register_exception<Error>(m, "Error", PyExc_ValueError);
  m.attr("__version__") = TRIVCON_VERSION;
  m.attr("pi") = kPi;

  // --- Files.
  m.def(
      "read_mesh",
      [](const std::string& path) {
        MeshData mesh;
        {
          py::gil_scoped_release release;
          mesh = read_mesh(path);
        }
        return py::make_tuple(double_matrix3(mesh.V), int64_matrix(mesh.F), int64_vector(mesh.polygon_of_triangle), mesh.polygon_count,
                              mesh.format);
      },
      py::arg("path"), "(V, F, polygon_of_triangle, polygon_count, format) of a mesh file (trivcon/io.h).");
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
      [](const MatrixX3d& V, const MatrixX3i& F, const MatrixX3d& directions, int N) {
        FieldIndices idx;
        {
          py::gil_scoped_release release;
          const PreparedMesh p(V, F);
          check_rows(directions, p.topology.num_faces);
          if (N < 1) throw Error("the symmetry N must be at least 1 (got " + std::to_string(N) + ")");
          idx = field_indices(p.topology, p.geometry, compute_cycles(p.topology), field_from_directions(p.geometry, directions, N));
        }
        return indices_tuple(idx);
      },
      py::arg("V"), py::arg("F"), py::arg("directions"), py::arg("N"),
      "(vertex n, loop n, generator n) read from a per-face field, as `trivcon check` does.");
  m.def(
      "render",
      [](const MatrixX3d& V, const MatrixX3i& F, const MatrixX3d& directions, int N,
         const std::optional<std::vector<std::pair<int, int>>>& singular, const RenderArgs& args) {
        const RenderOptions o = args.options();
        Image image;
        {
          py::gil_scoped_release release;
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
          image = render_field(V, p.topology, p.geometry, field, s, o);
        }
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
           py::arg("weight_floor") = 0.0)
      .def_property_readonly("V", [](const DesignerState& s) { return double_matrix3(s.V); })
      .def_property_readonly("F_input", [](const DesignerState& s) { return int64_matrix(s.F); })
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
          "design",
          [](const DesignerPtr& s, int N, const std::map<int, int>& vertex, const std::map<int, int>& generator,
             const std::map<int, int>& loop, const std::map<int, double>& fixed, const std::vector<std::pair<int, double>>& roots) {
            auto r = std::make_unique<DesignResult>();
            r->state = s;
            r->prescription.N = N;
            r->prescription.vertex = vertex;
            r->prescription.generator = generator;
            r->prescription.loop = loop;
            r->prescription.fixed = fixed;
            {
              py::gil_scoped_release release;
              std::lock_guard<std::mutex> lock(s->mutex);
              for (const auto& [f, angle] : fixed) check_face(s->topology(), f, "fixed face");
              s->use_fixed_faces(fixed);
              r->design = s->designer->design(r->prescription, roots);
              r->verified = design_verified(r->design);
            }
            return r;
          },
          py::arg("N"), py::arg("vertex"), py::arg("generator"), py::arg("loop"), py::arg("fixed"), py::arg("roots"),
          "A Design of the prescription (n = index·N per id; fixed: face -> angle).")
      .def(
          "split_large_turns",
          [](const DesignerPtr& s, int N, const std::map<int, int>& vertex, const std::map<int, double>& fixed, bool align_boundary,
             int max_rounds, const std::string& weights, const std::string& solver, const std::string& factorization, double weight_floor) {
            const SolverOptions options = solver_options(weights, solver, factorization, weight_floor);
            auto r = std::make_unique<DesignResult>();
            r->prescription.N = N;
            r->prescription.vertex = vertex;
            r->prescription.fixed = fixed;
            if (align_boundary)
              for (auto [f, angle] : boundary_alignment(s->V, s->topology(), s->geometry())) r->prescription.fixed.emplace(f, angle);
            std::vector<RefineRound> rounds;
            std::vector<int> parent;
            bool converged = false;
            DesignerPtr refined = s;
            {
              py::gil_scoped_release release;
              std::lock_guard<std::mutex> lock(s->mutex);
              for (const auto& [f, angle] : fixed) check_face(s->topology(), f, "fixed face");
              s->use_fixed_faces(r->prescription.fixed);
              // Each refined mesh: the boundary aligned again, the given fixed faces' directions (world
              // vectors) on their children (they win, as on the input mesh).
              std::map<int, Eigen::Vector3d> world;
              for (auto [f, angle] : fixed) world[f] = s->geometry().direction_in_face(f, angle);
              auto constraints = [&](const FieldDesigner& d, const std::vector<int>& parent_face) {
                std::map<int, double> out;
                if (align_boundary) out = boundary_alignment(d.V(), d.topology(), d.geometry());
                for (int f = 0; f < static_cast<int>(parent_face.size()); ++f) {
                  const auto it = world.find(parent_face[f]);
                  if (it != world.end()) out[f] = d.geometry().angle_in_face(f, it->second);
                }
                return out;
              };
              RefinedDesign d = split_large_turns(*s->designer, s->F, r->prescription, options, constraints, max_rounds);
              rounds = d.rounds, parent = d.parent_face, converged = d.converged;
              if (d.designer) {
                refined = std::make_shared<DesignerState>();
                refined->V = d.V, refined->F = d.F;
                refined->designer = std::move(d.designer);
                for (const auto& [f, angle] : d.prescription.fixed) refined->fixed_faces.push_back(f);
                refined->sort_edges();
              }
              r->prescription = d.prescription;
              r->design = std::move(d.design);
              r->verified = design_verified(r->design);
            }
            r->state = refined;
            py::list round_list;
            for (const RefineRound& k : rounds) {
              py::dict d;
              d["split_edges"] = k.split_edges, d["vertices"] = k.vertices, d["faces"] = k.faces;
              round_list.append(d);
            }
            return py::make_tuple(refined, py::cast(std::move(r)), int64_vector(parent), round_list, converged);
          },
          py::arg("N"), py::arg("vertex"), py::arg("fixed"), py::arg("align_boundary"), py::arg("max_rounds"), py::arg("weights"),
          py::arg("solver"), py::arg("factorization"), py::arg("weight_floor"),
          "Design, refined until no edge turns by pi/N or more (trivcon/refine.h): (designer of the final mesh, DesignResult, "
          "parent face of each face, rounds, converged).")
      .def(
          "auto_singularities",
          [](const DesignerPtr& s, int N, int iterations, double cancel, bool cancel_absolute, const std::map<int, double>& fixed,
             bool align_curvature, double curvature_t) {
            AutoOptions o;
            o.N = N, o.iterations = iterations, o.cancel_distance = cancel, o.cancel_absolute = cancel_absolute, o.fixed = fixed;
            o.align_curvature = align_curvature, o.curvature_t = curvature_t;
            auto out = std::make_unique<AutoOut>();
            out->state = s;
            {
              py::gil_scoped_release release;
              std::lock_guard<std::mutex> lock(s->mutex);
              for (const auto& [f, angle] : fixed) check_face(s->topology(), f, "fixed face");
              out->result = auto_singularities(*s->designer, o);
            }
            return out;
          },
          py::arg("N"), py::arg("iterations"), py::arg("cancel"), py::arg("cancel_absolute"), py::arg("fixed"), py::arg("align_curvature"),
          py::arg("curvature_t"), "Singularities of the smoothest field (trivcon/auto.h).")
      .def(
          "field_indices",
          [](const DesignerState& s, const MatrixX3d& directions, int N) {
            FieldIndices idx;
            {
              py::gil_scoped_release release;
              check_rows(directions, s.topology().num_faces);
              if (N < 1) throw Error("the symmetry N must be at least 1 (got " + std::to_string(N) + ")");
              idx = field_indices(s.topology(), s.geometry(), s.designer->cycles(), field_from_directions(s.geometry(), directions, N));
            }
            return indices_tuple(idx);
          },
          py::arg("directions"), py::arg("N"), "(vertex n, loop n, generator n) of a per-face field on this mesh.");

  py::class_<DesignResult>(m, "DesignResult", "A trivcon::Design with its prescription.")
      .def_property_readonly("N", [](const DesignResult& r) { return r.prescription.N; })
      .def_property_readonly("vertex", [](const DesignResult& r) { return r.prescription.vertex; })
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
            write_singularities(path, r.prescription.vertex, r.prescription.N);
          },
          py::arg("path"))
      .def(
          "render",
          [](const DesignResult& r, const std::optional<std::vector<std::pair<int, int>>>& singular, const RenderArgs& args) {
            if (singular)
              for (auto [v, n] : *singular)
                if (v < 0 || v >= r.state->topology().num_vertices)
                  throw Error("singular vertex " + std::to_string(v) + " out of range (mesh has " +
                              std::to_string(r.state->topology().num_vertices) + " vertices)");
            return render_design(r, args, singular ? &*singular : nullptr);
          },
          py::arg("singularities"), py::arg("options"));

  py::class_<AutoOut>(m, "AutoResult", "A trivcon::AutoResult.")
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
