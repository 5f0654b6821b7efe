// SPDX-License-Identifier: MIT
// Independent checks of the formulation (docs/explanation/conventions.md, docs/explanation/weights.md): every expected value
// here is computed in the test from the vertex positions alone, by hand or with the few lines of geometry
// below (cotangents, corner angles, polar angles in the plane), never with the library's weight, angle,
// frame or index functions. The library is only asked for its results (weights, x, energy, the field).
#include <gtest/gtest.h>

#include <Eigen/Geometry>
#include <algorithm>
#include <cmath>
#include <fstream>
#include <map>
#include <random>
#include <set>
#include <sstream>
#include <string>
#include <utility>
#include <vector>

#include "support.h"
#include "trivcon/constraints.h"
#include "trivcon/design.h"
#include "trivcon/field_io.h"
#include "trivcon/generate.h"
#include "trivcon/io.h"

namespace trivcon {
namespace {

using Edge = std::pair<int, int>;  // (i, j), i < j
using test::vertices_of_valence;
Edge edge_of(int a, int b) { return {std::min(a, b), std::max(a, b)}; }

Eigen::Vector3d pos(const MatrixX3d& V, int v) { return V.row(v).transpose(); }

// ---------------------------------------------------------------------------------------------
// The test's own geometry.

// Cotangent of the angle at `apex` of the triangle (apex, a, b).
double cot_at(const Eigen::Vector3d& apex, const Eigen::Vector3d& a, const Eigen::Vector3d& b) {
  const Eigen::Vector3d u = a - apex, w = b - apex;
  return u.dot(w) / u.cross(w).norm();
}
// Angle at `apex` of the triangle (apex, a, b), in [0, π].
double angle_at(const Eigen::Vector3d& apex, const Eigen::Vector3d& a, const Eigen::Vector3d& b) {
  const Eigen::Vector3d u = a - apex, w = b - apex;
  return std::atan2(u.cross(w).norm(), u.dot(w));
}
struct EdgeData {
  int faces = 0;
  double weight = 0;   // ½ Σ max(cot, 0)
  double cot_sum = 0;  // Σ cot (unclamped), for counting negative-cotangent edges
};

// Cotangent of the angle opposite side `a` of a triangle with sides a, b, c, by the law of cosines
// (a different route from the library's Kahan–Heron area).
double cot_from_sides(double a, double b, double c) {
  const double cosine = (b * b + c * c - a * a) / (2 * b * c);
  return cosine / std::sqrt(std::max(0.0, 1 - cosine * cosine));
}

// The mollification's ε for a mesh of one component (docs/explanation/weights.md, Sharp & Crane 2020 Sec. 4.5): δ = 1e-5 × the mean edge
// length; ε = the largest δ − (l_i + l_j − l_k) over faces and sides, or 0.
double mollify_epsilon(const MatrixX3d& V, const MatrixX3i& F) {
  std::map<Edge, double> length;
  for (int f = 0; f < F.rows(); ++f)
    for (int k = 0; k < 3; ++k) length[edge_of(F(f, k), F(f, (k + 1) % 3))] = (pos(V, F(f, k)) - pos(V, F(f, (k + 1) % 3))).norm();
  double total = 0;
  for (auto [e, l] : length) total += l;
  const double delta = 1e-5 * total / static_cast<double>(length.size());
  double epsilon = 0;
  for (int f = 0; f < F.rows(); ++f) {
    double l[3];
    for (int k = 0; k < 3; ++k) l[k] = length.at(edge_of(F(f, k), F(f, (k + 1) % 3)));
    for (int k = 0; k < 3; ++k) epsilon = std::max(epsilon, delta - (l[k] + l[(k + 1) % 3] - l[(k + 2) % 3]));
  }
  return epsilon;
}

// docs/explanation/weights.md: w_e = ½ (max(cot α, 0) + max(cot β, 0)) over the angles opposite interior edge e, of the
// mollified intrinsic triangles when ε > 0 (every length + ε), of the faces as given otherwise; boundary
// edges have weight 0.
std::map<Edge, EdgeData> independent_weights(const MatrixX3d& V, const MatrixX3i& F) {
  const double epsilon = mollify_epsilon(V, F);
  std::map<Edge, EdgeData> edges;
  for (int f = 0; f < F.rows(); ++f) {
    const Eigen::Vector3d p[3] = {pos(V, F(f, 0)), pos(V, F(f, 1)), pos(V, F(f, 2))};
    for (int k = 0; k < 3; ++k) {
      // Edge k → k+1 is opposite corner k+2.
      EdgeData& e = edges[edge_of(F(f, k), F(f, (k + 1) % 3))];
      ++e.faces;
      const Eigen::Vector3d &apex = p[(k + 2) % 3], &a = p[k], &b = p[(k + 1) % 3];
      const double c = epsilon > 0 ? cot_from_sides((a - b).norm() + epsilon, (apex - a).norm() + epsilon, (apex - b).norm() + epsilon)
                                   : cot_at(apex, a, b);
      e.weight += 0.5 * std::max(c, 0.0);
      e.cot_sum += c;
    }
  }
  for (auto& [edge, e] : edges)
    if (e.faces != 2) e.weight = 0;
  return edges;
}

// Interior vertices (every edge at the vertex shared by two faces) and their angle defects 2π − Σ angles.
std::map<int, double> independent_angle_defects(const MatrixX3d& V, const MatrixX3i& F) {
  std::map<Edge, int> faces_of_edge;
  std::map<int, double> angle_sum;
  for (int f = 0; f < F.rows(); ++f)
    for (int k = 0; k < 3; ++k) {
      ++faces_of_edge[edge_of(F(f, k), F(f, (k + 1) % 3))];
      angle_sum[F(f, k)] += angle_at(pos(V, F(f, k)), pos(V, F(f, (k + 1) % 3)), pos(V, F(f, (k + 2) % 3)));
    }
  std::set<int> boundary;
  for (auto [e, n] : faces_of_edge)
    if (n != 2) boundary.insert(e.first), boundary.insert(e.second);
  std::map<int, double> defect;
  for (auto [v, sum] : angle_sum)
    if (!boundary.count(v)) defect[v] = 2 * kPi - sum;
  return defect;
}

// The library's x as a map from (i, j): only the topology's edge list is used to name the edges.
std::map<Edge, double> x_by_vertices(const Topology& t, const Eigen::VectorXd& x) {
  std::map<Edge, double> out;
  for (int e = 0; e < t.num_edges; ++e) out[{t.edge_vertices(e, 0), t.edge_vertices(e, 1)}] = x(e);
  return out;
}

// A flat n×n grid of [0,1]² in the z = 0 plane: interior vertices jittered by up to ±`jitter`·h in x and y,
// each cell split along a random diagonal, faces counter-clockwise seen from +z. Deterministic: the draws
// are raw std::mt19937 outputs.
Mesh jittered_grid(int n, double jitter, unsigned seed) {
  std::mt19937 rng(seed);
  auto uniform = [&] { return static_cast<double>(rng()) / 4294967296.0 - 0.5; };  // [−½, ½)
  Mesh m;
  m.V.resize((n + 1) * (n + 1), 3);
  const double h = 1.0 / n;
  for (int j = 0; j <= n; ++j)
    for (int i = 0; i <= n; ++i) {
      double x = i * h, y = j * h;
      if (i > 0 && i < n && j > 0 && j < n) x += 2 * jitter * h * uniform(), y += 2 * jitter * h * uniform();
      m.V.row(j * (n + 1) + i) << x, y, 0;
    }
  m.F.resize(2 * n * n, 3);
  int f = 0;
  for (int j = 0; j < n; ++j)
    for (int i = 0; i < n; ++i) {
      const int a = j * (n + 1) + i, b = a + 1, c = a + n + 2, d = a + n + 1;  // counter-clockwise cell corners
      if (rng() & 1) {
        m.F.row(f++) << a, b, c;
        m.F.row(f++) << a, c, d;
      } else {
        m.F.row(f++) << a, b, d;
        m.F.row(f++) << b, c, d;
      }
    }
  return m;
}

// Reduces an angle into (−π/N, π/N] (the test's own).
double reduce(double a, int N) {
  const double period = 2 * kPi / N;
  a = std::fmod(a, period);
  if (a > period / 2) a -= period;
  if (a <= -period / 2) a += period;
  return a;
}

// ---------------------------------------------------------------------------------------------
// Cotangent weights of two triangles sharing the edge (0, 1) from (0,0,0) to (2,0,0): vertex 2 is the
// apex of face (0, 1, 2) above the edge, vertex 3 the apex of face (0, 3, 1) below it.

struct PairCase {
  const char* name;
  Eigen::Vector3d up, down;
  double weight;       // worked out by hand (to O(δ) relative where mollified)
  int negative_cotan;  // 1 when cot α + cot β < 0
  int degenerate_faces, zero_area_faces;
  int mollified_faces = 0;
};

Mesh pair_mesh(const PairCase& c) {
  Mesh m;
  m.V.resize(4, 3);
  m.V << 0, 0, 0, 2, 0, 0, c.up.x(), c.up.y(), c.up.z(), c.down.x(), c.down.y(), c.down.z();
  m.F.resize(2, 3);
  m.F << 0, 1, 2, 0, 3, 1;
  return m;
}

TEST(Formulation, CotanWeightsOfHandMadePairs) {
  const double s3 = std::sqrt(3.0);
  // Hand computations, apex p over the edge a = (0,0,0), b = (2,0,0): cot = (a−p)·(b−p) / |(a−p)×(b−p)|.
  const std::vector<PairCase> cases = {
      // (1,1): (−1,−1)·(1,−1) = 0 → cot 0 (right angle); (1,−2): (−1,2)·(1,2) = 3, |cross| = 4 → 3/4.
      {"right angle and 3/4", {1, 1, 0}, {1, -2, 0}, 0.5 * (0 + 0.75), 0, 0, 0},
      // Two right angles (a square split along its diagonal): w = 0.
      {"two right angles", {1, 1, 0}, {1, -1, 0}, 0.0, 0, 0, 0},
      // Two equilateral triangles: cot 60° = 1/√3 on both sides.
      {"equilateral", {1, s3, 0}, {1, -s3, 0}, 0.5 * (2 / s3), 0, 0, 0},
      // Obtuse 157°: (−1,−0.2)·(1,−0.2) = −0.96, |cross| = 0.4 → −2.4 (clamped to 0); (1,−10): 99 / 20 = 4.95.
      // The sum is positive (2.55): clamping the sum instead of each cotangent would give 1.275.
      {"obtuse, positive sum", {1, 0.2, 0}, {1, -10, 0}, 0.5 * (0 + 4.95), 0, 0, 0},
      // −2.4 and (1,−3): 8 / 6 = 4/3; the sum is negative (clamping the sum would give 0).
      {"obtuse, negative sum", {1, 0.2, 0}, {1, -3, 0}, 0.5 * (0 + 4.0 / 3.0), 1, 0, 0},
      // Both obtuse: both clamped.
      {"both obtuse", {1, 0.2, 0}, {1, -0.2, 0}, 0.0, 1, 0, 0},
      // A fold out of the plane: apex (1,−1,1): (−1,1,−1)·(1,1,−1) = 1, cross (0,−2,−2), |.| = 2√2.
      {"folded", {1, 1, 0}, {1, -1, 1}, 0.5 * (1 / (2 * std::sqrt(2.0))), 0, 0, 0},
      // Collinear (3,0,0): a zero-area face (its cot would be +∞), mollified. Edges 2, 1, 3, √5, √5: mean
      // m = (6 + 2√5)/5, δ = 1e-5 m; the face (a, b, p) has margin 2 + 1 − 3 = 0, so ε = δ and its sides
      // are 2 + δ, 1 + δ, 3 + δ: cos at p = (6 + 4δ + δ²)/(6 + 8δ + 2δ²) ≈ 1 − 2δ/3, cot ≈ √(3/(4δ)) ≈ 189;
      // the other face keeps cot 3/4 (to O(δ)).
      {"collinear", {3, 0, 0}, {1, -2, 0}, 0.5 * (std::sqrt(3 / (4e-5 * (6 + 2 * std::sqrt(5.0)) / 5)) + 0.75), 0, 1, 1, 1},
      // Area 1e-15 ≤ 1e-14 × longest edge² (9): degenerate (its cot would be 1.5e15), mollified alike (the
      // apex is within 1e-15 of the line: the margin is ~1e-30, so ε = δ to round-off).
      {"below the degeneracy threshold",
       {3, 1e-15, 0},
       {1, -2, 0},
       0.5 * (std::sqrt(3 / (4e-5 * (6 + 2 * std::sqrt(5.0)) / 5)) + 0.75),
       0,
       1,
       0,
       1},
      // Area 1e-6 is above the degeneracy threshold, but the margin 2 + √(1 + 1e-12) − √(9 + 1e-12) ≈ 3e-13 is
      // far below δ: mollified like the collinear face (its unmollified cot would be (3 + 1e-12) / 2e-6).
      {"thin but not degenerate",
       {3, 1e-6, 0},
       {1, -2, 0},
       0.5 * (std::sqrt(3 / (4e-5 * (6 + 2 * std::sqrt(5.0)) / 5)) + 0.75),
       0,
       0,
       0,
       1},
      // Margin 2 + √(1 + 0.01) − √(9 + 0.01) ≈ 3.3e-3 > δ: not mollified, (−3,−0.1)·(−1,−0.1) = 3.01, |cross| = 0.2.
      {"thin, above the margin", {3, 0.1, 0}, {1, -2, 0}, 0.5 * (3.01 / 0.2 + 0.75), 0, 0, 0},
  };
  for (const PairCase& c : cases) {
    SCOPED_TRACE(c.name);
    const Mesh m = pair_mesh(c);
    // The test's own formula agrees with the hand value (so it can be trusted on larger meshes below).
    const std::map<Edge, EdgeData> mine = independent_weights(m.V, m.F);
    const double hand_tolerance = c.mollified_faces > 0 ? 1e-3 : 1e-12, tolerance = c.mollified_faces > 0 ? 1e-6 : 1e-12;
    ASSERT_NEAR(mine.at({0, 1}).weight, c.weight, hand_tolerance * std::max(1.0, c.weight));

    const FieldDesigner designer(m.V, m.F);
    const Topology& t = designer.topology();
    const Geometry& g = designer.geometry();
    ASSERT_EQ(t.num_edges, 5);
    for (int e = 0; e < t.num_edges; ++e) {
      const bool shared = t.edge_vertices(e, 0) == 0 && t.edge_vertices(e, 1) == 1;
      const double want = shared ? mine.at({0, 1}).weight : 0.0;
      EXPECT_NEAR(g.cotan_weight(e), want, tolerance * std::max(1.0, want)) << "edge " << e;
      EXPECT_NEAR(designer.solver().weights()(e), want, tolerance * std::max(1.0, want)) << "edge " << e;
      EXPECT_TRUE(std::isfinite(g.cotan_weight(e)));
    }
    EXPECT_EQ(g.negative_cotan_edges, c.negative_cotan);
    EXPECT_EQ(g.degenerate_faces, c.degenerate_faces);
    EXPECT_EQ(g.zero_area_faces, c.zero_area_faces);
    EXPECT_EQ(g.mollified_faces, c.mollified_faces);
    // Unit weights: 1 on the interior edge, 0 on the boundary.
    SolverOptions unit;
    unit.weights = WeightKind::Unit;
    const FieldDesigner u(m.V, m.F, unit);
    for (int e = 0; e < t.num_edges; ++e) EXPECT_EQ(u.solver().weights()(e), t.is_boundary_edge(e) ? 0.0 : 1.0) << "edge " << e;
  }
}

// A star of six triangles around one interior vertex: each interior edge's weight is the sum of two
// cotangents worked out by hand, and the one interior vertex's constraint involves all of them.
TEST(Formulation, CotanWeightsOfAStar) {
  // Regular hexagon of radius 1 around vertex 0, but vertex 1 pulled outward to radius 2 so the weights differ.
  Mesh m;
  m.V.resize(7, 3);
  m.V.row(0) << 0, 0, 0;
  for (int k = 0; k < 6; ++k) {
    const double r = k == 0 ? 2.0 : 1.0, a = kPi / 3 * k;
    m.V.row(k + 1) << r * std::cos(a), r * std::sin(a), 0;
  }
  m.F.resize(6, 3);
  for (int k = 0; k < 6; ++k) m.F.row(k) << 0, k + 1, (k + 1) % 6 + 1;
  // Spokes (0, 3), (0, 4), (0, 5): both neighbours are equilateral, opposite angles 60° → w = 1/√3.
  // Spoke (0, 1) to (2, 0): in face (0, 1, 2) the angle at vertex 2 = (cos 60°, sin 60°): u = (−½, −√3/2),
  // w = (3/2, −√3/2): u·w = −3/4 + 3/4 = 0 → cot 0; symmetric in face (0, 6, 1) → w = 0.
  // Spoke (0, 2): in face (0, 1, 2) the angle at vertex 1 = (2, 0): u = (−2, 0), w = (−3/2, √3/2): u·w = 3,
  // |u×w| = √3 → cot √3; in face (0, 2, 3) equilateral: 1/√3 → w = ½(√3 + 1/√3) = 2/√3. Same for (0, 6).
  const double s3 = std::sqrt(3.0);
  const std::map<Edge, double> spoke = {{{0, 1}, 0.0},    {{0, 2}, 2 / s3}, {{0, 3}, 1 / s3},
                                        {{0, 4}, 1 / s3}, {{0, 5}, 1 / s3}, {{0, 6}, 2 / s3}};
  const FieldDesigner designer(m.V, m.F);
  const Topology& t = designer.topology();
  for (int e = 0; e < t.num_edges; ++e) {
    const Edge key{t.edge_vertices(e, 0), t.edge_vertices(e, 1)};
    const double want = spoke.count(key) ? spoke.at(key) : 0.0;
    EXPECT_NEAR(designer.solver().weights()(e), want, 1e-12) << key.first << "-" << key.second;
  }
  // A +1 vortex at the centre. Vertex 0 is the smaller id of every spoke, so s = −1 and the one constraint is
  // −Σ x_e = K − 2π; minimising Σ x_e² / w_e under it gives x_e = −w_e (K − 2π) / Σ w and energy 4π² / Σ w.
  IndexPrescription p;
  p.vertex[0] = 1;
  const Design d = designer.design(p);
  double K = 2 * kPi;
  for (int k = 0; k < 6; ++k) K -= angle_at(pos(m.V, 0), pos(m.V, m.F(k, 1)), pos(m.V, m.F(k, 2)));
  EXPECT_NEAR(K, 0.0, 1e-12);  // flat
  double total_w = 0;
  for (auto [e, w] : spoke) total_w += w;
  const std::map<Edge, double> x = x_by_vertices(t, d.connection.x);
  double energy = 0;
  for (auto [e, w] : spoke) {
    const double want = -w * (K - 2 * kPi) / total_w;
    EXPECT_NEAR(x.at(e), want, 1e-12) << e.first << "-" << e.second;
    if (w > 0) energy += want * want / w;
  }
  EXPECT_NEAR(d.connection.energy, energy, 1e-12 * energy);
  EXPECT_NEAR(energy, 4 * kPi * kPi / total_w, 1e-12 * energy);
}

// ---------------------------------------------------------------------------------------------
// The energy reported by a solve equals Σ x_e² / w_e with the test's own weights, and x_e = 0 where w_e = 0.

void expect_energy_matches(const Mesh& m, const IndexPrescription& p, const std::string& what) {
  SCOPED_TRACE(what);
  const FieldDesigner designer(m.V, m.F);
  ASSERT_EQ(designer.solver().regularized_edges(), 0);
  const Design d = designer.design(p);
  const std::map<Edge, EdgeData> w = independent_weights(m.V, m.F);
  const std::map<Edge, double> x = x_by_vertices(designer.topology(), d.connection.x);
  ASSERT_EQ(w.size(), x.size());
  double energy = 0, largest = 0;
  int zero_weight = 0, nonzero_x_on_zero_weight = 0, negative_cot = 0;
  for (const auto& [e, data] : w) {
    const double xe = x.at(e);
    largest = std::max(largest, std::abs(xe));
    negative_cot += data.faces == 2 && data.cot_sum < 0;
    if (data.weight > 0) {
      energy += xe * xe / data.weight;
    } else {
      zero_weight += data.faces == 2;
      nonzero_x_on_zero_weight += xe != 0;
    }
  }
  EXPECT_GT(largest, 0.0) << "a trivial test: the connection is zero";
  EXPECT_EQ(nonzero_x_on_zero_weight, 0) << "of " << zero_weight << " interior edges of zero weight";
  EXPECT_NEAR(d.connection.energy, energy, 1e-10 * energy);
  EXPECT_EQ(designer.geometry().negative_cotan_edges, negative_cot);
}

TEST(Formulation, EnergyIsTheWeightedNormWithIndependentWeights) {
  {  // A cube-like sphere: a cross field with the eight corners at +1/4.
    const Mesh m = make_cube_sphere(5, true);
    IndexPrescription p;
    p.N = 4;
    for (int v : vertices_of_valence(m, 3)) p.vertex[v] = 1;
    ASSERT_EQ(p.vertex.size(), 8u);
    expect_energy_matches(m, p, "cube sphere, N = 4");
  }
  {  // A jittered grid with obtuse triangles (some edges have one negative cotangent), a ±1 pair inside.
    const Mesh m = jittered_grid(14, 0.4, 7);
    int mixed = 0;
    for (const auto& [e, data] : independent_weights(m.V, m.F)) {
      if (data.faces != 2) continue;
      // Edges where one cotangent is negative but the sum positive: clamping the sum would differ.
      mixed += data.cot_sum > 0 && data.weight > 0.5 * data.cot_sum + 1e-12;
    }
    ASSERT_GT(mixed, 5) << "the grid should have edges where clamping each cotangent differs from clamping the sum";
    IndexPrescription p;
    p.vertex[3 * 15 + 4] = 1;
    p.vertex[10 * 15 + 9] = -1;
    expect_energy_matches(m, p, "jittered grid, N = 1");
  }
  {  // A torus, N = 2, a ±1/2 pair; generators chosen.
    const Mesh m = make_torus(18, 9);
    IndexPrescription p;
    p.N = 2;
    p.vertex[20] = 1;
    p.vertex[100] = -1;
    expect_energy_matches(m, p, "torus, N = 2");
  }
}

TEST(Formulation, EnergyOnSpotWithIndependentWeights) {
  TRIVCON_REQUIRE_SHARED();
  const MeshData spot = read_mesh(test::shared_mesh("spot.obj"));
  IndexPrescription p;  // docs/getting-started.md's picture: +1 at the snout and a vortex on the flank
  p.vertex[1453] = 1;
  p.vertex[849] = 1;
  expect_energy_matches(spot, p, "spot.obj");
}

// ---------------------------------------------------------------------------------------------
// On a flat disk a field without singularities is parallel: every face's world direction equals the root
// face's. This checks ρ (transport angles), the face frames, the propagation and the writer together.

std::vector<Eigen::Vector3d> parse_txt_field(const std::string& path, int* N, int* faces) {
  std::ifstream in(path);
  std::vector<Eigen::Vector3d> out;
  std::string line;
  while (std::getline(in, line)) {
    if (line.rfind("# N ", 0) == 0) *N = std::stoi(line.substr(4));
    if (line.rfind("# faces ", 0) == 0) *faces = std::stoi(line.substr(8));
    if (line.empty() || line[0] == '#') continue;
    std::istringstream s(line);
    Eigen::Vector3d d;
    std::string extra;
    EXPECT_TRUE(s >> d.x() >> d.y() >> d.z()) << line;
    EXPECT_FALSE(s >> extra) << line;
    out.push_back(d);
  }
  return out;
}

std::vector<std::vector<Eigen::Vector3d>> parse_rawfield(const std::string& path, int* N, int* faces) {
  std::ifstream in(path);
  std::vector<std::vector<Eigen::Vector3d>> out;
  std::string line;
  if (!std::getline(in, line)) return out;
  std::istringstream header(line);
  header >> *N >> *faces;
  while (std::getline(in, line)) {
    std::istringstream s(line);
    std::vector<Eigen::Vector3d> vectors;
    Eigen::Vector3d d;
    while (s >> d.x() >> d.y() >> d.z()) vectors.push_back(d);
    out.push_back(vectors);
  }
  return out;
}

// Rotates `d` by `angle` about the unit `axis` (right-hand rule).
Eigen::Vector3d rotate(const Eigen::Vector3d& d, const Eigen::Vector3d& axis, double angle) {
  return Eigen::AngleAxisd(angle, axis.normalized()) * d;
}

// The frame of face f (docs/explanation/conventions.md): x along corner 0 → corner 1, normal (p1 − p0) × (p2 − p0).
Eigen::Vector3d frame_x(const Mesh& m, int f) { return (pos(m.V, m.F(f, 1)) - pos(m.V, m.F(f, 0))).normalized(); }
Eigen::Vector3d normal(const Mesh& m, int f) {
  const Eigen::Vector3d p0 = pos(m.V, m.F(f, 0));
  return (pos(m.V, m.F(f, 1)) - p0).cross(pos(m.V, m.F(f, 2)) - p0).normalized();
}

double max_deviation(const MatrixX3d& dirs, const Eigen::Vector3d& want) {
  double worst = 0;
  for (int f = 0; f < dirs.rows(); ++f) worst = std::max(worst, (dirs.row(f).transpose() - want).norm());
  return worst;
}

TEST(Formulation, FlatJitteredGridFieldIsParallel) {
  // In the z = 0 plane, and the same grid turned rigidly to a tilted plane (world directions still parallel).
  const Mesh flat = jittered_grid(16, 0.35, 2024);
  Mesh tilted = flat;
  const Eigen::Matrix3d turn = (Eigen::AngleAxisd(0.7, Eigen::Vector3d(1, 2, 0.5).normalized())).toRotationMatrix();
  for (int v = 0; v < tilted.V.rows(); ++v) tilted.V.row(v) = (turn * pos(flat.V, v) + Eigen::Vector3d(0.3, -1, 2)).transpose();
  const std::string dir = test::temp_dir("formulation_parallel");
  for (const Mesh* m : std::vector<const Mesh*>{&flat, &tilted}) {
    SCOPED_TRACE(m == &flat ? "z = 0" : "tilted plane");
    const int nF = static_cast<int>(m->F.rows());
    const FieldDesigner designer(m->V, m->F);
    ASSERT_EQ(designer.topology().flipped_faces.size(), 0u);
    ASSERT_EQ(designer.topology().boundary_loops.size(), 1u);
    for (bool prescribe_loop : {false, true}) {
      IndexPrescription p;  // N = 1, no singularities
      if (prescribe_loop) p.loop[0] = 1;
      const Design d = designer.design(p);
      EXPECT_EQ(d.connection.loop_index, std::vector<int>{1}) << "a disk with no singularity: loop index +1";
      EXPECT_EQ(d.connection.loop_chosen, std::vector<char>{!prescribe_loop});
      // Root: face 0, angle 0 → its first edge's direction.
      const MatrixX3d dirs = field_directions(designer.geometry(), d.field);
      EXPECT_LE(max_deviation(dirs, frame_x(*m, 0)), 1e-9);
    }
    // Another root face and angle: everything is that face's first edge turned by the angle about its normal.
    const Design d = designer.design(IndexPrescription{}, {{37, 0.5}});
    const Eigen::Vector3d want = rotate(frame_x(*m, 37), normal(*m, 37), 0.5);
    EXPECT_LE(max_deviation(field_directions(designer.geometry(), d.field), want), 1e-9);

    // The writer: .txt read back with the test's own parser.
    const std::string txt = dir + "/field.txt";
    write_field(txt, m->V, m->F, designer.geometry(), d.field);
    int N = 0, faces = 0;
    const std::vector<Eigen::Vector3d> read = parse_txt_field(txt, &N, &faces);
    EXPECT_EQ(N, 1);
    EXPECT_EQ(faces, nF);
    ASSERT_EQ(static_cast<int>(read.size()), nF);
    double worst = 0;
    for (const Eigen::Vector3d& v : read) worst = std::max(worst, (v - want).norm());
    EXPECT_LE(worst, 1e-9);

    // A cross field (N = 4; the loop index must be 4/4): .rawfield, all four vectors a quarter turn apart.
    IndexPrescription p4;
    p4.N = 4;
    const Design d4 = designer.design(p4, {{37, 0.5}});
    EXPECT_EQ(d4.connection.loop_index, std::vector<int>{4});
    const std::string raw = dir + "/field.rawfield";
    write_field(raw, m->V, m->F, designer.geometry(), d4.field);
    const std::vector<std::vector<Eigen::Vector3d>> rows = parse_rawfield(raw, &N, &faces);
    EXPECT_EQ(N, 4);
    EXPECT_EQ(faces, nF);
    ASSERT_EQ(static_cast<int>(rows.size()), nF);
    worst = 0;
    for (int f = 0; f < nF; ++f) {
      ASSERT_EQ(rows[f].size(), 4u) << "face " << f;
      for (int k = 0; k < 4; ++k) worst = std::max(worst, (rows[f][k] - rotate(want, normal(*m, 37), k * kPi / 2)).norm());
    }
    EXPECT_LE(worst, 1e-9);
  }
}

// ---------------------------------------------------------------------------------------------
// Boundary loop indices on a flat annulus (make_annulus: loop 0 is the inner circle, vertices 0..segments−1).
//
// Independent computation. A loop's index is that of a virtual vertex capping the hole, measured along the
// loop's dual cycle (the sum of its vertices' counter-clockwise dual cycles): index = (K_ℓ + turn) / 2π, K_ℓ
// = Σ (π − Σ angles) over the loop's vertices, turn = the field's turning relative to transport along the
// cycle (on a flat surface: its world angle's winding). Around a vertex of the inner circle the faces lie
// outside the circle, so its counter-clockwise cycle runs counter-clockwise about the centre; around a vertex
// of the outer circle they lie inside, so it runs clockwise. Hence index = (K_ℓ ± W) / 2π with W the winding
// of the field along the band of faces at the loop, walked counter-clockwise about the centre, + for the
// inner loop and − for the outer. A constant field (W = 0) gives +1 outer, −1 inner (docs/explanation/conventions.md). A field
// tangent to both circles winds once (W = 2π on both): inner −1 + 1 = 0, outer +1 − 1 = 0.

struct AnnulusLoop {
  int n;         // the index × N, computed by the test
  double error;  // distance of N × index from an integer
};

AnnulusLoop independent_loop_index(const Mesh& m, const MatrixX3d& dirs, int N, bool inner, double r_in, double r_out) {
  const double r_loop = inner ? r_in : r_out;
  auto on_loop = [&](int v) { return std::abs(pos(m.V, v).head<2>().norm() - r_loop) < 1e-9; };
  // K_ℓ from the corner angles at the loop's vertices.
  std::map<int, double> angle_sum;
  for (int f = 0; f < m.F.rows(); ++f)
    for (int k = 0; k < 3; ++k)
      if (on_loop(m.F(f, k)))
        angle_sum[m.F(f, k)] += angle_at(pos(m.V, m.F(f, k)), pos(m.V, m.F(f, (k + 1) % 3)), pos(m.V, m.F(f, (k + 2) % 3)));
  double K = 0;
  for (auto [v, sum] : angle_sum) K += kPi - sum;
  // The faces touching the loop, in counter-clockwise order of their centroids about the centre.
  std::vector<std::pair<double, int>> band;
  for (int f = 0; f < m.F.rows(); ++f) {
    if (!on_loop(m.F(f, 0)) && !on_loop(m.F(f, 1)) && !on_loop(m.F(f, 2))) continue;
    const Eigen::Vector3d c = (pos(m.V, m.F(f, 0)) + pos(m.V, m.F(f, 1)) + pos(m.V, m.F(f, 2))) / 3;
    band.emplace_back(std::atan2(c.y(), c.x()), f);
  }
  std::sort(band.begin(), band.end());
  double W = 0;
  for (size_t k = 0; k < band.size(); ++k) {
    const int a = band[k].second, b = band[(k + 1) % band.size()].second;
    W += reduce(std::atan2(dirs(b, 1), dirs(b, 0)) - std::atan2(dirs(a, 1), dirs(a, 0)), N);
  }
  const double index_times_N = N * (K + (inner ? W : -W)) / (2 * kPi);
  const double n = std::round(index_times_N);
  return {static_cast<int>(n), std::abs(index_times_N - n)};
}

TEST(Formulation, AnnulusLoopIndicesConstantField) {
  const Mesh m = make_annulus(5, 36);
  const FieldDesigner designer(m.V, m.F);
  ASSERT_EQ(designer.topology().boundary_loops.size(), 2u);
  ASSERT_EQ(designer.topology().boundary_loops[0][0], 0);  // loop 0 is the inner circle
  for (int N : {1, 4}) {
    SCOPED_TRACE("N = " + std::to_string(N));
    IndexPrescription p;
    p.N = N;
    const Design d = designer.design(p);  // loops chosen: the smoothest field is constant (energy 0)
    EXPECT_LE(d.connection.energy, 1e-20);
    EXPECT_EQ(d.connection.loop_index, (std::vector<int>{-N, N}));
    const MatrixX3d dirs = field_directions(designer.geometry(), d.field);
    const AnnulusLoop inner = independent_loop_index(m, dirs, N, true, 0.5, 1.0),
                      outer = independent_loop_index(m, dirs, N, false, 0.5, 1.0);
    EXPECT_LE(inner.error, 1e-6);
    EXPECT_LE(outer.error, 1e-6);
    EXPECT_EQ(inner.n, -N);
    EXPECT_EQ(outer.n, N);
  }
}

TEST(Formulation, AnnulusAlignedCrossFieldLoopIndices) {
  // 2 × 40 aligned faces (79 fixed-face paths: the dense route) and 2 × 150 (299 paths: the sparse route).
  for (int segments : {40, 150}) {
    SCOPED_TRACE("segments " + std::to_string(segments));
    const int N = 4;
    const Mesh m = make_annulus(4, segments);
    FieldDesigner designer(m.V, m.F, test::sparse_path_options());
    const std::map<int, double> aligned = boundary_alignment(designer.V(), designer.topology(), designer.geometry());
    ASSERT_EQ(static_cast<int>(aligned.size()), 2 * segments);
    std::vector<int> faces;
    for (auto [f, a] : aligned) faces.push_back(f);
    designer.set_fixed_faces(faces);
    IndexPrescription p;
    p.N = N;
    p.fixed = aligned;
    const Design d = designer.design(p);
    EXPECT_LE(d.max_fixed_error, 1e-9);
    EXPECT_LE(d.connection.max_cycle_residual, 1e-9 * std::max(1.0, d.connection.rhs_scale));
    const MatrixX3d dirs = field_directions(designer.geometry(), d.field);
    // The test's own check of the alignment: at every face with a boundary edge, the field is parallel (mod a
    // quarter turn) to that edge.
    std::map<Edge, int> faces_of_edge;
    for (int f = 0; f < m.F.rows(); ++f)
      for (int k = 0; k < 3; ++k) ++faces_of_edge[edge_of(m.F(f, k), m.F(f, (k + 1) % 3))];
    double worst = 0;
    int boundary_faces = 0;
    for (int f = 0; f < m.F.rows(); ++f) {
      bool any = false;
      for (int k = 0; k < 3; ++k) {
        const int a = m.F(f, k), b = m.F(f, (k + 1) % 3);
        if (faces_of_edge[edge_of(a, b)] != 1) continue;
        any = true;
        const Eigen::Vector3d e = pos(m.V, b) - pos(m.V, a);
        worst = std::max(worst, std::abs(reduce(std::atan2(dirs(f, 1), dirs(f, 0)) - std::atan2(e.y(), e.x()), N)));
      }
      boundary_faces += any;
    }
    EXPECT_EQ(boundary_faces, 2 * segments);
    EXPECT_LE(worst, 1e-9);
    // The loop indices used, and the same computed by the test from the field: the tangent field turns once
    // with each circle, so both loops have index 0 (see above; the constant field has +1 and −1).
    const AnnulusLoop inner = independent_loop_index(m, dirs, N, true, 0.5, 1.0),
                      outer = independent_loop_index(m, dirs, N, false, 0.5, 1.0);
    EXPECT_LE(inner.error, 1e-6);
    EXPECT_LE(outer.error, 1e-6);
    EXPECT_EQ(inner.n, 0);
    EXPECT_EQ(outer.n, 0);
    EXPECT_EQ(d.connection.loop_index, (std::vector<int>{inner.n, outer.n}));
    EXPECT_EQ(d.connection.loop_index[0] + d.connection.loop_index[1], 0) << "Gauss-Bonnet: χ = 0";
    EXPECT_EQ(d.indices.loop, d.connection.loop_index) << "the library's own read-back";
  }
}

// ---------------------------------------------------------------------------------------------
// The holonomy constraint at every interior vertex, with the sign of docs/explanation/conventions.md: Σ_{edges (u,v)} s·x = K_v − 2π k_v,
// s = +1 when v is the edge's larger id. K_v and the interior vertices are the test's own.

void expect_vertex_holonomy(const Mesh& m, const IndexPrescription& p, const std::string& what, SolverKind solver = SolverKind::Cholesky) {
  SCOPED_TRACE(what);
  SolverOptions o;
  o.solver = solver;
  const FieldDesigner designer(m.V, m.F, o);
  const Design d = designer.design(p);
  const std::map<int, double> defect = independent_angle_defects(m.V, m.F);
  std::map<int, double> sum;
  for (const auto& [e, x] : x_by_vertices(designer.topology(), d.connection.x)) {
    sum[e.second] += x;  // v = larger id: s = +1
    sum[e.first] -= x;
  }
  ASSERT_FALSE(defect.empty());
  double worst = 0;
  int singular = 0;
  for (auto [v, K] : defect) {
    const double k = p.vertex.count(v) ? static_cast<double>(p.vertex.at(v)) / p.N : 0.0;
    singular += k != 0;
    worst = std::max(worst, std::abs((K - sum[v]) - 2 * kPi * k));
  }
  EXPECT_EQ(singular, static_cast<int>(p.vertex.size()));
  EXPECT_LE(worst, 1e-9);
}

TEST(Formulation, VertexHolonomyFromPositionsAndReadmeSign) {
  {
    const Mesh m = make_cube_sphere(4, true);
    IndexPrescription p;
    p.N = 4;
    for (int v : vertices_of_valence(m, 3)) p.vertex[v] = 1;
    // Plus a ±1/2 pair away from the corners (sum still 8/4 = χ).
    int a = 20, b = 61;
    while (p.vertex.count(a)) ++a;
    while (p.vertex.count(b)) ++b;
    p.vertex[a] = 2;
    p.vertex[b] = -2;
    expect_vertex_holonomy(m, p, "cube sphere, N = 4");
#ifdef TRIVCON_WITH_SUITESPARSE
    expect_vertex_holonomy(m, p, "cube sphere, N = 4, QR", SolverKind::QR);
#endif
  }
  {
    const Mesh m = make_icosphere(2);
    IndexPrescription p;
    p.vertex[0] = 2;
    p.vertex[5] = -1;
    p.vertex[11] = 1;
    expect_vertex_holonomy(m, p, "icosphere, N = 1");
  }
  {
    const Mesh m = make_torus(16, 8);
    IndexPrescription p;
    p.N = 2;
    p.vertex[9] = 1;
    p.vertex[77] = -1;
    expect_vertex_holonomy(m, p, "torus, N = 2");
  }
  {
    const Mesh m = jittered_grid(12, 0.4, 99);  // a disk: its loop takes the rest
    IndexPrescription p;
    p.N = 4;
    p.vertex[2 * 13 + 3] = 1;
    p.vertex[8 * 13 + 7] = 3;
    expect_vertex_holonomy(m, p, "jittered grid, N = 4");
  }
}

TEST(Formulation, VertexHolonomyOnSpot) {
  TRIVCON_REQUIRE_SHARED();
  const MeshData spot = read_mesh(test::shared_mesh("spot.obj"));
  IndexPrescription p;
  p.N = 4;
  p.vertex[1453] = 4;
  p.vertex[849] = 3;
  p.vertex[100] = 1;
  expect_vertex_holonomy(spot, p, "spot.obj, N = 4");
}

}  // namespace
}  // namespace trivcon
