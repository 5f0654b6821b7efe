// SPDX-License-Identifier: MIT
// Tests of trivcon/generate.h. Every property is recomputed here from V and F alone (no use of
// topology.h), so a bug shared by the generators and the library's connectivity code cannot hide.
#include "trivcon/generate.h"

#include <gtest/gtest.h>

#include <Eigen/Geometry>

#include <algorithm>
#include <array>
#include <cmath>
#include <cstdint>
#include <functional>
#include <map>
#include <numeric>
#include <set>
#include <string>
#include <unordered_map>
#include <unordered_set>
#include <utility>
#include <vector>

#include "trivcon/error.h"

namespace trivcon {
namespace {

// Everything the tests assert about a mesh, computed by brute force.
struct MeshReport {
  int vertices = 0, faces = 0, edges = 0;
  int bad_faces = 0;  // index out of range or repeated corner
  int boundary_edges = 0;
  int nonmanifold_edges = 0;     // > 2 half-edges, or two half-edges in the same direction
  int inconsistent_edges = 0;    // the two faces of an interior edge traverse it the same way
  int nonmanifold_vertices = 0;  // faces around the vertex are not one fan
  int boundary_loops = 0;        // connected components of the boundary edges
  int unreferenced_vertices = 0;
  int duplicate_vertices = 0;                             // pairs of vertices closer than 1e-9 · bounding-box diagonal
  double min_area = INFINITY;                             // smallest face area
  double min_angle_degrees = 180;                         // smallest corner angle
  double signed_volume = 0;                               // Σ det(a, b, c)/6: > 0 when a closed mesh faces outward
  Eigen::Vector3d area_vector = Eigen::Vector3d::Zero();  // Σ (b − a) × (c − a)/2
  std::vector<int> valence;                               // edges at each vertex
  int euler_characteristic() const { return vertices - edges + faces; }
};

std::uint64_t edge_key(int a, int b) {
  return static_cast<std::uint64_t>(std::min(a, b)) << 32 | static_cast<std::uint32_t>(std::max(a, b));
}

int find_root(std::vector<int>& parent, int v) {
  while (parent[v] != v) v = parent[v] = parent[parent[v]];
  return v;
}

// Number of vertex pairs closer than `tolerance`, using a hash grid of cell size `tolerance`.
int count_close_pairs(const MatrixX3d& V, double tolerance) {
  std::unordered_map<std::uint64_t, std::vector<int>> cells;
  auto cell_of = [&](int v, int axis) { return static_cast<std::int64_t>(std::floor(V(v, axis) / tolerance)); };
  auto key = [](std::int64_t x, std::int64_t y, std::int64_t z) {
    return static_cast<std::uint64_t>(x * 73856093) ^ static_cast<std::uint64_t>(y * 19349663) ^ static_cast<std::uint64_t>(z * 83492791);
  };
  int pairs = 0;
  for (int v = 0; v < V.rows(); ++v) {
    const std::int64_t cx = cell_of(v, 0), cy = cell_of(v, 1), cz = cell_of(v, 2);
    for (std::int64_t dx = -1; dx <= 1; ++dx) {
      for (std::int64_t dy = -1; dy <= 1; ++dy) {
        for (std::int64_t dz = -1; dz <= 1; ++dz) {
          auto it = cells.find(key(cx + dx, cy + dy, cz + dz));
          if (it == cells.end()) continue;
          for (int w : it->second) pairs += (V.row(v) - V.row(w)).norm() < tolerance;
        }
      }
    }
    cells[key(cx, cy, cz)].push_back(v);
  }
  return pairs;
}

MeshReport analyse(const Mesh& mesh) {
  MeshReport report;
  const int nv = static_cast<int>(mesh.V.rows()), nf = static_cast<int>(mesh.F.rows());
  report.vertices = nv;
  report.faces = nf;
  for (int f = 0; f < nf; ++f) {
    const int a = mesh.F(f, 0), b = mesh.F(f, 1), c = mesh.F(f, 2);
    const bool in_range = std::min({a, b, c}) >= 0 && std::max({a, b, c}) < nv;
    report.bad_faces += !in_range || a == b || b == c || c == a;
  }
  if (report.bad_faces > 0) return report;

  // Half-edge counts per undirected edge: [0] for min→max, [1] for max→min.
  std::unordered_map<std::uint64_t, std::array<int, 2>> edges;
  edges.reserve(3 * static_cast<size_t>(nf));
  std::vector<std::vector<int>> faces_at(nv);
  for (int f = 0; f < nf; ++f) {
    for (int k = 0; k < 3; ++k) {
      const int a = mesh.F(f, k), b = mesh.F(f, (k + 1) % 3);
      ++edges.try_emplace(edge_key(a, b), std::array<int, 2>{0, 0}).first->second[a < b ? 0 : 1];
      faces_at[a].push_back(f);
    }
  }
  report.edges = static_cast<int>(edges.size());
  report.valence.assign(nv, 0);
  std::vector<int> parent(nv), boundary_degree(nv, 0);
  std::iota(parent.begin(), parent.end(), 0);
  for (const auto& [key, count] : edges) {
    const int a = static_cast<int>(key >> 32), b = static_cast<int>(key & 0xffffffffu);
    ++report.valence[a];
    ++report.valence[b];
    const int total = count[0] + count[1];
    if (total == 1) {
      ++report.boundary_edges;
      ++boundary_degree[a];
      ++boundary_degree[b];
      parent[find_root(parent, a)] = find_root(parent, b);
    } else if (total > 2) {
      ++report.nonmanifold_edges;
    } else if (count[0] != 1) {
      ++report.inconsistent_edges;
    }
  }
  for (int v = 0; v < nv; ++v) {
    if (boundary_degree[v] > 0 && find_root(parent, v) == v) ++report.boundary_loops;
    if (boundary_degree[v] != 0 && boundary_degree[v] != 2) ++report.nonmanifold_vertices;
  }

  // Vertex fans: in face (v, a, b), a is followed by b around v; a manifold vertex's faces chain
  // into one cycle (interior) or one path (boundary).
  for (int v = 0; v < nv; ++v) {
    if (faces_at[v].empty()) {
      ++report.unreferenced_vertices;
      continue;
    }
    std::map<int, int> next;
    std::map<int, int> in_degree;
    bool ok = true;
    for (int f : faces_at[v]) {
      int k = 0;
      while (mesh.F(f, k) != v) ++k;
      const int a = mesh.F(f, (k + 1) % 3), b = mesh.F(f, (k + 2) % 3);
      ok = ok && next.emplace(a, b).second;
      ok = ok && ++in_degree[b] == 1;
    }
    if (ok) {
      int start = next.begin()->first;
      for (const auto& [a, b] : next) {
        if (!in_degree.count(a)) start = a;  // a path starts where nothing leads in
      }
      size_t walked = 0;
      for (auto it = next.find(start); it != next.end() && walked <= next.size(); it = next.find(it->second)) {
        ++walked;
        if (it->second == start) break;
      }
      ok = walked == next.size();
    }
    report.nonmanifold_vertices += !ok;
  }

  for (int f = 0; f < nf; ++f) {
    const Eigen::Vector3d p[3] = {mesh.V.row(mesh.F(f, 0)), mesh.V.row(mesh.F(f, 1)), mesh.V.row(mesh.F(f, 2))};
    const Eigen::Vector3d area = 0.5 * (p[1] - p[0]).cross(p[2] - p[0]);
    report.area_vector += area;
    report.min_area = std::min(report.min_area, area.norm());
    report.signed_volume += p[0].dot(p[1].cross(p[2])) / 6;
    for (int k = 0; k < 3; ++k) {
      const Eigen::Vector3d u = p[(k + 1) % 3] - p[k], w = p[(k + 2) % 3] - p[k];
      const double angle = std::atan2(u.cross(w).norm(), u.dot(w)) * 180 / kPi;
      report.min_angle_degrees = std::min(report.min_angle_degrees, angle);
    }
  }
  const double diagonal = (mesh.V.colwise().maxCoeff() - mesh.V.colwise().minCoeff()).norm();
  report.duplicate_vertices = count_close_pairs(mesh.V, 1e-9 * diagonal);
  return report;
}

// Properties shared by every generated mesh.
void expect_well_formed(const MeshReport& r, double min_angle_degrees) {
  EXPECT_EQ(r.bad_faces, 0);
  EXPECT_EQ(r.nonmanifold_edges, 0);
  EXPECT_EQ(r.nonmanifold_vertices, 0);
  EXPECT_EQ(r.inconsistent_edges, 0);
  EXPECT_EQ(r.unreferenced_vertices, 0);
  EXPECT_EQ(r.duplicate_vertices, 0);
  EXPECT_GT(r.min_area, 0);
  EXPECT_GE(r.min_angle_degrees, min_angle_degrees);
}

MeshReport expect_closed(const Mesh& mesh, int euler_characteristic, double min_angle_degrees) {
  const MeshReport r = analyse(mesh);
  expect_well_formed(r, min_angle_degrees);
  EXPECT_EQ(r.boundary_edges, 0);
  EXPECT_EQ(r.boundary_loops, 0);
  EXPECT_EQ(2 * r.edges, 3 * r.faces);  // every edge has exactly two faces
  EXPECT_EQ(r.euler_characteristic(), euler_characteristic);
  EXPECT_GT(r.signed_volume, 0) << "faces must point outward";
  return r;
}

MeshReport expect_flat(const Mesh& mesh, int euler_characteristic, int boundary_loops, int boundary_edges, double min_angle_degrees) {
  const MeshReport r = analyse(mesh);
  expect_well_formed(r, min_angle_degrees);
  EXPECT_EQ(r.boundary_edges, boundary_edges);
  EXPECT_EQ(r.boundary_loops, boundary_loops);
  EXPECT_EQ(2 * r.edges - r.boundary_edges, 3 * r.faces);  // interior edges have two faces, boundary one
  EXPECT_EQ(r.euler_characteristic(), euler_characteristic);
  EXPECT_EQ(mesh.V.col(2).cwiseAbs().maxCoeff(), 0.0) << "flat meshes lie in z = 0";
  for (int f = 0; f < mesh.F.rows(); ++f) {
    const Eigen::Vector3d a = mesh.V.row(mesh.F(f, 0)), b = mesh.V.row(mesh.F(f, 1)), c = mesh.V.row(mesh.F(f, 2));
    const double signed_area = 0.5 * ((b - a).cross(c - a)).z();
    if (signed_area <= 0) {
      ADD_FAILURE() << "face " << f << " is not counter-clockwise (signed area " << signed_area << ")";
      break;
    }
  }
  return r;
}

// For meshes of a convex body around the origin: each face's normal points away from the origin.
void expect_faces_point_away_from_origin(const Mesh& mesh) {
  for (int f = 0; f < mesh.F.rows(); ++f) {
    const Eigen::Vector3d a = mesh.V.row(mesh.F(f, 0)), b = mesh.V.row(mesh.F(f, 1)), c = mesh.V.row(mesh.F(f, 2));
    if ((b - a).cross(c - a).dot(a + b + c) <= 0) {
      ADD_FAILURE() << "face " << f << " points inward";
      return;
    }
  }
}

void expect_on_unit_sphere(const Mesh& mesh) {
  EXPECT_NEAR(mesh.V.rowwise().norm().minCoeff(), 1.0, 1e-12);
  EXPECT_NEAR(mesh.V.rowwise().norm().maxCoeff(), 1.0, 1e-12);
}

void expect_same(const Mesh& a, const Mesh& b) {
  EXPECT_TRUE(a.V == b.V);
  EXPECT_TRUE(a.F == b.F);
}

// Runs `make`, expects trivcon::Error, and checks its message mentions every one of `words`.
void expect_error(const std::function<void()>& make, const std::vector<std::string>& words) {
  try {
    make();
    ADD_FAILURE() << "no trivcon::Error thrown";
  } catch (const Error& error) {
    for (const std::string& word : words) {
      EXPECT_NE(std::string(error.what()).find(word), std::string::npos) << "message \"" << error.what() << "\" lacks \"" << word << "\"";
    }
  }
}

// ---------------------------------------------------------------------------------------- spheres

TEST(Icosphere, CountsTopologyAndGeometry) {
  for (int level = 0; level <= 4; ++level) {
    SCOPED_TRACE("level " + std::to_string(level));
    const Mesh mesh = make_icosphere(level);
    const int power = 1 << (2 * level);
    EXPECT_EQ(mesh.V.rows(), 10 * power + 2);
    EXPECT_EQ(mesh.F.rows(), 20 * power);
    const MeshReport r = expect_closed(mesh, 2, 50);
    expect_on_unit_sphere(mesh);
    expect_faces_point_away_from_origin(mesh);
    EXPECT_EQ(std::count(r.valence.begin(), r.valence.end(), 5), 12);  // only the icosahedron's corners
    EXPECT_EQ(std::count(r.valence.begin(), r.valence.end(), 6), mesh.V.rows() - 12);
  }
}

TEST(Icosphere, CoarserLevelIsPrefixOfFiner) {
  const Mesh coarse = make_icosphere(2), fine = make_icosphere(3);
  EXPECT_TRUE(fine.V.topRows(coarse.V.rows()) == coarse.V);
}

TEST(UvSphere, CountsTopologyAndGeometry) {
  for (auto [rings, segments] : {std::pair{2, 3}, {3, 4}, {8, 16}, {17, 9}}) {
    SCOPED_TRACE("rings " + std::to_string(rings) + " segments " + std::to_string(segments));
    const Mesh mesh = make_uv_sphere(rings, segments);
    EXPECT_EQ(mesh.V.rows(), 2 + segments * (rings - 1));
    EXPECT_EQ(mesh.F.rows(), 2 * segments * (rings - 1));
    const MeshReport r = expect_closed(mesh, 2, 5);
    expect_on_unit_sphere(mesh);
    expect_faces_point_away_from_origin(mesh);
    EXPECT_EQ(r.valence.front(), segments);  // poles
    EXPECT_EQ(r.valence.back(), segments);
    EXPECT_EQ(mesh.V.row(0), Eigen::RowVector3d(0, 0, 1));
  }
}

TEST(CubeSphere, CountsTopologyAndCornerValence) {
  for (int n : {1, 2, 3, 4, 7}) {
    for (bool spherical : {false, true}) {
      SCOPED_TRACE("n " + std::to_string(n) + (spherical ? " spherical" : " cube"));
      const Mesh mesh = make_cube_sphere(n, spherical);
      EXPECT_EQ(mesh.V.rows(), 6 * n * n + 2);
      EXPECT_EQ(mesh.F.rows(), 12 * n * n);
      const MeshReport r = expect_closed(mesh, 2, spherical ? 20 : 45 - 1e-9);
      expect_faces_point_away_from_origin(mesh);
      if (spherical) {
        expect_on_unit_sphere(mesh);
      } else {
        EXPECT_DOUBLE_EQ(mesh.V.cwiseAbs().rowwise().maxCoeff().minCoeff(), 1.0);  // on the cube's surface
        EXPECT_DOUBLE_EQ(mesh.V.cwiseAbs().maxCoeff(), 1.0);
        EXPECT_NEAR(r.signed_volume, 8.0, 1e-12);
      }
      if (n < 2) continue;  // one cell per face cannot avoid the corners with both diagonals
      std::vector<int> valence3;
      for (int v = 0; v < mesh.V.rows(); ++v) {
        if (r.valence[v] == 3) valence3.push_back(v);
      }
      ASSERT_EQ(valence3.size(), 8u);
      for (int v : valence3) {
        const Eigen::Vector3d corner = mesh.V.row(v).array().sign();  // the cube corner in this octant
        EXPECT_NEAR((mesh.V.row(v).transpose() - (spherical ? corner.normalized() : corner)).norm(), 0, 1e-12);
      }
    }
  }
}

TEST(CubeSphere, EvenResolutionHasMirrorSymmetry) {
  // With the diamond split, mirroring x → −x maps the face set onto itself (orientation reversed).
  const Mesh mesh = make_cube_sphere(4, true);
  std::map<std::array<long, 3>, int> vertex_at;
  auto rounded = [](const Eigen::Vector3d& p) {
    return std::array<long, 3>{std::lround(p.x() * 1e9), std::lround(p.y() * 1e9), std::lround(p.z() * 1e9)};
  };
  for (int v = 0; v < mesh.V.rows(); ++v) vertex_at[rounded(mesh.V.row(v))] = v;
  std::set<std::array<int, 3>> faces;
  auto sorted = [](std::array<int, 3> f) {
    std::sort(f.begin(), f.end());
    return f;
  };
  for (int f = 0; f < mesh.F.rows(); ++f) faces.insert(sorted({mesh.F(f, 0), mesh.F(f, 1), mesh.F(f, 2)}));
  for (int f = 0; f < mesh.F.rows(); ++f) {
    std::array<int, 3> mirrored;
    for (int k = 0; k < 3; ++k) {
      Eigen::Vector3d p = mesh.V.row(mesh.F(f, k));
      p.x() = -p.x();
      auto it = vertex_at.find(rounded(p));
      ASSERT_NE(it, vertex_at.end());
      mirrored[k] = it->second;
    }
    EXPECT_TRUE(faces.count(sorted(mirrored))) << "face " << f;
  }
}

// ------------------------------------------------------------------------------- torus and genus g

TEST(Torus, CountsTopologyAndGeometry) {
  for (auto [nu, nv] : {std::pair{3, 3}, {12, 8}, {40, 17}}) {
    SCOPED_TRACE("nu " + std::to_string(nu) + " nv " + std::to_string(nv));
    const double R = 1.5, r = 0.5;
    const Mesh mesh = make_torus(nu, nv, R, r);
    EXPECT_EQ(mesh.V.rows(), nu * nv);
    EXPECT_EQ(mesh.F.rows(), 2 * nu * nv);
    expect_closed(mesh, 0, 10);
    // On the torus surface, and every face agrees with the outward normals of the torus at its
    // corners (p minus the nearest point of the core circle).
    auto outward = [R](const Eigen::Vector3d& p) {
      Eigen::Vector3d core(p.x(), p.y(), 0);
      return Eigen::Vector3d(p - core * (R / core.norm()));
    };
    for (int v = 0; v < mesh.V.rows(); ++v) EXPECT_NEAR(outward(mesh.V.row(v)).norm(), r, 1e-12);
    for (int f = 0; f < mesh.F.rows(); ++f) {
      const Eigen::Vector3d a = mesh.V.row(mesh.F(f, 0)), b = mesh.V.row(mesh.F(f, 1)), c = mesh.V.row(mesh.F(f, 2));
      const Eigen::Vector3d normal = (b - a).cross(c - a);
      for (const Eigen::Vector3d& p : {a, b, c}) EXPECT_GT(normal.dot(outward(p)), 0) << "face " << f;
    }
  }
}

TEST(Torus, DefaultRadii) {
  const Mesh mesh = make_torus(16, 8);
  EXPECT_NEAR(mesh.V.rowwise().norm().maxCoeff(), 1.4, 1e-12);
  EXPECT_NEAR(mesh.V.col(2).maxCoeff(), 0.4 * std::sin(2 * kPi * 2 / 8), 1e-12);
}

TEST(GenusSurface, CountsTopologyAndVolume) {
  for (int g : {0, 1, 2, 3, 5}) {
    for (int resolution : {1, 2, 3}) {
      SCOPED_TRACE("g " + std::to_string(g) + " resolution " + std::to_string(resolution));
      const Mesh mesh = make_genus_surface(g, resolution);
      const int voxel_faces = 72 * g + 56;
      EXPECT_EQ(mesh.F.rows(), 2 * resolution * resolution * voxel_faces);
      EXPECT_EQ(mesh.V.rows(), 2 - 2 * g + resolution * resolution * voxel_faces);
      const MeshReport r = expect_closed(mesh, 2 - 2 * g, 45 - 1e-9);
      EXPECT_NEAR(r.signed_volume, 2.0 * (20 * g + 12) / 27, 1e-12);
      // Centred at the origin, voxel edge 1/3.
      const Eigen::RowVector3d extent((2 * g + 1) / 3.0, 1.0, 1.0 / 3);  // half of (4g+2, 6, 2)/3
      EXPECT_NEAR((mesh.V.colwise().maxCoeff() - extent).norm(), 0, 1e-12);
      EXPECT_NEAR((mesh.V.colwise().minCoeff() + extent).norm(), 0, 1e-12);
    }
  }
}

// ---------------------------------------------------------------------------------- flat meshes

TEST(Disk, CountsTopologyAndBoundary) {
  for (auto [rings, segments] : {std::pair{1, 3}, {1, 8}, {2, 6}, {5, 6}, {9, 7}}) {
    SCOPED_TRACE("rings " + std::to_string(rings) + " segments " + std::to_string(segments));
    const Mesh mesh = make_disk(rings, segments);
    EXPECT_EQ(mesh.V.rows(), 1 + segments * rings * (rings + 1) / 2);
    EXPECT_EQ(mesh.F.rows(), segments * rings * rings);
    const MeshReport r = expect_flat(mesh, 1, 1, rings * segments, 25);
    // Exactly the regular polygon on the outer ring.
    const int outer = rings * segments;
    EXPECT_NEAR(r.area_vector.z(), outer / 2.0 * std::sin(2 * kPi / outer), 1e-12);
    EXPECT_EQ(mesh.V.row(0), Eigen::RowVector3d::Zero());
    EXPECT_NEAR(mesh.V.rowwise().norm().maxCoeff(), 1.0, 1e-12);
  }
}

TEST(Annulus, CountsTopologyAndBoundary) {
  for (auto [rings, segments] : {std::pair{1, 3}, {2, 12}, {6, 40}}) {
    SCOPED_TRACE("rings " + std::to_string(rings) + " segments " + std::to_string(segments));
    const Mesh mesh = make_annulus(rings, segments, 0.25, 2.0);
    EXPECT_EQ(mesh.V.rows(), (rings + 1) * segments);
    EXPECT_EQ(mesh.F.rows(), 2 * rings * segments);
    const MeshReport r = expect_flat(mesh, 0, 2, 2 * segments, 3);
    EXPECT_GT(r.area_vector.z(), 0);
    EXPECT_NEAR(mesh.V.rowwise().norm().minCoeff(), 0.25, 1e-12);
    EXPECT_NEAR(mesh.V.rowwise().norm().maxCoeff(), 2.0, 1e-12);
  }
  const Mesh defaults = make_annulus(3, 16);
  EXPECT_NEAR(defaults.V.rowwise().norm().minCoeff(), 0.5, 1e-12);
  EXPECT_NEAR(defaults.V.rowwise().norm().maxCoeff(), 1.0, 1e-12);
}

TEST(HoledGrid, CountsTopologyAndBoundary) {
  for (auto [n, holes] : {std::pair{1, 0}, {4, 0}, {3, 1}, {7, 1}, {5, 2}, {12, 2}, {20, 3}, {31, 4}}) {
    SCOPED_TRACE("n " + std::to_string(n) + " holes " + std::to_string(holes));
    const Mesh mesh = make_holed_grid(n, holes);
    const int w = n / (2 * holes + 1);
    EXPECT_EQ(mesh.V.rows(), (n + 1) * (n + 1) - holes * (w - 1) * (w - 1));
    EXPECT_EQ(mesh.F.rows(), 2 * (n * n - holes * w * w));
    const MeshReport r = expect_flat(mesh, 1 - holes, 1 + holes, 4 * n + 4 * w * holes, 45 - 1e-9);
    EXPECT_NEAR(r.area_vector.z(), 1.0 - holes * double(w * w) / (n * n), 1e-12);
    EXPECT_EQ(mesh.V.leftCols(2).minCoeff(), 0.0);
    EXPECT_EQ(mesh.V.leftCols(2).maxCoeff(), 1.0);
  }
}

// --------------------------------------------------------------------------- mesh operations

TEST(Concatenate, StacksVerticesAndShiftsIds) {
  const Mesh a = make_icosphere(1), b = make_torus(6, 5), c = make_disk(2, 4);
  const Mesh all = concatenate({a, b, c});
  ASSERT_EQ(all.V.rows(), a.V.rows() + b.V.rows() + c.V.rows());
  ASSERT_EQ(all.F.rows(), a.F.rows() + b.F.rows() + c.F.rows());
  EXPECT_TRUE(all.V.topRows(a.V.rows()) == a.V);
  EXPECT_TRUE(all.V.middleRows(a.V.rows(), b.V.rows()) == b.V);
  EXPECT_TRUE(all.V.bottomRows(c.V.rows()) == c.V);
  EXPECT_TRUE(all.F.topRows(a.F.rows()) == a.F);
  EXPECT_TRUE((all.F.middleRows(a.F.rows(), b.F.rows()).array() - int(a.V.rows())).matrix() == b.F);
  EXPECT_TRUE((all.F.bottomRows(c.F.rows()).array() - int(a.V.rows() + b.V.rows())).matrix() == c.F);
  const MeshReport r = analyse(all);
  EXPECT_EQ(r.euler_characteristic(), 2 + 0 + 1);
  EXPECT_EQ(r.boundary_loops, 1);
  EXPECT_EQ(r.nonmanifold_vertices, 0);

  const Mesh empty = concatenate({});
  EXPECT_EQ(empty.V.rows(), 0);
  EXPECT_EQ(empty.F.rows(), 0);
}

TEST(SubdivideMidpoint, QuadruplesFacesAndKeepsTopology) {
  struct Case {
    std::string name;
    Mesh mesh;
    int euler_characteristic;
    bool closed;
  };
  const std::vector<Case> cases = {{"icosphere", make_icosphere(1), 2, true},
                                   {"torus", make_torus(7, 5), 0, true},
                                   {"genus 2", make_genus_surface(2, 1), -2, true},
                                   {"holed grid", make_holed_grid(7, 2), -1, false},
                                   {"disk", make_disk(3, 5), 1, false}};
  for (const Case& c : cases) {
    SCOPED_TRACE(c.name);
    const MeshReport before = analyse(c.mesh);
    const Mesh fine = subdivide_midpoint(c.mesh);
    ASSERT_EQ(fine.F.rows(), 4 * c.mesh.F.rows());
    ASSERT_EQ(fine.V.rows(), c.mesh.V.rows() + before.edges);  // one new vertex per edge
    EXPECT_TRUE(fine.V.topRows(c.mesh.V.rows()) == c.mesh.V);
    const MeshReport after = analyse(fine);
    expect_well_formed(after, 0.5 * before.min_angle_degrees);  // midpoint subdivision keeps angles
    EXPECT_NEAR(after.min_angle_degrees, before.min_angle_degrees, 1e-9);
    EXPECT_EQ(after.euler_characteristic(), c.euler_characteristic);
    EXPECT_EQ(after.boundary_edges, 2 * before.boundary_edges);
    EXPECT_EQ(after.boundary_loops, before.boundary_loops);
    EXPECT_NEAR(after.signed_volume, before.signed_volume, 1e-12);  // same surface, flat pieces
    EXPECT_NEAR((after.area_vector - before.area_vector).norm(), 0, 1e-12);
    // The corner children carry the parent's corners in the parent's order.
    for (int f = 0; f < c.mesh.F.rows(); ++f) {
      EXPECT_EQ(fine.F(4 * f, 0), c.mesh.F(f, 0));
      EXPECT_EQ(fine.F(4 * f + 1, 1), c.mesh.F(f, 1));
      EXPECT_EQ(fine.F(4 * f + 2, 2), c.mesh.F(f, 2));
      const Eigen::RowVector3d midpoint = 0.5 * (c.mesh.V.row(c.mesh.F(f, 0)) + c.mesh.V.row(c.mesh.F(f, 1)));
      EXPECT_EQ(fine.V.row(fine.F(4 * f, 1)), midpoint);
    }
  }
}

TEST(SubdivideMidpoint, HandlesHighValenceAndRejectsBadIndices) {
  // A fan of 500 triangles around vertex 0: one large edge bucket.
  const Mesh disk = make_disk(1, 500);
  const Mesh fine = subdivide_midpoint(disk);
  expect_flat(fine, 1, 1, 1000, 0.3);
  Mesh bad = disk;
  bad.F(7, 2) = static_cast<int>(bad.V.rows());
  expect_error([&] { subdivide_midpoint(bad); }, {"subdivide_midpoint", "face 7", "out of range"});
}

// Faces with one, two and three split edges: the same surface and orientation, each new vertex the midpoint of its
// edge, each face's children in it, ids as documented.
TEST(SplitEdgesAtMidpoints, KeepsTheSurfaceAndNumbersAsDocumented) {
  const Mesh m = make_icosphere(1);
  const MeshReport before = analyse(m);
  // Face 0's three edges, face 1's edges not shared with face 0, and one more edge elsewhere (given reversed).
  std::vector<std::pair<int, int>> edges;
  for (int k = 0; k < 3; ++k) edges.emplace_back(m.F(0, k), m.F(0, (k + 1) % 3));
  edges.emplace_back(m.F(1, 0), m.F(1, 1));
  edges.emplace_back(m.F(30, 2), m.F(30, 1));
  edges.emplace_back(m.F(0, 1), m.F(0, 0));  // a duplicate
  std::vector<int> parent;
  const Mesh fine = split_edges_at_midpoints(m, edges, &parent);
  std::set<std::pair<int, int>> unique;
  for (auto [i, j] : edges) unique.emplace(std::min(i, j), std::max(i, j));
  ASSERT_EQ(fine.V.rows(), m.V.rows() + static_cast<Eigen::Index>(unique.size()));
  EXPECT_TRUE(fine.V.topRows(m.V.rows()) == m.V);
  int k = 0;
  for (auto [i, j] : unique) {  // the k-th edge in increasing order has vertex V + k at its midpoint
    EXPECT_EQ(fine.V.row(m.V.rows() + k), (0.5 * (m.V.row(i) + m.V.row(j))).eval());
    ++k;
  }
  // Every face with s split edges gains s faces.
  int gained = 0;
  for (int f = 0; f < m.F.rows(); ++f)
    for (int c = 0; c < 3; ++c) gained += unique.count({std::min(m.F(f, c), m.F(f, (c + 1) % 3)), std::max(m.F(f, c), m.F(f, (c + 1) % 3))}) > 0;
  ASSERT_EQ(fine.F.rows(), m.F.rows() + gained);
  const MeshReport after = analyse(fine);
  expect_well_formed(after, 1);
  EXPECT_EQ(after.euler_characteristic(), 2);
  EXPECT_NEAR(after.signed_volume, before.signed_volume, 1e-12);
  EXPECT_NEAR((after.area_vector - before.area_vector).norm(), 0, 1e-12);
  // Each child lies in its parent's plane, with the same orientation, and the children's areas sum to the parent's.
  ASSERT_EQ(parent.size(), static_cast<size_t>(fine.F.rows()));
  std::vector<Eigen::Vector3d> area(m.F.rows(), Eigen::Vector3d::Zero());
  for (int f = 0; f < fine.F.rows(); ++f) {
    ASSERT_TRUE(f < m.F.rows() ? parent[f] == f : parent[f] >= 0 && parent[f] < m.F.rows()) << f;
    const Eigen::Vector3d a = fine.V.row(fine.F(f, 0)), b = fine.V.row(fine.F(f, 1)), c = fine.V.row(fine.F(f, 2));
    area[parent[f]] += 0.5 * (b - a).cross(c - a);
  }
  for (int f = 0; f < m.F.rows(); ++f) {
    const Eigen::Vector3d a = m.V.row(m.F(f, 0)), b = m.V.row(m.F(f, 1)), c = m.V.row(m.F(f, 2));
    EXPECT_NEAR((area[f] - 0.5 * (b - a).cross(c - a)).norm(), 0, 1e-12) << f;
  }
  EXPECT_TRUE(split_edges_at_midpoints(m, {}).F == m.F);
  expect_error([&] { split_edges_at_midpoints(m, {{0, 0}}); }, {"split_edges_at_midpoints", "(0, 0)", "not an edge"});
  expect_error([&] { split_edges_at_midpoints(m, {{0, 1000}}); }, {"split_edges_at_midpoints", "(0, 1000)", "not an edge"});
  int far = 1;
  while (unique.count({0, far}) || std::any_of(m.F.rowwise().begin(), m.F.rowwise().end(), [&](const auto& row) {
           return (row.array() == 0).any() && (row.array() == far).any();
         }))
    ++far;
  expect_error([&] { split_edges_at_midpoints(m, {{0, far}}); },
               {"split_edges_at_midpoints", "(0, " + std::to_string(far) + ")", "is not an edge of a face"});
}

TEST(Permute, MapsVerticesAndFacesAndKeepsOrientation) {
  const Mesh mesh = make_genus_surface(1, 2);
  std::vector<int> vertex_perm, face_perm;
  const Mesh shuffled = permute(mesh, 12345, &vertex_perm, &face_perm);
  ASSERT_EQ(shuffled.V.rows(), mesh.V.rows());
  ASSERT_EQ(shuffled.F.rows(), mesh.F.rows());
  // Both maps are permutations.
  for (const std::vector<int>* perm : {&vertex_perm, &face_perm}) {
    std::vector<int> sorted = *perm;
    std::sort(sorted.begin(), sorted.end());
    std::vector<int> identity(sorted.size());
    std::iota(identity.begin(), identity.end(), 0);
    EXPECT_EQ(sorted, identity);
  }
  for (int v = 0; v < mesh.V.rows(); ++v) EXPECT_EQ(shuffled.V.row(vertex_perm[v]), mesh.V.row(v));
  // Each face moved to face_perm[f], its vertices renamed, its corners rotated cyclically only.
  int rotated = 0;
  for (int f = 0; f < mesh.F.rows(); ++f) {
    const int g = face_perm[f];
    const int a = vertex_perm[mesh.F(f, 0)], b = vertex_perm[mesh.F(f, 1)], c = vertex_perm[mesh.F(f, 2)];
    int k = 0;
    while (k < 3 && shuffled.F(g, k) != a) ++k;
    ASSERT_LT(k, 3) << "face " << f;
    EXPECT_EQ(shuffled.F(g, (k + 1) % 3), b) << "face " << f;
    EXPECT_EQ(shuffled.F(g, (k + 2) % 3), c) << "face " << f;
    rotated += k != 0;
  }
  EXPECT_GT(rotated, mesh.F.rows() / 3);  // rotations actually happen (expected 2/3)
  EXPECT_GT(std::count_if(vertex_perm.begin(), vertex_perm.end(), [n = 0](int p) mutable { return p != n++; }), mesh.V.rows() / 2);
  // Still a valid outward genus-1 surface.
  const MeshReport r = expect_closed(shuffled, 0, 45 - 1e-9);
  EXPECT_NEAR(r.signed_volume, analyse(mesh).signed_volume, 1e-12);
}

TEST(Permute, DeterministicPerSeed) {
  const Mesh mesh = make_icosphere(2);
  expect_same(permute(mesh, 7), permute(mesh, 7));
  const Mesh other = permute(mesh, 8);
  EXPECT_FALSE(permute(mesh, 7).F == other.F);
  const Mesh empty = permute(Mesh{}, 3);
  EXPECT_EQ(empty.F.rows(), 0);
}

TEST(Generators, AreDeterministic) {
  expect_same(make_icosphere(3), make_icosphere(3));
  expect_same(make_uv_sphere(9, 13), make_uv_sphere(9, 13));
  expect_same(make_cube_sphere(5, true), make_cube_sphere(5, true));
  expect_same(make_torus(11, 7), make_torus(11, 7));
  expect_same(make_genus_surface(3, 2), make_genus_surface(3, 2));
  expect_same(make_disk(6, 5), make_disk(6, 5));
  expect_same(make_annulus(4, 9), make_annulus(4, 9));
  expect_same(make_holed_grid(15, 3), make_holed_grid(15, 3));
  const Mesh torus = make_torus(30, 20);
  expect_same(subdivide_midpoint(torus), subdivide_midpoint(torus));
}

// ---------------------------------------------------------------------------- invalid parameters

TEST(Generators, RejectInvalidParameters) {
  expect_error([] { make_icosphere(-1); }, {"make_icosphere", "level = -1"});
  expect_error([] { make_icosphere(40); }, {"make_icosphere", "more than the supported"});
  expect_error([] { make_uv_sphere(1, 8); }, {"make_uv_sphere", "rings = 1"});
  expect_error([] { make_uv_sphere(4, 2); }, {"make_uv_sphere", "segments = 2"});
  expect_error([] { make_cube_sphere(0, true); }, {"make_cube_sphere", "n = 0"});
  expect_error([] { make_cube_sphere(100000, false); }, {"make_cube_sphere", "more than the supported"});
  expect_error([] { make_torus(2, 8); }, {"make_torus", "nu = 2"});
  expect_error([] { make_torus(8, 2); }, {"make_torus", "nv = 2"});
  expect_error([] { make_torus(8, 8, 1.0, 0.0); }, {"make_torus", "r = 0"});
  expect_error([] { make_torus(8, 8, 0.3, 0.4); }, {"make_torus", "R = 0.3"});
  expect_error([] { make_torus(8, 8, 1.0, NAN); }, {"make_torus", "r = nan"});
  expect_error([] { make_genus_surface(-1, 1); }, {"make_genus_surface", "g = -1"});
  expect_error([] { make_genus_surface(1, 0); }, {"make_genus_surface", "resolution = 0"});
  expect_error([] { make_genus_surface(1000000, 1); }, {"make_genus_surface", "too large"});
  expect_error([] { make_disk(0, 8); }, {"make_disk", "rings = 0"});
  expect_error([] { make_disk(3, 2); }, {"make_disk", "segments = 2"});
  expect_error([] { make_annulus(0, 8); }, {"make_annulus", "rings = 0"});
  expect_error([] { make_annulus(2, 2); }, {"make_annulus", "segments = 2"});
  expect_error([] { make_annulus(2, 8, 1.0, 1.0); }, {"make_annulus", "r_out = 1", "r_in = 1"});
  expect_error([] { make_annulus(2, 8, 2.0, 1.0); }, {"make_annulus", "r_out = 1", "r_in = 2"});
  expect_error([] { make_annulus(2, 8, 0.0, 1.0); }, {"make_annulus", "r_in = 0"});
  expect_error([] { make_holed_grid(0, 0); }, {"make_holed_grid", "n = 0"});
  expect_error([] { make_holed_grid(8, -1); }, {"make_holed_grid", "holes = -1"});
  expect_error([] { make_holed_grid(4, 2); }, {"make_holed_grid", "n = 4", "2 holes", "n >= 2·holes + 1 = 5"});
  Mesh bad = make_icosphere(0);
  bad.F(3, 1) = -1;
  expect_error([&] { permute(bad, 1); }, {"permute", "face 3", "out of range"});
}

}  // namespace
}  // namespace trivcon
