// SPDX-License-Identifier: MIT
// generate.cpp: meshes built in code (see trivcon/generate.h).
//
// All generators write into a MeshBuilder; grids of quads go through add_quad_grid so that the
// quad-splitting rule lives in one place, and edge midpoints (subdivision, icosphere) come from
// index_edges, a counting sort of half-edges by their smaller vertex.
#include "trivcon/generate.h"

#include <algorithm>
#include <array>
#include <cmath>
#include <cstdint>
#include <limits>
#include <numeric>
#include <random>
#include <sstream>
#include <string>
#include <unordered_map>

#include <Eigen/Geometry>
#include <utility>

#include "trivcon/error.h"

namespace trivcon {
namespace {

// Ids are int and index_edges packs half-edge ids (3·F) into 32 bits; a quarter of INT_MAX keeps
// every derived count (half-edges, subdivided faces) representable.
constexpr double kMaxElements = std::numeric_limits<int>::max() / 4;

template <class T>
std::string to_text(const T& value) {
  std::ostringstream out;
  out << value;
  return out.str();
}

template <class T>
void require(bool ok, const char* function, const char* name, const T& value, const std::string& condition) {
  if (!ok) {
    throw Error(std::string(function) + ": invalid " + name + " = " + to_text(value) + " (need " + condition + ")");
  }
}

// Counts are computed in double by the callers so that absurd parameters cannot overflow first.
void require_size(const char* function, double vertices, double faces) {
  if (vertices > kMaxElements || faces > kMaxElements) {
    throw Error(std::string(function) + ": parameters give " + to_text(vertices) + " vertices and " + to_text(faces) +
                " faces, more than the supported " + to_text(kMaxElements));
  }
}

void require_valid_faces(const char* function, const Mesh& mesh) {
  const int num_vertices = static_cast<int>(mesh.V.rows());
  for (Eigen::Index f = 0; f < mesh.F.rows(); ++f) {
    for (int k = 0; k < 3; ++k) {
      const int v = mesh.F(f, k);
      if (v < 0 || v >= num_vertices) {
        throw Error(std::string(function) + ": vertex index " + to_text(v) + " out of range in face " + to_text(f) + " (mesh has " +
                    to_text(num_vertices) + " vertices)");
      }
    }
  }
}

class MeshBuilder {
 public:
  MeshBuilder(double expected_vertices, double expected_faces) {
    positions_.reserve(3 * static_cast<size_t>(expected_vertices));
    corners_.reserve(3 * static_cast<size_t>(expected_faces));
  }

  int num_vertices() const { return static_cast<int>(positions_.size() / 3); }

  int add_vertex(double x, double y, double z) {
    positions_.insert(positions_.end(), {x, y, z});
    return num_vertices() - 1;
  }
  // For generators that compute ids arithmetically: make room for `count` vertices, then set them.
  void resize_vertices(int count) { positions_.resize(3 * static_cast<size_t>(count)); }
  void set_vertex(int id, double x, double y, double z) {
    positions_[3 * static_cast<size_t>(id)] = x;
    positions_[3 * static_cast<size_t>(id) + 1] = y;
    positions_[3 * static_cast<size_t>(id) + 2] = z;
  }

  void add_triangle(int a, int b, int c) { corners_.insert(corners_.end(), {a, b, c}); }

  // The quad q00 q10 q11 q01 (in this cyclic order) as two triangles of the same orientation, cut
  // along the diagonal q00–q11 or q10–q01.
  void add_quad(int q00, int q10, int q11, int q01, bool diagonal_00_11) {
    if (diagonal_00_11) {
      add_triangle(q00, q10, q11);
      add_triangle(q00, q11, q01);
    } else {
      add_triangle(q00, q10, q01);
      add_triangle(q10, q11, q01);
    }
  }

  Mesh finish() const {
    Mesh mesh;
    mesh.V = Eigen::Map<const MatrixX3d>(positions_.data(), num_vertices(), 3);
    mesh.F = Eigen::Map<const MatrixX3i>(corners_.data(), static_cast<Eigen::Index>(corners_.size() / 3), 3);
    return mesh;
  }

