// SPDX-License-Identifier: MIT
// Tests of trivcon/cycles.h: the generators are 2g closed, non-contractible and independent dual cycles
// per component, the loop cycles go once around their boundary loop, and the holonomies add up.
#include "trivcon/cycles.h"

#include <gtest/gtest.h>

#include <Eigen/LU>
#include <algorithm>
#include <cmath>
#include <map>
#include <random>
#include <set>
#include <string>
#include <utility>
#include <vector>

#include "support.h"
#include "trivcon/generate.h"
#include "trivcon/geometry.h"
#include "trivcon/topology.h"

namespace trivcon {
namespace {

using test::topo;

// Meshes with handles, boundary loops, both, neither, and several components; their topology and cycles.
struct Prepared {
  std::string name;
  Topology t;
  Cycles c;
};

std::vector<Prepared> test_meshes() {
  std::vector<Prepared> out;
  for (const auto& [name, mesh] : std::vector<std::pair<std::string, Mesh>>{
           {"torus", make_torus(6, 5)},
           {"genus 2", make_genus_surface(2, 1)},
           {"genus 3", make_genus_surface(3, 1)},
           {"annulus", make_annulus(2, 8)},
           {"grid with 3 holes", make_holed_grid(9, 3)},
           {"sphere", make_icosphere(1)},
           {"five components",
            concatenate({make_torus(5, 4), make_disk(2, 5), make_genus_surface(1, 1), make_annulus(1, 6), make_holed_grid(7, 2)})}}) {
    Topology t = topo(mesh);
    Cycles c = compute_cycles(t);
    out.push_back({name, std::move(t), std::move(c)});
  }
  return out;
}

// Faces a dual cycle's k-th crossing goes from and to (sign +1: L → R).
int from_face(const Topology& t, const DualCycle& c, size_t k) { return t.edge_faces(c.edges[k], c.signs[k] > 0 ? 0 : 1); }
int to_face(const Topology& t, const DualCycle& c, size_t k) { return t.edge_faces(c.edges[k], c.signs[k] > 0 ? 1 : 0); }

// Every crossing of an interior edge of the cycle's component, signs ±1: the number of crossings that
// are not.
int bad_crossings(const Topology& t, const DualCycle& c) {
  int bad = c.edges.size() != c.signs.size();
  for (size_t k = 0; k < c.edges.size() && k < c.signs.size(); ++k) {
    const int e = c.edges[k];
    if (e < 0 || e >= t.num_edges || t.is_boundary_edge(e) || std::abs(c.signs[k]) != 1) {
      ++bad;
      continue;
    }
    bad += t.face_component[t.edge_faces(e, 0)] != c.component;
  }
  return bad;
}

// Net number of times the cycle enters each face (0 everywhere for a closed dual chain): the faces where not.
int open_faces(const Topology& t, const DualCycle& c) {
  std::map<int, int> net;
  for (size_t k = 0; k < c.edges.size(); ++k) --net[from_face(t, c, k)], ++net[to_face(t, c, k)];
  return static_cast<int>(std::count_if(net.begin(), net.end(), [](const auto& fn) { return fn.second != 0; }));
}

// Algebraic intersection number of a dual cycle with a primal vertex path (closed when `closed`): each
// shared edge counts sign × (+1 where the path runs from the edge's smaller vertex id to the larger).
int intersection(const Topology& t, const DualCycle& c, const std::vector<int>& path, bool closed) {
  std::map<std::pair<int, int>, int> along;  // (i, j), i < j → +1 / −1 per traversal
  for (size_t k = 0; k + 1 < path.size() + (closed ? 1 : 0); ++k) {
    const int a = path[k], b = path[(k + 1) % path.size()];
    along[{std::min(a, b), std::max(a, b)}] += a < b ? 1 : -1;
  }
  int sum = 0;
  for (size_t k = 0; k < c.edges.size(); ++k) {
    const auto it = along.find({t.edge_vertices(c.edges[k], 0), t.edge_vertices(c.edges[k], 1)});
    if (it != along.end()) sum += c.signs[k] * it->second;
  }
  return sum;
}

// The dual cycle of interior vertex v, as coefficients (cycles.h: +1 where v is the edge's larger id).
DualCycle vertex_cycle(const Topology& t, int v) {
  DualCycle c;
  c.component = t.vertex_component[v];
  for (int a = t.vertex_edge_offsets[v]; a < t.vertex_edge_offsets[v + 1]; ++a) {
    c.edges.push_back(t.vertex_edges[a]);
    c.signs.push_back(t.edge_vertices(t.vertex_edges[a], 1) == v ? 1 : -1);
  }
  return c;
}

TEST(Cycles, TwoGeneratorsPerHandleAndOneLoopPerBoundary) {
  for (const auto& [name, t, c] : test_meshes()) {
    SCOPED_TRACE(name);
    std::vector<int> per_component(t.components.size(), 0);
    for (size_t g = 0; g < c.generators.size(); ++g) {
      ASSERT_GE(c.generators[g].component, 0);
      ASSERT_LT(c.generators[g].component, static_cast<int>(t.components.size()));
      if (g > 0) {
        EXPECT_LE(c.generators[g - 1].component, c.generators[g].component) << "generators not grouped by component";
      }
      ++per_component[c.generators[g].component];
    }
    for (size_t k = 0; k < t.components.size(); ++k) EXPECT_EQ(per_component[k], 2 * t.components[k].genus) << "component " << k;
    ASSERT_EQ(c.loops.size(), t.boundary_loops.size());
    for (size_t l = 0; l < c.loops.size(); ++l) EXPECT_EQ(c.loops[l].component, t.vertex_component[t.boundary_loops[l][0]]) << "loop " << l;
  }
}

// A generator crosses L → R across its first edge, then walks back through faces: each crossing starts
// in the face where the previous one ended, the last ends where the first started, no edge twice.
TEST(Cycles, GeneratorsAreClosedDualWalks) {
  for (const auto& [name, t, c] : test_meshes()) {
    SCOPED_TRACE(name);
    for (size_t g = 0; g < c.generators.size(); ++g) {
      const DualCycle& cycle = c.generators[g];
      ASSERT_GE(cycle.edges.size(), 2u) << "generator " << g;
      ASSERT_EQ(bad_crossings(t, cycle), 0) << "generator " << g;
      EXPECT_EQ(cycle.signs[0], 1) << "generator " << g << " must cross its first edge from L to R";
      int breaks = 0;
      for (size_t k = 0; k < cycle.edges.size(); ++k) breaks += to_face(t, cycle, k) != from_face(t, cycle, (k + 1) % cycle.edges.size());
      EXPECT_EQ(breaks, 0) << "generator " << g << ": consecutive crossings that do not share a face";
      const std::set<int> distinct(cycle.edges.begin(), cycle.edges.end());
      EXPECT_EQ(distinct.size(), cycle.edges.size()) << "generator " << g << " repeats an edge";
    }
  }
}

// Over the rationals: the vertex cycles span the contractible dual cycles (with one dependency per
// closed component), b − 1 loop cycles per component with boundary are independent of them, and each
// generator adds one more dimension: 2g non-contractible cycles, independent in homology.
TEST(Cycles, GeneratorsAreIndependentInHomology) {
  for (const auto& [name, t, c] : test_meshes()) {
    SCOPED_TRACE(name);
    std::vector<int> column(t.num_edges, -1);
    int columns = 0;
    for (int e = 0; e < t.num_edges; ++e)
      if (!t.is_boundary_edge(e)) column[e] = columns++;
    std::vector<DualCycle> rows;
    for (int v = 0; v < t.num_vertices; ++v)
      if (t.is_interior_vertex(v)) rows.push_back(vertex_cycle(t, v));
    const size_t vertex_rows = rows.size();
    rows.insert(rows.end(), c.loops.begin(), c.loops.end());
    rows.insert(rows.end(), c.generators.begin(), c.generators.end());
    auto rank = [&](size_t count) {
      Eigen::MatrixXd A = Eigen::MatrixXd::Zero(static_cast<int>(count), columns);
      for (size_t r = 0; r < count; ++r)
        for (size_t k = 0; k < rows[r].edges.size(); ++k) {
          if (column[rows[r].edges[k]] >= 0) A(static_cast<int>(r), column[rows[r].edges[k]]) += rows[r].signs[k];
        }
      Eigen::FullPivLU<Eigen::MatrixXd> lu(A);
      lu.setThreshold(1e-9);
      return static_cast<int>(lu.rank());
    };
    int closed = 0, extra_loops = 0, handles = 0;
    for (const ComponentInfo& info : t.components) {
      closed += info.boundary_loops.empty();
      extra_loops += info.boundary_loops.empty() ? 0 : static_cast<int>(info.boundary_loops.size()) - 1;
      handles += 2 * info.genus;
    }
    const int vertex_rank = static_cast<int>(vertex_rows) - closed;
    EXPECT_EQ(rank(vertex_rows), vertex_rank);
    EXPECT_EQ(rank(vertex_rows + c.loops.size()), vertex_rank + extra_loops);
    EXPECT_EQ(rank(rows.size()), vertex_rank + extra_loops + handles);
  }
}

// On the torus, the generators against the two grid circles (longitude: j fixed; meridian: i fixed;
// make_torus's vertex i·nv + j): an intersection matrix of determinant ±1, so they are a basis of the
// integer homology, not only independent. Every vertex cycle meets both circles 0 times.
TEST(Cycles, TorusGeneratorsAreAHomologyBasisByIntersectionNumbers) {
  const int nu = 7, nv = 5;
  const Topology t = topo(make_torus(nu, nv));
  const Cycles c = compute_cycles(t);
  ASSERT_EQ(c.generators.size(), 2u);
  std::vector<int> longitude, meridian;
  for (int i = 0; i < nu; ++i) longitude.push_back(i * nv + 2);
  for (int j = 0; j < nv; ++j) meridian.push_back(3 * nv + j);
  int m[2][2];
  for (int g = 0; g < 2; ++g) {
    m[g][0] = intersection(t, c.generators[g], longitude, true);
    m[g][1] = intersection(t, c.generators[g], meridian, true);
  }
  EXPECT_EQ(std::abs(m[0][0] * m[1][1] - m[0][1] * m[1][0]), 1)
      << "intersection matrix " << m[0][0] << " " << m[0][1] << " / " << m[1][0] << " " << m[1][1];
  int nonzero = 0;
  for (int v = 0; v < t.num_vertices; ++v)
    nonzero += intersection(t, vertex_cycle(t, v), longitude, true) != 0 || intersection(t, vertex_cycle(t, v), meridian, true) != 0;
  EXPECT_EQ(nonzero, 0);
}

// Shortest vertex path from loop `from` to loop `to` whose inner vertices are interior.
std::vector<int> path_between_loops(const Topology& t, int from, int to) {
  std::vector<int> previous(t.num_vertices, -2), queue;
  for (int v : t.boundary_loops[from]) previous[v] = -1, queue.push_back(v);
  for (size_t q = 0; q < queue.size(); ++q) {
    const int v = queue[q];
    if (t.vertex_boundary_loop[v] == to) {
      std::vector<int> path;
      for (int u = v; u >= 0; u = previous[u]) path.push_back(u);
      std::reverse(path.begin(), path.end());
      return path;
    }
    if (q > 0 && t.is_boundary_vertex(v) && t.vertex_boundary_loop[v] == from) continue;  // only the sources start on `from`
    for (int a = t.vertex_edge_offsets[v]; a < t.vertex_edge_offsets[v + 1]; ++a) {
      const int e = t.vertex_edges[a], u = t.edge_vertices(e, 0) == v ? t.edge_vertices(e, 1) : t.edge_vertices(e, 0);
      if (previous[u] != -2 || t.is_boundary_edge(e)) continue;
      if (t.is_boundary_vertex(u) && t.vertex_boundary_loop[u] != to) continue;
      previous[u] = v;
      queue.push_back(u);
    }
  }
  return {};
}

// Loop cycle ℓ is the sum of its loop's vertex cycles on interior edges: closed, made of the interior
// edges with exactly one end on the loop; and it goes once around its hole: a path from loop a to loop b
// crosses loop cycle a once leaving it (−1, as a path leaving any vertex crosses its vertex cycle) and
// loop cycle b once arriving (+1), and no other loop cycle.
TEST(Cycles, LoopCyclesGoOnceAroundTheirBoundaryLoop) {
  for (const auto& [name, t, c] : test_meshes()) {
    SCOPED_TRACE(name);
    for (size_t l = 0; l < c.loops.size(); ++l) {
      const DualCycle& loop = c.loops[l];
      ASSERT_EQ(bad_crossings(t, loop), 0) << "loop " << l;
      EXPECT_EQ(open_faces(t, loop), 0) << "loop cycle " << l << " is not closed";
      std::map<int, int> expected;  // edge → sign
      for (int e = 0; e < t.num_edges; ++e) {
        if (t.is_boundary_edge(e)) continue;
        const bool on_i = t.vertex_boundary_loop[t.edge_vertices(e, 0)] == static_cast<int>(l);
        const bool on_j = t.vertex_boundary_loop[t.edge_vertices(e, 1)] == static_cast<int>(l);
        if (on_i != on_j) expected[e] = on_j ? 1 : -1;
      }
      std::map<int, int> got;
      for (size_t k = 0; k < loop.edges.size(); ++k) got[loop.edges[k]] += loop.signs[k];
      EXPECT_EQ(got, expected) << "loop " << l;
    }
    for (const ComponentInfo& info : t.components) {
      for (int a : info.boundary_loops)
        for (int b : info.boundary_loops) {
          if (a == b) continue;
          const std::vector<int> path = path_between_loops(t, a, b);
          ASSERT_GE(path.size(), 2u) << "no path from loop " << a << " to loop " << b;
          for (size_t l = 0; l < c.loops.size(); ++l) {
            const int want = static_cast<int>(l) == a ? -1 : static_cast<int>(l) == b ? 1 : 0;
            EXPECT_EQ(intersection(t, c.loops[l], path, false), want) << "path from loop " << a << " to loop " << b << ", loop cycle " << l;
          }
        }
    }
  }
}

// loop_curvature: 2π around a flat disk, ±2π on the outer and inner circles of a flat annulus, and with
// the interior angle defects 2π χ per component; the Levi-Civita holonomy of a loop cycle is its
// curvature modulo 2π, also on curved surfaces.
TEST(Cycles, LoopCurvatureAndHolonomy) {
  auto loop_curvatures = [](const Mesh& m) {
    const Topology t = topo(m);
    const Geometry g = compute_geometry(m.V, t);
    std::vector<double> k;
    for (size_t l = 0; l < t.boundary_loops.size(); ++l) k.push_back(loop_curvature(t, g, static_cast<int>(l)));
    return k;
  };
  const std::vector<double> disk = loop_curvatures(make_disk(4, 6));
  ASSERT_EQ(disk.size(), 1u);
  EXPECT_NEAR(disk[0], kTwoPi, 1e-9);
  const Mesh annulus = make_annulus(3, 12);
  const std::vector<double> ring = loop_curvatures(annulus);
  ASSERT_EQ(ring.size(), 2u);
  const Topology ta = topo(annulus);
  const int outer = annulus.V.row(ta.boundary_loops[0][0]).norm() > 0.75 ? 0 : 1;  // radii 0.5 and 1
  EXPECT_NEAR(ring[outer], kTwoPi, 1e-9);
  EXPECT_NEAR(ring[1 - outer], -kTwoPi, 1e-9);

  std::mt19937 rng(9);
  std::uniform_real_distribution<double> jitter(-0.05, 0.05);
  for (Mesh m : {make_disk(4, 6), make_annulus(3, 12), make_holed_grid(9, 3),
                 concatenate({make_holed_grid(7, 2), make_torus(5, 4), make_annulus(2, 7)})}) {
    for (int v = 0; v < m.V.rows(); ++v)
      for (int k = 0; k < 3; ++k) m.V(v, k) += jitter(rng);  // curved, with boundary
    const Topology t = topo(m);
    const Geometry g = compute_geometry(m.V, t);
    const Cycles c = compute_cycles(t);
    std::vector<double> total(t.components.size(), 0.0);
    for (int v = 0; v < t.num_vertices; ++v)
      if (t.is_interior_vertex(v)) total[t.vertex_component[v]] += g.angle_defect(v);
    for (size_t l = 0; l < c.loops.size(); ++l) {
      const double k = loop_curvature(t, g, static_cast<int>(l));
      total[c.loops[l].component] += k;
      EXPECT_NEAR(wrap_angle(levi_civita_holonomy(c.loops[l], g) - k), 0.0, 1e-9) << "loop " << l;
    }
    for (size_t k = 0; k < t.components.size(); ++k) EXPECT_NEAR(total[k], kTwoPi * t.components[k].euler_characteristic, 1e-9);
  }
}

TEST(Cycles, HolonomyIsTheSignedSumOfRho) {
  const Mesh m = make_genus_surface(2, 1);
  const Topology t = topo(m);
  Geometry g = compute_geometry(m.V, t);
  std::mt19937 rng(2);
  std::uniform_real_distribution<double> any(-kPi, kPi);
  for (int e = 0; e < t.num_edges; ++e) g.rho(e) = any(rng);
  for (const DualCycle& c : compute_cycles(t).generators) {
    double sum = 0;
    for (size_t k = 0; k < c.edges.size(); ++k) sum += c.signs[k] * g.rho(c.edges[k]);
    EXPECT_NEAR(levi_civita_holonomy(c, g), sum, 1e-12);
  }
}

}  // namespace
}  // namespace trivcon