 private:
  std::vector<double> positions_;
  std::vector<int> corners_;
};

// The na × nb cells of a grid whose point (a, b) is vertex id(a, b): cell (a, b) is the quad
// (a,b) (a+1,b) (a+1,b+1) (a,b+1), so the triangles face the side the a × b direction points to.
// Periodic grids just wrap in `id`.
template <class Id, class Diagonal>
void add_quad_grid(MeshBuilder& out, int na, int nb, const Id& id, const Diagonal& diagonal_00_11) {
  for (int b = 0; b < nb; ++b) {
    for (int a = 0; a < na; ++a) {
      out.add_quad(id(a, b), id(a + 1, b), id(a + 1, b + 1), id(a, b + 1), diagonal_00_11(a, b));
    }
  }
}

template <class Id>
void add_quad_grid(MeshBuilder& out, int na, int nb, const Id& id) {
  add_quad_grid(out, na, nb, id, [](int, int) { return true; });
}

// Diagonal for cell (a, b) of an n×n face: perpendicular to the direction from the face centre
// (middle row/column counted as positive). Symmetric under the square's symmetries for even n, and
// for n ≥ 2 no diagonal touches a face corner, so cube corners keep valence 3.
bool diamond_diagonal(int a, int b, int n) { return (2 * a + 1 - n >= 0) != (2 * b + 1 - n >= 0); }

using Lattice = std::array<int, 3>;

// One face of the axis-aligned lattice cube [corner, corner + size]^3, the one normal to `axis` on
// its positive or negative side, as a size×size grid oriented outward. `id(lattice point)` returns
// (creating if needed) the vertex there; `ids` is scratch space reused between calls.
template <class LatticeId>
void add_box_face(MeshBuilder& out, const Lattice& corner, int size, int axis, bool positive, LatticeId& id, std::vector<int>& ids) {
  // (u, v, axis) is right-handed, so u × v = +axis; swapping u and v turns the face to −axis.
  int u = (axis + 1) % 3, v = (axis + 2) % 3;
  if (!positive) std::swap(u, v);
  Lattice origin = corner;
  if (positive) origin[axis] += size;
  const int stride = size + 1;
  // Look each grid point up once, not once per incident quad (id may be a hash lookup).
  ids.resize(static_cast<size_t>(stride) * stride);
  for (int b = 0; b <= size; ++b) {
    for (int a = 0; a <= size; ++a) {
      Lattice p = origin;
      p[u] += a;
      p[v] += b;
      ids[static_cast<size_t>(b) * stride + a] = id(p);
    }
  }
  add_quad_grid(
      out, size, size, [&](int a, int b) { return ids[static_cast<size_t>(b) * stride + a]; },
      [size](int a, int b) { return diamond_diagonal(a, b, size); });
}

// Vertex id of a surface point of the lattice cube [0, n]^3 without a lookup table: the bottom
// layer z = 0 ((n+1)² points, row-major), then for each 0 < z < n a ring of 4n points walked
// counter-clockwise from (0, 0), then the top layer z = n.
int cube_surface_id(const Lattice& p, int n) {
  const int x = p[0], y = p[1], z = p[2];
  const int layer = (n + 1) * (n + 1);
  if (z == 0) return y * (n + 1) + x;
  if (z == n) return layer + 4 * n * (n - 1) + y * (n + 1) + x;
  int ring;
  if (y == 0 && x < n) {
    ring = x;
  } else if (x == n && y < n) {
    ring = n + y;
  } else if (y == n && x > 0) {
    ring = 2 * n + (n - x);
  } else {  // x == 0, y > 0
    ring = 3 * n + (n - y);
  }
  return layer + (z - 1) * 4 * n + ring;
}

void project_to_unit_sphere(MatrixX3d& V, Eigen::Index first_row) {
  for (Eigen::Index i = first_row; i < V.rows(); ++i) V.row(i).normalize();
}

// The undirected edges of F: edge_of_halfedge[3f + k] is the edge from corner k to corner k+1 of
// face f; edges[e] = {i, j} with i < j, numbered in increasing (i, j). Half-edges are bucketed by
// their smaller vertex (counting sort) and each bucket sorted on its own, so this is O(V + F) for
// bounded valence and never worse than O(F log F).
struct EdgeIndex {
  std::vector<int> edge_of_halfedge;
  std::vector<std::array<int, 2>> edges;
};

EdgeIndex index_edges(const MatrixX3i& F, int num_vertices) {
  const size_t num_halfedges = 3 * static_cast<size_t>(F.rows());
  auto endpoints = [&F](size_t h) {
    const int a = F(h / 3, h % 3), b = F(h / 3, (h + 1) % 3);
    return std::make_pair(std::min(a, b), std::max(a, b));
  };
  std::vector<size_t> bucket_start(static_cast<size_t>(num_vertices) + 1, 0);
  for (size_t h = 0; h < num_halfedges; ++h) ++bucket_start[endpoints(h).first + 1];
  std::partial_sum(bucket_start.begin(), bucket_start.end(), bucket_start.begin());

  // Entry = (larger vertex << 32) | half-edge: sorting a bucket groups each edge's half-edges.
  std::vector<std::uint64_t> entries(num_halfedges);
  std::vector<size_t> fill(bucket_start.begin(), bucket_start.end() - 1);
  for (size_t h = 0; h < num_halfedges; ++h) {
    const auto [lo, hi] = endpoints(h);
    entries[fill[lo]++] = (static_cast<std::uint64_t>(hi) << 32) | h;
  }

  EdgeIndex index;
  index.edge_of_halfedge.resize(num_halfedges);
  index.edges.reserve(num_halfedges / 2 + 1);
  for (int lo = 0; lo < num_vertices; ++lo) {
    const auto begin = entries.begin() + bucket_start[lo], end = entries.begin() + bucket_start[lo + 1];
    std::sort(begin, end);
    int previous_hi = -1;
    for (auto it = begin; it != end; ++it) {
      const int hi = static_cast<int>(*it >> 32);
      if (hi != previous_hi) index.edges.push_back({lo, hi});
      previous_hi = hi;
      index.edge_of_halfedge[*it & 0xffffffffu] = static_cast<int>(index.edges.size() - 1);
    }
  }
  return index;
}

// Uniform draw in [0, bound) from the raw 32-bit output: std::uniform_int_distribution and
// std::shuffle are implementation-defined, so they would give different meshes per standard library.
int draw_below(std::mt19937& rng, int bound) {
  return static_cast<int>((static_cast<std::uint64_t>(rng()) * static_cast<std::uint64_t>(bound)) >> 32);
}

std::vector<int> random_permutation(int n, std::mt19937& rng) {
  std::vector<int> permutation(static_cast<size_t>(n));
  std::iota(permutation.begin(), permutation.end(), 0);
  for (int i = n - 1; i > 0; --i) std::swap(permutation[i], permutation[draw_below(rng, i + 1)]);
  return permutation;
}

}  // namespace

Mesh make_icosphere(int level) {
  require(level >= 0, "make_icosphere", "level", level, "level >= 0");
  require_size("make_icosphere", 10 * std::pow(4.0, level) + 2, 20 * std::pow(4.0, level));
  const double t = (1 + std::sqrt(5.0)) / 2;
  const double corners[12][3] = {{-1, t, 0},  {1, t, 0},  {-1, -t, 0}, {1, -t, 0}, {0, -1, t},  {0, 1, t},
                                 {0, -1, -t}, {0, 1, -t}, {t, 0, -1},  {t, 0, 1},  {-t, 0, -1}, {-t, 0, 1}};
  // Counter-clockwise seen from outside.
  const int faces[20][3] = {{0, 11, 5},  {0, 5, 1},  {0, 1, 7},  {0, 7, 10}, {0, 10, 11}, {1, 5, 9}, {5, 11, 4},
                            {11, 10, 2}, {10, 7, 6}, {7, 1, 8},  {3, 9, 4},  {3, 4, 2},   {3, 2, 6}, {3, 6, 8},
                            {3, 8, 9},   {4, 9, 5},  {2, 4, 11}, {6, 2, 10}, {8, 6, 7},   {9, 8, 1}};
  MeshBuilder builder(12, 20);
  for (const auto& c : corners) builder.add_vertex(c[0], c[1], c[2]);
  for (const auto& f : faces) builder.add_triangle(f[0], f[1], f[2]);
  Mesh mesh = builder.finish();
  project_to_unit_sphere(mesh.V, 0);
  for (int l = 0; l < level; ++l) {
    const Eigen::Index old_vertices = mesh.V.rows();
    mesh = subdivide_midpoint(mesh);
    // Only the new midpoints move, so coarser levels stay exact prefixes.
    project_to_unit_sphere(mesh.V, old_vertices);
  }
  return mesh;
}

Mesh make_uv_sphere(int rings, int segments) {
  require(rings >= 2, "make_uv_sphere", "rings", rings, "rings >= 2");
  require(segments >= 3, "make_uv_sphere", "segments", segments, "segments >= 3");
  const double rows = rings - 1.0;
  require_size("make_uv_sphere", 2 + segments * rows, 2 * segments * rows);
  MeshBuilder builder(2 + segments * rows, 2 * segments * rows);
  const int north = builder.add_vertex(0, 0, 1);
  for (int row = 1; row < rings; ++row) {
    const double theta = kPi * row / rings;
    for (int j = 0; j < segments; ++j) {
      const double phi = 2 * kPi * j / segments;
      builder.add_vertex(std::sin(theta) * std::cos(phi), std::sin(theta) * std::sin(phi), std::cos(theta));
    }
  }
  const int south = builder.add_vertex(0, 0, -1);
  auto id = [segments](int row, int j) { return 1 + (row - 1) * segments + j % segments; };
  for (int j = 0; j < segments; ++j) builder.add_triangle(north, id(1, j), id(1, j + 1));
  // Grid a = row offset (southward), b = longitude: south × east points outward.
  add_quad_grid(builder, rings - 2, segments, [&](int a, int b) { return id(1 + a, b); });
  for (int j = 0; j < segments; ++j) builder.add_triangle(south, id(rings - 1, j + 1), id(rings - 1, j));
  return builder.finish();
}

Mesh make_cube_sphere(int n, bool spherical) {
  require(n >= 1, "make_cube_sphere", "n", n, "n >= 1");
  require_size("make_cube_sphere", 6.0 * n * n + 2, 12.0 * n * n);
  const int num_vertices = 6 * n * n + 2;
  MeshBuilder builder(num_vertices, 12.0 * n * n);
  builder.resize_vertices(num_vertices);
  // Vertices shared by several cube faces get the same arithmetic id (and the same position).
  auto id = [&](const Lattice& p) {
    const int vertex = cube_surface_id(p, n);
    Eigen::Vector3d x(p[0], p[1], p[2]);
    x = x * (2.0 / n) - Eigen::Vector3d::Ones();
    if (spherical) x.normalize();
    builder.set_vertex(vertex, x[0], x[1], x[2]);
    return vertex;
  };
  std::vector<int> scratch;
  for (int axis = 0; axis < 3; ++axis) {
    for (bool positive : {false, true}) add_box_face(builder, {0, 0, 0}, n, axis, positive, id, scratch);
  }
  return builder.finish();
}

Mesh make_torus(int nu, int nv, double R, double r) {
  require(nu >= 3, "make_torus", "nu", nu, "nu >= 3");
  require(nv >= 3, "make_torus", "nv", nv, "nv >= 3");
  require(std::isfinite(r) && r > 0, "make_torus", "r", r, "0 < r < R");
  require(std::isfinite(R) && R > r, "make_torus", "R", R, "R > r = " + to_text(r));
  require_size("make_torus", double(nu) * nv, 2.0 * nu * nv);
  MeshBuilder builder(double(nu) * nv, 2.0 * nu * nv);
  for (int i = 0; i < nu; ++i) {
    const double u = 2 * kPi * i / nu;
    for (int j = 0; j < nv; ++j) {
      const double v = 2 * kPi * j / nv;
      const double rho = R + r * std::cos(v);
      builder.add_vertex(rho * std::cos(u), rho * std::sin(u), r * std::sin(v));
    }
  }
  // d/du × d/dv is the outward normal.
  add_quad_grid(builder, nu, nv, [nu, nv](int a, int b) { return (a % nu) * nv + b % nv; });
  return builder.finish();
}

Mesh make_genus_surface(int g, int resolution) {
  require(g >= 0, "make_genus_surface", "g", g, "g >= 0");
  require(resolution >= 1, "make_genus_surface", "resolution", resolution, "resolution >= 1");
  const double voxel_faces = 72.0 * g + 56;
  require_size("make_genus_surface", 2 - 2.0 * g + double(resolution) * resolution * voxel_faces,
               2.0 * resolution * resolution * voxel_faces);
  // Plate of nx × ny × nz voxels; hole t covers x in [4t+2, 4t+4), y in [2, 4).
  const int nx = 4 * g + 2, ny = 6, nz = 2;
  // Lattice coordinates are packed into 21 bits each for the hash key.
  if (double(nx) * resolution >= (1 << 21)) {
    throw Error("make_genus_surface: g = " + to_text(g) + " with resolution = " + to_text(resolution) +
                " is too large (need (4g+2)·resolution < 2^21)");
  }
  auto solid = [&](int x, int y, int z) {
    if (x < 0 || y < 0 || z < 0 || x >= nx || y >= ny || z >= nz) return false;
    const bool in_hole = y >= 2 && y < 4 && x >= 2 && x < nx - 2 && (x - 2) % 4 < 2;
    return !in_hole;
  };
  const double expected_vertices = 2 - 2.0 * g + double(resolution) * resolution * voxel_faces;
  MeshBuilder builder(expected_vertices, 2.0 * resolution * resolution * voxel_faces);
  std::unordered_map<std::uint64_t, int> vertex_at;
  vertex_at.reserve(static_cast<size_t>(expected_vertices));
  const double step = 1.0 / (3.0 * resolution);  // voxel edge 1/3
  auto id = [&](const Lattice& p) {
    const std::uint64_t key =
        static_cast<std::uint64_t>(p[0]) | static_cast<std::uint64_t>(p[1]) << 21 | static_cast<std::uint64_t>(p[2]) << 42;
    const auto [it, inserted] = vertex_at.try_emplace(key, builder.num_vertices());
    if (inserted) {
      builder.add_vertex(p[0] * step - nx / 6.0, p[1] * step - ny / 6.0, p[2] * step - nz / 6.0);
    }
    return it->second;
  };
  std::vector<int> scratch;
  for (int z = 0; z < nz; ++z) {
    for (int y = 0; y < ny; ++y) {
      for (int x = 0; x < nx; ++x) {
        if (!solid(x, y, z)) continue;
        const Lattice voxel = {x, y, z};
        for (int axis = 0; axis < 3; ++axis) {
          for (bool positive : {false, true}) {
            Lattice neighbour = voxel;
            neighbour[axis] += positive ? 1 : -1;
            if (solid(neighbour[0], neighbour[1], neighbour[2])) continue;
            const Lattice corner = {x * resolution, y * resolution, z * resolution};
            add_box_face(builder, corner, resolution, axis, positive, id, scratch);
          }
        }
      }
    }
  }
  return builder.finish();
}

Mesh make_capped_cylinder(int rings, int segments, int stacks, double height) {
  require(stacks >= 1, "make_capped_cylinder", "stacks", stacks, "stacks >= 1");
  require(std::isfinite(height) && height > 0, "make_capped_cylinder", "height", height, "height > 0");
  const Mesh disk = make_disk(rings, segments);  // checks rings and segments
  // rim: the first id of the disk's outer ring, of `count` vertices.
  const int nd = static_cast<int>(disk.V.rows()), count = rings * segments, rim = nd - count;
  require_size("make_capped_cylinder", 2.0 * nd + (stacks - 1.0) * count, 2.0 * disk.F.rows() + 2.0 * stacks * count);
  MeshBuilder builder(2.0 * nd + (stacks - 1.0) * count, 2.0 * disk.F.rows() + 2.0 * stacks * count);
  for (int cap = 0; cap < 2; ++cap)
    for (int v = 0; v < nd; ++v) builder.add_vertex(disk.V(v, 0), disk.V(v, 1), cap == 0 ? -height / 2 : height / 2);
  for (int r = 1; r < stacks; ++r)
    for (int m = 0; m < count; ++m) {
      const double angle = 2 * kPi * m / count;
      builder.add_vertex(std::cos(angle), std::sin(angle), -height / 2 + height * r / stacks);
    }
  for (int f = 0; f < disk.F.rows(); ++f) builder.add_triangle(disk.F(f, 0), disk.F(f, 2), disk.F(f, 1));  // bottom: faces −z
  for (int f = 0; f < disk.F.rows(); ++f) builder.add_triangle(nd + disk.F(f, 0), nd + disk.F(f, 1), nd + disk.F(f, 2));
  // Row r, vertex m of the side; rows 0 and `stacks` are the rims. (angle, z) × is the outward normal.
  auto id = [&](int m, int r) {
    m %= count;
    if (r == 0) return rim + m;
    if (r == stacks) return nd + rim + m;
    return 2 * nd + (r - 1) * count + m;
  };
  add_quad_grid(builder, count, stacks, id);
  return builder.finish();
}

Mesh make_disk(int rings, int segments) {
  require(rings >= 1, "make_disk", "rings", rings, "rings >= 1");
  require(segments >= 3, "make_disk", "segments", segments, "segments >= 3");
  const double num_vertices = 1 + segments * 0.5 * rings * (rings + 1.0);
  require_size("make_disk", num_vertices, double(segments) * rings * rings);
  MeshBuilder builder(num_vertices, double(segments) * rings * rings);
  const int centre = builder.add_vertex(0, 0, 0);
  for (int k = 1; k <= rings; ++k) {
    const int count = k * segments;
    const double radius = double(k) / rings;
    for (int m = 0; m < count; ++m) {
      const double angle = 2 * kPi * m / count;
      builder.add_vertex(radius * std::cos(angle), radius * std::sin(angle), 0);
    }
  }
  auto ring_start = [segments](int k) { return 1 + segments * k * (k - 1) / 2; };
  for (int o = 0; o < segments; ++o) builder.add_triangle(centre, ring_start(1) + o, ring_start(1) + (o + 1) % segments);
  for (int k = 2; k <= rings; ++k) {
    const int inner_count = (k - 1) * segments, outer_count = k * segments;
    const int inner = ring_start(k - 1), outer = ring_start(k);
    // Merge the two rings by angle: step along whichever ring's next vertex comes first (the outer
    // one on ties), each step making one counter-clockwise triangle.
    int i = 0, o = 0;
    while (i < inner_count || o < outer_count) {
      const bool step_outer =
          i == inner_count || (o < outer_count && std::int64_t(o + 1) * inner_count <= std::int64_t(i + 1) * outer_count);
      const int a = inner + i % inner_count, b = outer + o % outer_count;
      if (step_outer) {
        ++o;
        builder.add_triangle(a, b, outer + o % outer_count);
      } else {
        ++i;
        builder.add_triangle(a, b, inner + i % inner_count);
      }
    }
  }
  return builder.finish();
}

Mesh make_annulus(int rings, int segments, double r_in, double r_out) {
  require(rings >= 1, "make_annulus", "rings", rings, "rings >= 1");
  require(segments >= 3, "make_annulus", "segments", segments, "segments >= 3");
  require(std::isfinite(r_in) && r_in > 0, "make_annulus", "r_in", r_in, "0 < r_in < r_out");
  require(std::isfinite(r_out) && r_out > r_in, "make_annulus", "r_out", r_out, "r_out > r_in = " + to_text(r_in));
  require_size("make_annulus", (rings + 1.0) * segments, 2.0 * rings * segments);
  MeshBuilder builder((rings + 1.0) * segments, 2.0 * rings * segments);
  for (int k = 0; k <= rings; ++k) {
    const double radius = r_in + (r_out - r_in) * k / rings;
    for (int j = 0; j < segments; ++j) {
      const double angle = 2 * kPi * j / segments;
      builder.add_vertex(radius * std::cos(angle), radius * std::sin(angle), 0);
    }
  }
  // Grid a = radial, b = angular: radial × angular is +z.
  add_quad_grid(builder, rings, segments, [segments](int a, int b) { return a * segments + b % segments; });
  return builder.finish();
}

Mesh make_holed_grid(int n, int holes) {
  require(n >= 1, "make_holed_grid", "n", n, "n >= 1");
  require(holes >= 0, "make_holed_grid", "holes", holes, "holes >= 0");
  if (n < 2 * double(holes) + 1) {
    throw Error("make_holed_grid: n = " + to_text(n) + " is too small for " + to_text(holes) + " holes (need n >= 2·holes + 1 = " +
                to_text(2 * double(holes) + 1) + " so that holes are at least one cell apart and away from the border)");
  }
  require_size("make_holed_grid", (n + 1.0) * (n + 1.0), 2.0 * n * n);
  // Hole t: cells [start_t, start_t + w) in x with start_t = ⌊(2t+1)·n/(2·holes+1)⌋, and a centred
  // band of w cells in y; see generate.h for why the gaps are at least one cell.
  const int w = n / (2 * holes + 1);
  const int y0 = (n - w) / 2;
  std::vector<char> in_hole_column(static_cast<size_t>(n), 0);
  for (int t = 0; t < holes; ++t) {
    const int x0 = static_cast<int>((2 * std::int64_t(t) + 1) * n / (2 * holes + 1));
    std::fill(in_hole_column.begin() + x0, in_hole_column.begin() + x0 + w, 1);
  }
  auto present = [&](int x, int y) { return !(in_hole_column[x] && y >= y0 && y < y0 + w); };

  // Compact renumbering: a grid point is kept when one of its (up to four) cells is present.
  const int stride = n + 1;
  std::vector<int> vertex_of_point(static_cast<size_t>(stride) * stride, -1);
  MeshBuilder builder(double(stride) * stride, 2.0 * n * n);
  for (int y = 0; y <= n; ++y) {
    for (int x = 0; x <= n; ++x) {
      bool used = false;
      for (int cy = std::max(y - 1, 0); cy <= std::min(y, n - 1) && !used; ++cy) {
        for (int cx = std::max(x - 1, 0); cx <= std::min(x, n - 1) && !used; ++cx) used = present(cx, cy);
      }
      if (used) vertex_of_point[static_cast<size_t>(y) * stride + x] = builder.add_vertex(double(x) / n, double(y) / n, 0);
    }
  }
  auto id = [&](int x, int y) { return vertex_of_point[static_cast<size_t>(y) * stride + x]; };
  for (int y = 0; y < n; ++y) {
    for (int x = 0; x < n; ++x) {
      if (present(x, y)) builder.add_quad(id(x, y), id(x + 1, y), id(x + 1, y + 1), id(x, y + 1), true);
    }
  }
  return builder.finish();
}

Mesh concatenate(const std::vector<Mesh>& parts) {
  Eigen::Index num_vertices = 0, num_faces = 0;
  for (const Mesh& part : parts) {
    num_vertices += part.V.rows();
    num_faces += part.F.rows();
  }
  require_size("concatenate", double(num_vertices), double(num_faces));
  Mesh mesh;
  mesh.V.resize(num_vertices, 3);
  mesh.F.resize(num_faces, 3);
  Eigen::Index vertex_offset = 0, face_offset = 0;
  for (const Mesh& part : parts) {
    mesh.V.middleRows(vertex_offset, part.V.rows()) = part.V;
    mesh.F.middleRows(face_offset, part.F.rows()) = part.F.array() + static_cast<int>(vertex_offset);
    vertex_offset += part.V.rows();
    face_offset += part.F.rows();
  }
  return mesh;
}

Mesh subdivide_midpoint(const Mesh& mesh) {
  require_valid_faces("subdivide_midpoint", mesh);
  const Eigen::Index num_vertices = mesh.V.rows(), num_faces = mesh.F.rows();
  require_size("subdivide_midpoint", double(num_vertices) + 3.0 * num_faces, 4.0 * num_faces);
  const EdgeIndex index = index_edges(mesh.F, static_cast<int>(num_vertices));
  const Eigen::Index num_edges = static_cast<Eigen::Index>(index.edges.size());

  Mesh out;
  out.V.resize(num_vertices + num_edges, 3);
  out.V.topRows(num_vertices) = mesh.V;
  for (Eigen::Index e = 0; e < num_edges; ++e) {
    out.V.row(num_vertices + e) = 0.5 * (mesh.V.row(index.edges[e][0]) + mesh.V.row(index.edges[e][1]));
  }
  out.F.resize(4 * num_faces, 3);
  const int first_midpoint = static_cast<int>(num_vertices);
  for (Eigen::Index f = 0; f < num_faces; ++f) {
    const int a = mesh.F(f, 0), b = mesh.F(f, 1), c = mesh.F(f, 2);
    const int ab = first_midpoint + index.edge_of_halfedge[3 * f];
    const int bc = first_midpoint + index.edge_of_halfedge[3 * f + 1];
    const int ca = first_midpoint + index.edge_of_halfedge[3 * f + 2];
    out.F.row(4 * f) << a, ab, ca;
    out.F.row(4 * f + 1) << ab, b, bc;
    out.F.row(4 * f + 2) << ca, bc, c;
    out.F.row(4 * f + 3) << ab, bc, ca;
  }
  return out;
}

Mesh permute(const Mesh& mesh, unsigned seed, std::vector<int>* vertex_perm, std::vector<int>* face_perm) {
  require_valid_faces("permute", mesh);
  const int num_vertices = static_cast<int>(mesh.V.rows()), num_faces = static_cast<int>(mesh.F.rows());
  std::mt19937 rng(seed);
  const std::vector<int> new_vertex = random_permutation(num_vertices, rng);
  const std::vector<int> new_face = random_permutation(num_faces, rng);

  Mesh out;
  out.V.resize(num_vertices, 3);
  for (int v = 0; v < num_vertices; ++v) out.V.row(new_vertex[v]) = mesh.V.row(v);
  out.F.resize(num_faces, 3);
  for (int f = 0; f < num_faces; ++f) {
    const int shift = draw_below(rng, 3);  // cyclic rotation keeps the orientation
    for (int k = 0; k < 3; ++k) out.F(new_face[f], k) = new_vertex[mesh.F(f, (k + shift) % 3)];
  }
  if (vertex_perm) *vertex_perm = new_vertex;
  if (face_perm) *face_perm = new_face;
  return out;
}

namespace {

// Appends the split faces' other children to `out` (whose first `num_faces` faces are the input's, each split one
// holding its first child) and fills `parent_face` (when not null): the input's faces their own, the appended
// ones `appended_parent`.
void append_children(Mesh& out, Eigen::Index num_faces, const std::vector<std::array<int, 3>>& appended,
                     const std::vector<int>& appended_parent, std::vector<int>* parent_face) {
  out.F.conservativeResize(num_faces + static_cast<Eigen::Index>(appended.size()), 3);
  for (size_t k = 0; k < appended.size(); ++k)
    out.F.row(num_faces + static_cast<Eigen::Index>(k)) << appended[k][0], appended[k][1], appended[k][2];
  if (parent_face) {
    parent_face->resize(out.F.rows());
    std::iota(parent_face->begin(), parent_face->begin() + num_faces, 0);
    std::copy(appended_parent.begin(), appended_parent.end(), parent_face->begin() + num_faces);
  }
}

}  // namespace

Mesh split_edges_near_end(const Mesh& mesh, double t, double lift, std::vector<int>* parent_face) {
  require_valid_faces("split_edges_near_end", mesh);
  require(t >= 0 && t < 1, "split_edges_near_end", "t", t, "0 <= t < 1");
  require(std::isfinite(lift), "split_edges_near_end", "lift", lift, "a finite lift");
  const Eigen::Index num_vertices = mesh.V.rows(), num_faces = mesh.F.rows();
  require_size("split_edges_near_end", double(num_vertices) + 1.5 * num_faces, 2.0 * num_faces);
  const EdgeIndex index = index_edges(mesh.F, static_cast<int>(num_vertices));
  const size_t num_edges = index.edges.size();
  // The faces of each edge (up to two are used; a non-manifold edge is never split).
  std::vector<std::array<int, 3>> edge_faces(num_edges, {-1, -1, 0});
  for (Eigen::Index f = 0; f < num_faces; ++f)
    for (int k = 0; k < 3; ++k) {
      std::array<int, 3>& slot = edge_faces[index.edge_of_halfedge[3 * f + k]];
      if (slot[2] < 2) slot[slot[2]] = static_cast<int>(f);
      ++slot[2];
    }
  // Edges in increasing (i, j) order: index_edges numbers them so.
  std::vector<int> order(num_edges);
  std::iota(order.begin(), order.end(), 0);
  std::sort(order.begin(), order.end(), [&](int a, int b) { return index.edges[a] < index.edges[b]; });
  std::vector<char> face_used(num_faces, 0);
  std::vector<int> split_vertex(num_edges, -1);
  std::vector<Eigen::RowVector3d> new_vertices;
  for (int e : order) {
    const std::array<int, 3>& s = edge_faces[e];
    if (s[2] > 2 || face_used[s[0]] || (s[1] >= 0 && face_used[s[1]])) continue;
    face_used[s[0]] = 1;
    if (s[1] >= 0) face_used[s[1]] = 1;
    const Eigen::RowVector3d pi = mesh.V.row(index.edges[e][0]), pj = mesh.V.row(index.edges[e][1]);
    Eigen::RowVector3d normal = Eigen::RowVector3d::Zero();
    for (int side = 0; side < 2 && s[side] >= 0; ++side) {
      const Eigen::RowVector3d a = mesh.V.row(mesh.F(s[side], 0)), b = mesh.V.row(mesh.F(s[side], 1)), c = mesh.V.row(mesh.F(s[side], 2));
      const Eigen::RowVector3d n = (b - a).cross(c - a);
      if (n.norm() > 0) normal += n.normalized();
    }
    if (normal.norm() > 0) normal.normalize();
    split_vertex[e] = static_cast<int>(num_vertices + new_vertices.size());
    new_vertices.push_back(pi + t * (pj - pi) + lift * (pj - pi).norm() * normal);
  }
  Mesh out;
  out.V.resize(num_vertices + static_cast<Eigen::Index>(new_vertices.size()), 3);
  out.V.topRows(num_vertices) = mesh.V;
  for (size_t k = 0; k < new_vertices.size(); ++k) out.V.row(num_vertices + static_cast<Eigen::Index>(k)) = new_vertices[k];
  std::vector<std::array<int, 3>> appended;
  std::vector<int> appended_parent;
  out.F = mesh.F;
  for (Eigen::Index f = 0; f < num_faces; ++f)
    for (int k = 0; k < 3; ++k) {
      const int m = split_vertex[index.edge_of_halfedge[3 * f + k]];
      if (m < 0) continue;
      const int a = mesh.F(f, k), b = mesh.F(f, (k + 1) % 3), c = mesh.F(f, (k + 2) % 3);
      out.F.row(f) << a, m, c;
      appended.push_back({m, b, c});
      appended_parent.push_back(static_cast<int>(f));
    }
  append_children(out, num_faces, appended, appended_parent, parent_face);
  return out;
}

Mesh split_faces_at_centroids(const Mesh& mesh, const std::vector<int>& faces, std::vector<int>* parent_face) {
  require_valid_faces("split_faces_at_centroids", mesh);
  const Eigen::Index num_vertices = mesh.V.rows(), num_faces = mesh.F.rows();
  std::vector<int> list = faces;
  std::sort(list.begin(), list.end());
  list.erase(std::unique(list.begin(), list.end()), list.end());
  for (int f : list)
    if (f < 0 || f >= num_faces)
      throw Error("split_faces_at_centroids: face " + std::to_string(f) + " out of range (mesh has " + std::to_string(num_faces) +
                  " faces)");
  require_size("split_faces_at_centroids", double(num_vertices) + list.size(), double(num_faces) + 2.0 * list.size());
  const Eigen::Index added = static_cast<Eigen::Index>(list.size());
  Mesh out;
  out.V.resize(num_vertices + added, 3);
  out.V.topRows(num_vertices) = mesh.V;
  out.F.resize(num_faces + 2 * added, 3);
  out.F.topRows(num_faces) = mesh.F;
  for (Eigen::Index k = 0; k < added; ++k) {
    const int f = list[k], a = mesh.F(f, 0), b = mesh.F(f, 1), c = mesh.F(f, 2);
    const int g = static_cast<int>(num_vertices + k);
    out.V.row(g) = (mesh.V.row(a) + mesh.V.row(b) + mesh.V.row(c)) / 3.0;
    out.F.row(f) << a, b, g;
    out.F.row(num_faces + 2 * k) << b, c, g;
    out.F.row(num_faces + 2 * k + 1) << c, a, g;
  }
  if (parent_face) {
    parent_face->resize(out.F.rows());
    std::iota(parent_face->begin(), parent_face->begin() + num_faces, 0);
    for (Eigen::Index k = 0; k < added; ++k) (*parent_face)[num_faces + 2 * k] = (*parent_face)[num_faces + 2 * k + 1] = list[k];
  }
  return out;
}

Mesh split_edges_at_midpoints(const Mesh& mesh, const std::vector<std::pair<int, int>>& edges, std::vector<int>* parent_face) {
  require_valid_faces("split_edges_at_midpoints", mesh);
  const Eigen::Index num_vertices = mesh.V.rows(), num_faces = mesh.F.rows();
  std::vector<std::pair<int, int>> list;
  for (auto [i, j] : edges) {
    if (i < 0 || j < 0 || i >= num_vertices || j >= num_vertices || i == j)
      throw Error("split_edges_at_midpoints: (" + std::to_string(i) + ", " + std::to_string(j) + ") is not an edge (mesh has " +
                  std::to_string(num_vertices) + " vertices)");
    list.emplace_back(std::min(i, j), std::max(i, j));
  }
  std::sort(list.begin(), list.end());
  list.erase(std::unique(list.begin(), list.end()), list.end());
  require_size("split_edges_at_midpoints", double(num_vertices) + list.size(), double(num_faces) + 2.0 * list.size());
  // The midpoint of half-edge k of face f, or −1.
  auto midpoint = [&](Eigen::Index f, int k) {
    const int a = mesh.F(f, k), b = mesh.F(f, (k + 1) % 3);
    const auto it = std::lower_bound(list.begin(), list.end(), std::make_pair(std::min(a, b), std::max(a, b)));
    return it != list.end() && *it == std::make_pair(std::min(a, b), std::max(a, b)) ? static_cast<int>(num_vertices + (it - list.begin())) : -1;
  };
  std::vector<char> found(list.size(), 0);
  Mesh out;
  out.V.resize(num_vertices + static_cast<Eigen::Index>(list.size()), 3);
  out.V.topRows(num_vertices) = mesh.V;
  for (size_t k = 0; k < list.size(); ++k)
    out.V.row(num_vertices + static_cast<Eigen::Index>(k)) = (mesh.V.row(list[k].first) + mesh.V.row(list[k].second)) / 2.0;
  out.F = mesh.F;
  std::vector<std::array<int, 3>> appended;
  std::vector<int> appended_parent;
  for (Eigen::Index f = 0; f < num_faces; ++f) {
    std::array<int, 3> m{};
    int splits = 0;
    for (int k = 0; k < 3; ++k)
      if ((m[k] = midpoint(f, k)) >= 0) ++splits, found[m[k] - num_vertices] = 1;
    if (splits == 0) continue;
    // Rotate so that half-edge 0 (a → b) is split and, with two splits, half-edge 1 (b → c) too.
    int r = 0;
    while (!(m[r] >= 0 && (splits != 2 || m[(r + 1) % 3] >= 0))) ++r;
    const int a = mesh.F(f, r), b = mesh.F(f, (r + 1) % 3), c = mesh.F(f, (r + 2) % 3);
    const int ab = m[r], bc = m[(r + 1) % 3], ca = m[(r + 2) % 3];
    std::vector<std::array<int, 3>> children;
    if (splits == 1) {
      children = {{a, ab, c}, {ab, b, c}};
    } else if (splits == 2) {
      children = {{ab, b, bc}};
      // The quadrilateral a, ab, bc, c along its shorter diagonal.
      if ((out.V.row(ab) - out.V.row(c)).norm() <= (out.V.row(a) - out.V.row(bc)).norm())
        children.push_back({a, ab, c}), children.push_back({ab, bc, c});
      else
        children.push_back({a, ab, bc}), children.push_back({a, bc, c});
    } else {
      children = {{a, ab, ca}, {ab, b, bc}, {ca, bc, c}, {ab, bc, ca}};
    }
    out.F.row(f) << children[0][0], children[0][1], children[0][2];
    for (size_t k = 1; k < children.size(); ++k) appended.push_back(children[k]), appended_parent.push_back(static_cast<int>(f));
  }
  for (size_t k = 0; k < list.size(); ++k)
    if (!found[k])
      throw Error("split_edges_at_midpoints: (" + std::to_string(list[k].first) + ", " + std::to_string(list[k].second) +
                  ") is not an edge of a face");
  append_children(out, num_faces, appended, appended_parent, parent_face);
  return out;
}

}  // namespace trivcon
