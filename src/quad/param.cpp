// SPDX-License-Identifier: MIT
// The integer-grid map (trivcon/param.h; the mathematics: docs/param.md).
//
// Stages: the cut and the combing (which of the four directions is u in each face), the corners grouped
// into wedges (one (u, v) unknown pair per wedge: the corners around a vertex between two cut edges), the
// linear relations (transitions across the cut, cones on integer points, aligned edges on iso-lines) turned
// into a substitution x = P y over free unknowns y, the least-squares system Pᵀ H P y = Pᵀ g, greedy rounding of
// the free integers with re-solves, stiffening against flips, and a check of everything the map promises.
#include "trivcon/param.h"

#include <Eigen/Cholesky>
#include <Eigen/SparseCore>

#include <algorithm>
#include <array>
#include <limits>
#include <map>
#include <set>
#include <memory>
#include <cmath>
#include <numeric>
#include <sstream>
#include <unordered_map>

#include "linalg/parallel.h"
#include "linalg/sparse_cholesky.h"
#include "linalg/timing.h"
#include "quad/untangle.h"
#include "trivcon/cancel.h"
#include "trivcon/error.h"
#include "trivcon/matching.h"

namespace trivcon {

namespace {

// The relief (after the untangling): faces whose σ_max/σ_min exceeds kReliefRatio are opened until every face
// of their region has det J > kReliefDeterminant (relative to the ideal unit square); a flat or folded face
// counts as kReliefFlat in the region's stretch.
constexpr double kReliefRatio = 10, kReliefDeterminant = 0.05, kReliefFlat = 1e6;
// Components of fewer unit squares than kLeastSquares get squares of their own size, within kLeastSquaresShare of
// the target's squares in all (parametrize_at, "Small components").
constexpr double kLeastSquares = 16;
constexpr double kLeastSquaresShare = 0.2;
// The shape pass (last, ParamOptions::shape; on a map whose mean ratio is past kMapDistortionGoal): the faces whose
// σ_max/σ_min exceeds it and the faces within kShapeRings rings of them lower their stretch with the barrier's shape
// term alone, at most kShapeRounds rounds of kShapeSteps L-BFGS steps.
constexpr int kShapeRings = 4, kShapeRounds = 8, kShapeSteps = 100;

using Terms = std::vector<std::pair<int, double>>;

// atan2(y, x) to within 1e-5 rad (a polynomial for atan on [0, 1]; the zeros as std::atan2): about a fifth of
// its cost, for tests that only tell apart angle sums differing by whole turns.
double rough_atan2(double y, double x) {
  const double ax = std::abs(x), ay = std::abs(y);
  if (ax == 0 && ay == 0) return std::atan2(y, x);
  const double a = std::min(ax, ay) / std::max(ax, ay), s = a * a;
  double r = a * (0.99997726 + s * (-0.33262347 + s * (0.19354346 + s * (-0.11643287 + s * (0.05265332 + s * -0.01172120)))));
  if (ay > ax) r = kPi / 2 - r;
  if (std::signbit(x)) r = kPi - r;
  return std::signbit(y) ? -r : r;
}

// Unknowns: 2 per wedge (u then v), then the integers (cone positions, iso-line values, translations).
// Linear relations Σ c x = 0 are eliminated one at a time: a relation is rewritten in the unknowns still free,
// then solved for one of them (a real one if there is one; among integers, one with coefficient ±1, so that
// the integers left free determine the others as whole numbers). Eliminated unknowns keep their expression,
// compressed to the free unknowns whenever it is read.
class Elimination {
 public:
  Elimination(int reals, int integers) : expr_(reals + integers), eliminated_(reals + integers, 0), reals_(reals) {}
  int size() const { return static_cast<int>(expr_.size()); }
  bool is_integer(int v) const { return v >= reals_; }
  bool eliminated(int v) const { return eliminated_[v]; }
  int non_unimodular() const { return non_unimodular_; }

  // The unknown as a combination of free unknowns.
  Terms resolve(int v) {
    if (!eliminated_[v]) return {{v, 1.0}};
    bool stale = false;
    for (const auto& [u, c] : expr_[v]) stale |= eliminated_[u] != 0;
    if (stale) {
      Terms out;
      for (const auto& [u, c] : expr_[v])
        for (const auto& [w, d] : resolve(u)) out.emplace_back(w, c * d);
      expr_[v] = merge(std::move(out));
    }
    return expr_[v];
  }

  void add(const Terms& relation) {
    Terms row;
    for (const auto& [v, c] : relation)
      for (const auto& [w, d] : resolve(v)) row.emplace_back(w, c * d);
    row = merge(std::move(row));
    if (row.empty()) return;  // implied by the relations before it
    int pivot = -1;
    for (int k = 0; k < static_cast<int>(row.size()); ++k)
      if (!is_integer(row[k].first) && (pivot < 0 || std::abs(row[k].second) > std::abs(row[pivot].second))) pivot = k;
    if (pivot < 0) {
      // Integers only: scale to whole coefficients, then solve for the newest one with coefficient ±1.
      double scale = 1;
      for (double m = 1; m <= 12; ++m) {
        bool whole = true;
        for (const auto& [v, c] : row) whole &= std::abs(c * m - std::round(c * m)) < 1e-9;
        if (whole) {
          scale = m;
          break;
        }
      }
      for (auto& term : row) term.second = std::round(term.second * scale);
      row = merge(std::move(row));
      if (row.empty()) return;
      long long divisor = 0;  // the relation holds over the reals: divide by its coefficients' gcd
      for (const auto& term : row) divisor = std::gcd(divisor, static_cast<long long>(std::abs(term.second)));
      if (divisor > 1)
        for (auto& term : row) term.second /= static_cast<double>(divisor);
      for (int k = 0; k < static_cast<int>(row.size()); ++k)
        if (std::abs(row[k].second) == 1 && (pivot < 0 || row[k].first > row[pivot].first)) pivot = k;
      if (pivot < 0) {
        ++non_unimodular_;
        pivot = 0;
        for (int k = 1; k < static_cast<int>(row.size()); ++k)
          if (std::abs(row[k].second) < std::abs(row[pivot].second)) pivot = k;
      }
    }
    const int v = row[pivot].first;
    const double c = row[pivot].second;
    Terms e;
    for (int k = 0; k < static_cast<int>(row.size()); ++k)
      if (k != pivot) e.emplace_back(row[k].first, -row[k].second / c);
    expr_[v] = std::move(e);
    eliminated_[v] = 1;
  }

 private:
  static Terms merge(Terms t) {
    std::sort(t.begin(), t.end(), [](const auto& a, const auto& b) { return a.first < b.first; });
    Terms out;
    for (const auto& [v, c] : t) {
      if (!out.empty() && out.back().first == v)
        out.back().second += c;
      else
        out.emplace_back(v, c);
    }
    out.erase(std::remove_if(out.begin(), out.end(), [](const auto& p) { return std::abs(p.second) < 1e-12; }), out.end());
    return out;
  }
  std::vector<Terms> expr_;
  std::vector<char> eliminated_;
  int reals_;
  int non_unimodular_ = 0;
};

int find_root(std::vector<int>& parent, int a) {
  while (parent[a] != a) a = parent[a] = parent[parent[a]];
  return a;
}

// J^r applied to (u, v): J the rotation by +π/2.
Eigen::Vector2d rotate(int r, const Eigen::Vector2d& p) {
  switch (((r % 4) + 4) % 4) {
    case 1: return {-p.y(), p.x()};
    case 2: return -p;
    case 3: return {p.y(), -p.x()};
    default: return p;
  }
}
// Entry (row a, column b) of J^r.
double rotation_entry(int r, int a, int b) {
  const Eigen::Vector2d column = rotate(r, b == 0 ? Eigen::Vector2d(1, 0) : Eigen::Vector2d(0, 1));
  return column[a];
}

// Face f laid out in its frame (x along corner 0 → 1), from its edge lengths plus `epsilon` (the
// mollification of trivcon/geometry.h, so that no face is degenerate): the corners' 2D positions.
std::array<Eigen::Vector2d, 3> layout(const MatrixX3d& V, const Topology& t, int f, double epsilon) {
  const Eigen::Vector3d p0 = V.row(t.F(f, 0)), p1 = V.row(t.F(f, 1)), p2 = V.row(t.F(f, 2));
  const double a = (p1 - p0).norm() + epsilon, b = (p2 - p1).norm() + epsilon, c = (p0 - p2).norm() + epsilon;
  const double x = (a * a + c * c - b * b) / (2 * a);
  const double y = std::sqrt(std::max(0.0, c * c - x * x));
  return {Eigen::Vector2d(0, 0), Eigen::Vector2d(a, 0), Eigen::Vector2d(x, y)};
}

// The gradients of the three hat functions of a laid-out triangle, and its area.
void hat_gradients(const std::array<Eigen::Vector2d, 3>& p, std::array<Eigen::Vector2d, 3>& g, double& area) {
  const Eigen::Vector2d e1 = p[1] - p[0], e2 = p[2] - p[0];
  area = 0.5 * (e1.x() * e2.y() - e1.y() * e2.x());
  for (int k = 0; k < 3; ++k) {
    const Eigen::Vector2d opposite = p[(k + 2) % 3] - p[(k + 1) % 3];
    g[k] = Eigen::Vector2d(-opposite.y(), opposite.x()) / (2 * area);
  }
}

// The integers' values on the map's Schur route: those `held` at `held_value`, the others minimising
// ½ yᵀ S y − ĉᵀ y with them held, S_ff y_f = ĉ_f − S_fh v_h (dense: S is the integers' Schur complement).
Eigen::VectorXd integers_from_schur(const Eigen::MatrixXd& S, const Eigen::VectorXd& c_hat, const std::vector<char>& held,
                                    const Eigen::VectorXd& held_value) {
  const int m = static_cast<int>(S.rows());
  std::vector<int> free_ints, held_ints;
  for (int a = 0; a < m; ++a) (held[a] ? held_ints : free_ints).push_back(a);
  Eigen::VectorXd y = held_value;
  const int nf = static_cast<int>(free_ints.size());
  if (nf == 0) return y;
  Eigen::MatrixXd Sff(nf, nf);
  Eigen::VectorXd rhs(nf);
  for (int p = 0; p < nf; ++p) {
    rhs[p] = c_hat[free_ints[p]];
    for (int a : held_ints) rhs[p] -= S(free_ints[p], a) * held_value[a];
    for (int r = 0; r < nf; ++r) Sff(r, p) = S(free_ints[r], free_ints[p]);
  }
  const Eigen::LLT<Eigen::MatrixXd> llt(Sff);
  if (llt.info() != Eigen::Success) throw Error("param: the integers' Schur complement is not positive definite; the mesh or the field is degenerate");
  const Eigen::VectorXd yf = llt.solve(rhs);
  for (int p = 0; p < nf; ++p) y[free_ints[p]] = yf[p];
  return y;
}

double signed_area(const Eigen::Vector2d& a, const Eigen::Vector2d& b, const Eigen::Vector2d& c) {
  const Eigen::Vector2d e1 = b - a, e2 = c - a;
  return 0.5 * (e1.x() * e2.y() - e1.y() * e2.x());
}

double whole_offset(double x) { return std::abs(x - std::round(x)); }

// The conformal factor the connection implies, per vertex (docs/param.md, "Sizing"). Across edge e = {i, j} the
// connection turns the field by x_e against the surface's parallel transport from its left face to its right;
// the Levi-Civita connection of the metric e^{2φ} g turns by w_e (φ_i − φ_j) there (w_e = ½(cot α + cot β), the
// cotan Hodge star), so the trivial connection of least Σ x_e² / w_e with only vertex constraints is exactly that
// of e^{2φ} g with φ its vertex multipliers. The field's connection (features and cycles add other terms) is
// fitted by least squares, Σ_e w_e (φ_i − φ_j − x_e / w_e)² → min over the interior edges: the cotan Poisson
// problem L φ = Σ_e x_e (δ_i − δ_j), made definite by a pull toward 0 of 1e-8 of its mean diagonal (weighted
// by vertex area; the right-hand side sums to 0 on every component, so each component's mean stays near 0).
// Weights below 1e-3 of the mean positive weight (slivers, clamped cotangents) are raised to it. Empty when
// the system cannot be factored or the solution is not finite (the map then keeps the field's unit size).
std::vector<double> connection_log_scale(const Topology& t, const Geometry& g, const Eigen::VectorXd& x, const std::vector<double>& face_area) {
  const int nV = t.num_vertices, nE = t.num_edges, nF = t.num_faces;
  double weight_sum = 0, area_sum = 0;
  int weights = 0;
  for (int e = 0; e < nE; ++e)
    if (!t.is_boundary_edge(e) && g.cotan_weight[e] > 0) weight_sum += g.cotan_weight[e], ++weights;
  if (weights == 0) return {};
  const double mean_weight = weight_sum / weights, floor = 1e-3 * mean_weight;
  Eigen::VectorXd mass = Eigen::VectorXd::Zero(nV), rhs = Eigen::VectorXd::Zero(nV);
  for (int f = 0; f < nF; ++f)
    for (int k = 0; k < 3; ++k) mass[t.F(f, k)] += face_area[f] / 3, area_sum += face_area[f] / 3;
  std::vector<Eigen::Triplet<double>> triplets;
  for (int e = 0; e < nE; ++e) {
    if (t.is_boundary_edge(e)) continue;
    const int i = t.edge_vertices(e, 0), j = t.edge_vertices(e, 1);
    const double w = std::max(g.cotan_weight[e], floor);
    triplets.emplace_back(i, i, w), triplets.emplace_back(j, j, w), triplets.emplace_back(i, j, -w);
    rhs[i] += x[e], rhs[j] -= x[e];
  }
  const double mean_mass = area_sum > 0 ? area_sum / nV : 1.0;
  // A vertex no face holds has no row otherwise: the identity there.
  for (int v = 0; v < nV; ++v) triplets.emplace_back(v, v, mass[v] > 0 ? 1e-8 * mean_weight * mass[v] / mean_mass : 1.0);
  Eigen::SparseMatrix<double> L(nV, nV);
  L.setFromTriplets(triplets.begin(), triplets.end());
  Eigen::VectorXd phi;
  try {
    linalg::SparseCholesky cholesky(L, "param: the connection's conformal factor");
    if (cholesky.factorize(L) >= 0) return {};
    phi = cholesky.solve(rhs);
  } catch (const Cancelled&) {
    throw;
  } catch (const Error&) {  // not ordered or analysed: the map keeps the unit size
    return {};
  }
  if (!phi.allFinite()) return {};
  return std::vector<double>(phi.data(), phi.data() + nV);
}

}  // namespace

namespace {

// One attempt at the map, with the quad edge length (from options) times `scale`; with `keep_strips`, the widths of
// strips between parallel aligned lines are kept open by the rounding too (the second rounding, parametrize).
Parametrization parametrize_at(const FieldDesigner& designer, const Design& design, const ParamOptions& options, double scale,
                               double untangle_share = 1.0, bool keep_strips = false) {
  const auto t0 = linalg::Clock::now();
  const Topology& t = designer.topology();
  const Geometry& g = designer.geometry();
  const MatrixX3d& V = designer.V();
  const Field& field = design.field;
  if (field.N != 4) throw Error("param: a seamless parametrization needs a cross field (N = 4), got N = " + std::to_string(field.N));
  if (!(options.untangle_share > 0 && options.untangle_share <= 1)) {
    std::ostringstream m;
    m << "param: untangle_share must be in (0, 1], got " << options.untangle_share;
    throw Error(m.str());
  }
  const int nF = t.num_faces, nE = t.num_edges, nV = t.num_vertices;
  if (field.angle.size() != nF || design.connection.x.size() != nE) throw Error("param: the design does not belong to this mesh");

  double area = 0;
  for (int f = 0; f < nF; ++f) area += g.face_area[f];
  Parametrization out;
  if (options.edge_length > 0 && std::isfinite(options.edge_length)) {
    out.edge_length = options.edge_length;
  } else if (options.target_faces > 0 && std::isfinite(options.target_faces)) {
    out.edge_length = std::sqrt(area / options.target_faces);
  } else {
    throw Error("param: give a positive edge length or target face count (--edge-length H or --target-faces K)");
  }
  if (!(out.edge_length > 0) || !std::isfinite(out.edge_length))
    throw Error("param: the mesh has no area to parametrize");
  double s = 1.0 / out.edge_length;  // (u, v) units per mesh unit; with a target face count, rescaled below
  ParamQuality& q = out.quality;
  q.faces = nF;
  q.target_squares = area * s * s;
  s /= scale;
  out.edge_length *= scale;
  const double target_here = area * s * s;  // this attempt's

  // --- The cut and the combing ---------------------------------------------------------------------------
  const Eigen::VectorXi matching = connection_matching(t, g, field, design.connection.x);
  const FieldIndices indices = indices_with_matching(t, g, designer.cycles(), field, matching);
  for (int e = 0; e < nE; ++e) q.half_turn_edges += !t.is_boundary_edge(e) && std::abs(design.connection.x[e]) >= kPi - 1e-9;
  std::vector<int> comb(nF, -1);          // which direction is u: k_f
  std::vector<char> tree_edge(nE, 0);
  for (int c = 0; c < static_cast<int>(t.components.size()); ++c) {
    const int root = t.components[c].first_face;
    comb[root] = 0;
    std::vector<int> queue{root};
    for (size_t head = 0; head < queue.size(); ++head) {
      const int f = queue[head];
      for (int k = 0; k < 3; ++k) {
        const int e = t.face_edges(f, k);
        const int L = t.edge_faces(e, 0), R = t.edge_faces(e, 1);
        if (L < 0 || R < 0) continue;
        const int other = L == f ? R : L;
        if (comb[other] >= 0) continue;
        // Direction k_L of L is paired with direction k_L + m_e of R.
        comb[other] = other == R ? (comb[f] + matching[e]) % 4 : ((comb[f] - matching[e]) % 4 + 4) % 4;
        tree_edge[e] = 1;
        queue.push_back(other);
      }
    }
  }
  std::vector<char> singular(nV, 0);
  for (int v = 0; v < nV; ++v)
    if (t.is_interior_vertex(v) && indices.vertex[v] != 0) {
      singular[v] = 1;
      out.cones.push_back(v);
      out.cone_index.push_back(indices.vertex[v]);
    }
  std::vector<char> cut(nE, 0);
  std::vector<int> degree(nV, 0);
  for (int e = 0; e < nE; ++e)
    if (!t.is_boundary_edge(e) && !tree_edge[e]) {
      cut[e] = 1;
      ++degree[t.edge_vertices(e, 0)], ++degree[t.edge_vertices(e, 1)];
    }
  {  // Prune: an edge ending at an interior regular vertex it alone reaches is not needed (its residual matching is 0).
    std::vector<int> leaves;
    auto prunable = [&](int v) { return degree[v] == 1 && t.is_interior_vertex(v) && !singular[v]; };
    for (int v = 0; v < nV; ++v)
      if (prunable(v)) leaves.push_back(v);
    while (!leaves.empty()) {
      const int v = leaves.back();
      leaves.pop_back();
      if (!prunable(v)) continue;
      for (int j = t.vertex_edge_offsets[v]; j < t.vertex_edge_offsets[v + 1]; ++j) {
        const int e = t.vertex_edges[j];
        if (!cut[e]) continue;
        cut[e] = 0;
        --degree[v];
        const int w = t.edge_vertices(e, 0) == v ? t.edge_vertices(e, 1) : t.edge_vertices(e, 0);
        if (--degree[w] == 1 && prunable(w)) leaves.push_back(w);
        break;
      }
    }
  }
  out.rotation = Eigen::VectorXi::Zero(nE);
  out.translation = Eigen::MatrixXi::Zero(nE, 2);
  for (int e = 0; e < nE; ++e)
    if (cut[e]) {
      out.cut_edges.push_back(e);
      const int L = t.edge_faces(e, 0), R = t.edge_faces(e, 1);
      out.rotation[e] = ((comb[L] + matching[e] - comb[R]) % 4 + 4) % 4;
    }
  // Pruned edges carry no turn: every non-cut edge's residual matching is 0.
  for (int e = 0; e < nE; ++e)
    if (!cut[e] && !t.is_boundary_edge(e)) {
      const int L = t.edge_faces(e, 0), R = t.edge_faces(e, 1);
      if (((comb[L] + matching[e] - comb[R]) % 4 + 4) % 4 != 0)
        throw Error("param: internal error: the cut misses a turn of the field at edge " + std::to_string(e));
    }
  q.cones = static_cast<int>(out.cones.size());
  q.cut_edges = static_cast<int>(out.cut_edges.size());

  // --- Wedges ------------------------------------------------------------------------------------------
  std::vector<int> parent(3 * nF);
  std::iota(parent.begin(), parent.end(), 0);
  for (int e = 0; e < nE; ++e) {
    if (cut[e] || t.is_boundary_edge(e)) continue;
    const int L = t.edge_faces(e, 0), R = t.edge_faces(e, 1);
    for (int end = 0; end < 2; ++end) {
      const int v = t.edge_vertices(e, end);
      const int a = find_root(parent, 3 * L + t.corner_of(L, v)), b = find_root(parent, 3 * R + t.corner_of(R, v));
      if (a != b) parent[a] = b;
    }
  }
  std::vector<int> wedge(3 * nF, -1), wedge_id(3 * nF, -1);
  int W = 0;
  for (int c = 0; c < 3 * nF; ++c) {
    const int r = find_root(parent, c);
    if (wedge_id[r] < 0) wedge_id[r] = W++;
    wedge[c] = wedge_id[r];
  }
  auto wedge_at = [&](int f, int v) { return wedge[3 * f + t.corner_of(f, v)]; };

  // Combed frame per face: the angle of u's direction, θ_f = β_f + k_f π/2, in the face's frame.
  std::vector<double> theta(nF);
  for (int f = 0; f < nF; ++f) theta[f] = field.angle[f] + comb[f] * kPi / 2;

  // --- Relations -------------------------------------------------------------------------------------------
  // Integer unknowns: 2 per cone, 1 per aligned (edge, face), 2 per cut edge.
  std::vector<std::pair<int, int>> aligned;  // (edge, face) with the coordinate that is constant: stored below
  std::vector<int> aligned_coordinate;
  std::vector<char> to_align(nE, 0);
  for (int e : options.aligned_edges) {
    if (e < 0 || e >= nE) throw Error("param: aligned edge " + std::to_string(e) + " is out of range (the mesh has " + std::to_string(nE) + " edges)");
    to_align[e] = 1;
  }
  // The coordinate constant along edge e in face f (0: u, 1: v) where the field runs along or across it within
  // kAlignedEdgeTolerance; −1 otherwise.
  auto constant_coordinate = [&](int e, int f) {
    int k = 0;
    while (t.face_edges(f, k) != e) ++k;
    const double quarters = (g.half_edge_angle(f, k) - theta[f]) / (kPi / 2);
    const double nearest = std::round(quarters);
    if (std::abs(quarters - nearest) * (kPi / 2) > kAlignedEdgeTolerance) return -1;
    return ((static_cast<long long>(nearest) % 2) + 2) % 2 == 0 ? 1 : 0;  // along ±u: v constant
  };
  // Past the tolerance, an edge meeting another aligned edge of its face at an acute corner of kAcuteCorner or more
  // (below that a narrow corner's sector turns, trivcon/features.h; a corner in one triangle of 45°–60°) is
  // across it: that corner cannot be flat, so it is a quad corner.
  auto across_acute_corner = [&](int e, int f) {
    int k = 0;
    while (t.face_edges(f, k) != e) ++k;
    for (int j : {(k + 1) % 3, (k + 2) % 3}) {
      const int other = t.face_edges(f, j);
      if (!to_align[other]) continue;
      const int c = constant_coordinate(other, f);
      if (c < 0) continue;
      const double corner = g.corner_angles(f, j == (k + 1) % 3 ? j : k);  // at the vertex the two edges share
      if (corner >= kAcuteCorner && corner < kPi / 2 - kAlignedEdgeTolerance) return 1 - c;
    }
    return -1;
  };
  for (int e : options.aligned_edges) {
    bool any = false;
    // An edge of length 0 (its two ends one point of the surface, as a pole row of an unwelded sphere) has no
    // direction: both its ends get one (u, v), so that it is a point on both iso-lines through it.
    if (zero_length_edge(V, t, e)) {
      for (int side = 0; side < 2; ++side) {
        const int f = t.edge_faces(e, side);
        if (f < 0) continue;
        for (int c = 0; c < 2; ++c) aligned.emplace_back(e, f), aligned_coordinate.push_back(c);
        any = true;
      }
      any ? ++q.aligned_edges : ++q.unaligned_edges;
      if (any) out.aligned_edges.push_back(e);
      continue;
    }
    for (int side = 0; side < 2; ++side) {
      const int f = t.edge_faces(e, side);
      if (f < 0) continue;
      int c = constant_coordinate(e, f);
      if (c < 0) c = across_acute_corner(e, f);
      if (c < 0) continue;
      aligned.emplace_back(e, f);
      aligned_coordinate.push_back(c);
      any = true;
    }
    any ? ++q.aligned_edges : ++q.unaligned_edges;
    if (any) out.aligned_edges.push_back(e);
  }
  std::sort(out.aligned_edges.begin(), out.aligned_edges.end());
  out.aligned_edges.erase(std::unique(out.aligned_edges.begin(), out.aligned_edges.end()), out.aligned_edges.end());
  // A face with two edges aligned with the same coordinate constant (two feature lines meeting at a narrow
  // corner inside one triangle, where the field's sector there has no quarter turn) is a segment in (u, v)
  // whatever the integers: both edges lie on one iso-line through the corner they share, and so does the third
  // corner. Where one of the two edges is the only aligned edge at its other end (a feature line's loose end,
  // as a short spur of sharp edges beside a longer line), it is left free (and counted unaligned), and that end
  // leaves the iso-line so that the face keeps its shape; of two such edges the shorter. A boundary edge stays
  // aligned (off its iso-line the quads' traces would leave the surface there).
  // A face with two corners at one point of the surface (an edge of length 0) has no shape to keep: with that
  // edge aligned (above) it maps to a segment, of area 0 by construction.
  std::vector<char> collapsed(nF, 0);
  for (int f = 0; f < nF; ++f)
    for (int k = 0; k < 3; ++k) collapsed[f] |= zero_length_edge(V, t, t.face_edges(f, k));
  {
    std::vector<int> aligned_at(nV, 0);
    for (int e : out.aligned_edges) ++aligned_at[t.edge_vertices(e, 0)], ++aligned_at[t.edge_vertices(e, 1)];
    std::vector<char> freed(nE, 0);
    std::vector<std::array<int, 2>> in_face(nF, {-1, -1});  // per face and coordinate: an aligned edge in it
    // The length of e if freeing it opens the face (its end other than `shared` on no other aligned edge), else ∞.
    auto worth_freeing = [&](int e, int shared) {
      const int end = t.edge_vertices(e, 0) == shared ? t.edge_vertices(e, 1) : t.edge_vertices(e, 0);
      if (t.is_boundary_edge(e) || aligned_at[end] != 1) return std::numeric_limits<double>::infinity();
      return (V.row(t.edge_vertices(e, 0)) - V.row(t.edge_vertices(e, 1))).norm();
    };
    for (size_t i = 0; i < aligned.size(); ++i) {
      const auto [e, g] = aligned[i];
      // The edge's alignment holds in the chart of each face beside it that shares its ends' wedges.
      for (int side = 0; side < 2; ++side) {
        const int f = t.edge_faces(e, side);
        if (f < 0 || (f != g && cut[e]) || collapsed[f]) continue;
        int& other = in_face[f][aligned_coordinate[i]];
        if (other < 0 || other == e) {
          other = e;
          continue;
        }
        int shared = -1;  // the corner the two edges share
        for (int a = 0; a < 2; ++a)
          for (int b = 0; b < 2; ++b)
            if (t.edge_vertices(e, a) == t.edge_vertices(other, b)) shared = t.edge_vertices(e, a);
        const double le = worth_freeing(e, shared), lo = worth_freeing(other, shared);
        if (std::isfinite(le) || std::isfinite(lo)) freed[le <= lo ? e : other] = 1;
      }
    }
    size_t kept = 0;
    for (size_t i = 0; i < aligned.size(); ++i)
      if (!freed[aligned[i].first]) aligned[kept] = aligned[i], aligned_coordinate[kept] = aligned_coordinate[i], ++kept;
    aligned.resize(kept), aligned_coordinate.resize(kept);
    for (int e : out.aligned_edges)
      if (freed[e]) --q.aligned_edges, ++q.unaligned_edges;
    out.aligned_edges.erase(std::remove_if(out.aligned_edges.begin(), out.aligned_edges.end(), [&](int e) { return freed[e] != 0; }),
                            out.aligned_edges.end());
  }
  // Turned boundary points: a boundary vertex whose two boundary edges are aligned with the same coordinate
  // constant while the boundary turns back on itself in (u, v) (the tip of a slit: a seam of patches left
  // unwelded, a crack). The aligned edges make only that coordinate whole; the other is free, yet the point is a
  // corner of the quads (the slit's two sides part there), so it is made whole too: one more integer. The turn
  // between the two edges, in quarter turns, is read from the combed frames: the direction of the fan's first
  // edge (leaving the vertex) and of its last (coming back to it), carried across the fan's cut edges by their
  // rotations; it is 0 mod 4 at a slit's tip and 2 mod 4 where the boundary runs straight on.
  // Quarter turns from the chart of the first face of v's fan (vertex_fan) to its last, over its cut edges: a
  // direction code c in the first face's chart is c + turn in the last's.
  auto fan_turn = [&](int v, const std::vector<int>& fan) {
    int turn = 0;
    for (size_t i = 0; i + 1 < fan.size(); ++i) {
      const int e = t.face_edges(fan[i], (t.corner_of(fan[i], v) + 2) % 3);
      if (cut[e]) turn += fan[i + 1] == t.edge_faces(e, 1) ? out.rotation[e] : -out.rotation[e];
    }
    return turn;
  };
  std::vector<std::array<int, 3>> turned_points;  // (vertex, face, the coordinate made whole in face's wedge)
  // Per boundary vertex whose two boundary edges are aligned: the (u, v) angle between them in quarter turns
  // (their turn modulo 4, with the whole turns of the surface's own angle there), else −1. Its ring must sum to
  // it, as an interior ring to 2π(1 − k): `winds_wrong` below.
  std::vector<int> boundary_quarters(nV, -1);
  {
    auto quarter_of = [&](int f, int k) {  // direction code of half-edge k of f in f's chart: 0 = +u, 1 = +v, ...
      const long long q = std::llround((g.half_edge_angle(f, k) - theta[f]) / (kPi / 2));
      return static_cast<int>(((q % 4) + 4) % 4);
    };
    std::vector<char> aligned_in_face(3 * static_cast<size_t>(nF), 0);
    for (const auto& [e, f] : aligned)
      for (int k = 0; k < 3; ++k)
        if (t.face_edges(f, k) == e) aligned_in_face[3 * f + k] = 1;
    std::vector<int> fan;
    for (int v = 0; v < nV; ++v) {
      if (!t.is_boundary_vertex(v)) continue;
      vertex_fan(t, v, fan);
      if (fan.empty()) continue;
      const int first = fan.front(), last = fan.back(), k_first = t.corner_of(first, v);
      const int turn = fan_turn(v, fan);
      const int k_last = (t.corner_of(last, v) + 2) % 3;
      if (!t.is_boundary_edge(t.face_edges(first, k_first)) || !t.is_boundary_edge(t.face_edges(last, k_last))) continue;
      if (!aligned_in_face[3 * first + k_first] || !aligned_in_face[3 * last + k_last]) continue;
      const int c_first = constant_coordinate(t.face_edges(first, k_first), first);
      const int c_last = constant_coordinate(t.face_edges(last, k_last), last);
      if (c_first < 0 || c_last < 0) continue;
      // The last edge's direction from v, in the first face's chart.
      const int d_first = quarter_of(first, k_first), d_last = quarter_of(last, k_last) + 2 - turn;
      const int turn_class = (((d_last - d_first) % 4) + 4) % 4;
      if (turn_class == 0) turned_points.push_back({v, first, 1 - c_first});
      double angle = 0;
      for (int f : fan) angle += g.corner_angles(f, t.corner_of(f, v));
      const int quarters = turn_class + 4 * static_cast<int>(std::lround((angle / (kPi / 2) - turn_class) / 4));
      boundary_quarters[v] = quarters > 0 ? quarters : turn_class + 4;
    }
  }
  q.turned_boundary_points = static_cast<int>(turned_points.size());
  const int nCone = static_cast<int>(out.cones.size()), nAligned = static_cast<int>(aligned.size()), nCut = static_cast<int>(out.cut_edges.size());
  const int nTurned = static_cast<int>(turned_points.size());
  const int cone0 = 2 * W, aligned0 = cone0 + 2 * nCone, cut0 = aligned0 + nAligned, turned0 = cut0 + 2 * nCut;
  Elimination elim(2 * W, 2 * nCone + nAligned + 2 * nCut + nTurned);
  for (int i = 0; i < nCone; ++i) {
    const int v = out.cones[i];
    const int f = t.vertex_faces[t.vertex_face_offsets[v]];
    const int w = wedge_at(f, v);
    for (int c = 0; c < 2; ++c) elim.add({{2 * w + c, 1.0}, {cone0 + 2 * i + c, -1.0}});
  }
  for (int i = 0; i < nAligned; ++i) {
    const auto [e, f] = aligned[i];
    const int c = aligned_coordinate[i];
    for (int end = 0; end < 2; ++end) elim.add({{2 * wedge_at(f, t.edge_vertices(e, end)) + c, 1.0}, {aligned0 + i, -1.0}});
  }
  for (int i = 0; i < nCut; ++i) {
    const int e = out.cut_edges[i];
    const int L = t.edge_faces(e, 0), R = t.edge_faces(e, 1), r = out.rotation[e];
    for (int end = 0; end < 2; ++end) {
      const int v = t.edge_vertices(e, end);
      const int wL = wedge_at(L, v), wR = wedge_at(R, v);
      for (int a = 0; a < 2; ++a) {  // φ_R[a] − Σ_b J^r[a][b] φ_L[b] − t[a] = 0
        Terms row{{2 * wR + a, 1.0}, {cut0 + 2 * i + a, -1.0}};
        for (int b = 0; b < 2; ++b)
          if (const double j = rotation_entry(r, a, b); j != 0) row.emplace_back(2 * wL + b, -j);
        elim.add(row);
      }
    }
  }
  for (int i = 0; i < nTurned; ++i) {
    const auto [v, f, c] = turned_points[i];
    elim.add({{2 * wedge_at(f, v) + c, 1.0}, {turned0 + i, -1.0}});
  }
  q.non_unimodular = elim.non_unimodular();

  // Free unknowns and x = P y.
  const int nX = elim.size();
  std::vector<int> free_index(nX, -1), free_vars;
  for (int v = 0; v < nX; ++v)
    if (!elim.eliminated(v)) free_index[v] = static_cast<int>(free_vars.size()), free_vars.push_back(v);
  const int nY = static_cast<int>(free_vars.size());
  std::vector<Eigen::Triplet<double>> pt;
  for (int v = 0; v < nX; ++v)
    for (const auto& [u, c] : elim.resolve(v)) pt.emplace_back(v, free_index[u], c);
  Eigen::SparseMatrix<double> P(nX, nY);
  P.setFromTriplets(pt.begin(), pt.end());
  std::vector<int> integer_free;
  for (int j = 0; j < nY; ++j)
    if (elim.is_integer(free_vars[j])) integer_free.push_back(j);
  q.integer_unknowns = static_cast<int>(integer_free.size());
  std::vector<char> is_integer(nY, 0);
  for (int j : integer_free) is_integer[j] = 1;
  const Eigen::SparseMatrix<double, Eigen::RowMajor> P_rows = P;  // P by rows: a wedge coordinate's unknowns
  q.seconds_cut = linalg::seconds_since(t0);

  // --- The least-squares system -------------------------------------------------------------------------------
  const auto t1 = linalg::Clock::now();
  std::vector<std::array<Eigen::Vector2d, 3>> grad(nF);
  std::vector<double> face_area(nF);
  for (int f = 0; f < nF; ++f) {
    const double eps = g.component_epsilon.empty() ? 0.0 : g.component_epsilon[t.face_component[f]];
    hat_gradients(layout(V, t, f, eps), grad[f], face_area[f]);
  }
  // The least squares' matrix H over the wedges' (u, v) and its right-hand side r are linear in the faces'
  // weights (the stiffening changes only those): each face's terms are made once, 9 of H (corner i, corner j:
  // A ∇φ_i·∇φ_j, the same for u and v, at H_entry[18 f + 2 (3 i + j) + c]) and 6 of r (corner i: A ∇φ_i·X for
  // u, A ∇φ_i·Y for v); then H = Σ_f weight_f H_f, r = s Σ_f weight_f size_f r_f, K = Pᵀ H P, b = Pᵀ r.
  std::vector<double> weight(nF, 1.0);
  std::vector<double> size(nF, 1.0);  // the target's size per face (the sizing below): s·size·(X Y)ᵀ
  // Small components: one whose area is less than kLeastSquares unit squares (a bone of a skeleton, a screw of an
  // assembly) cannot place its singularities a unit apart (a closed one needs 8 of +1/4 and 6 squares at the very
  // least, as a cube); its target becomes that many squares, its size factor √(kLeastSquares / its squares) held
  // under every sizing. Largest first (the fewest squares added), while the squares added stay within
  // kLeastSquaresShare of the attempt's; the target's total is kept, so the other components' squares grow a little.
  std::vector<double> least_size(nF, 1.0);
  auto component_squares = [&]() {  // each component's target squares at the current scale, with its own size
    std::vector<double> squares(t.components.size(), 0);
    for (int f = 0; f < nF; ++f) squares[t.face_component[f]] += face_area[f] * s * s * least_size[f] * least_size[f];
    return squares;
  };
  {
    const int nC = static_cast<int>(t.components.size());
    const std::vector<double> squares = component_squares();
    std::vector<double> factor(nC, 1.0);
    std::vector<std::pair<double, int>> small;  // (−squares, component)
    for (int c = 0; c < nC; ++c)
      if (squares[c] > 0 && squares[c] < kLeastSquares) small.emplace_back(-squares[c], c);
    std::sort(small.begin(), small.end());
    double added = 0;
    for (auto [minus, c] : small) {
      if (added + kLeastSquares + minus > kLeastSquaresShare * target_here) break;
      added += kLeastSquares + minus;
      factor[c] = std::sqrt(kLeastSquares / -minus);
      ++q.small_components;
    }
    for (int f = 0; f < nF; ++f) size[f] = least_size[f] = factor[t.face_component[f]];
  }
  Eigen::SparseMatrix<double> H(nX, nX), K;
  Eigen::VectorXd b;
  std::vector<int> H_entry(18 * static_cast<size_t>(nF)), H_column;
  std::vector<double> H_term(9 * static_cast<size_t>(nF)), r_term(6 * static_cast<size_t>(nF));
  {
    // H's pattern: (2w + c, 2w' + c) for the wedges w, w' of one face, per column its rows ascending.
    std::vector<int> start(W + 1, 0), near(9 * static_cast<size_t>(nF));
    for (int c = 0; c < 3 * nF; ++c) start[wedge[c] + 1] += 3;
    for (int w = 0; w < W; ++w) start[w + 1] += start[w];
    {
      std::vector<int> next(start.begin(), start.end() - 1);
      for (int c = 0; c < 3 * nF; ++c)
        for (int k = 0; k < 3; ++k) near[next[wedge[c]]++] = wedge[3 * (c / 3) + k];
    }
    std::vector<int> outer(nX + 1, 0), inner;
    inner.reserve(near.size());
    for (int w = 0; w < W; ++w) {
      std::sort(near.begin() + start[w], near.begin() + start[w + 1]);
      const auto last = std::unique(near.begin() + start[w], near.begin() + start[w + 1]);
      for (int c = 0; c < 2; ++c) {
        for (auto it = near.begin() + start[w]; it != last; ++it) inner.push_back(2 * *it + c);
        outer[2 * w + c + 1] = static_cast<int>(inner.size());
      }
    }
    for (int j = 2 * W; j < nX; ++j) outer[j + 1] = outer[j];
    const std::vector<double> zeros(inner.size(), 0.0);
    H = Eigen::Map<const Eigen::SparseMatrix<double>>(nX, nX, static_cast<int>(inner.size()), outer.data(), inner.data(), zeros.data());
    H_column.resize(inner.size());
    for (int j = 0; j < nX; ++j)
      for (int k = outer[j]; k < outer[j + 1]; ++k) H_column[k] = j;
  }
  auto entry = [&](int row, int col) {  // H(row, col)'s place among H's stored values
    const int* first = H.innerIndexPtr() + H.outerIndexPtr()[col];
    const int* last = H.innerIndexPtr() + H.outerIndexPtr()[col + 1];
    return static_cast<int>(std::lower_bound(first, last, row) - H.innerIndexPtr());
  };
  for (int f = 0; f < nF; ++f) {
    const double A = face_area[f];
    const Eigen::Vector2d X(std::cos(theta[f]), std::sin(theta[f])), Y(-X.y(), X.x());
    for (int i = 0; i < 3; ++i) {
      const int wi = wedge[3 * f + i];
      r_term[6 * f + 2 * i] = A * grad[f][i].dot(X);
      r_term[6 * f + 2 * i + 1] = A * grad[f][i].dot(Y);
      for (int j = 0; j < 3; ++j) {
        const int wj = wedge[3 * f + j];
        H_term[9 * f + 3 * i + j] = A * grad[f][i].dot(grad[f][j]);
        for (int c = 0; c < 2; ++c) H_entry[18 * f + 2 * (3 * i + j) + c] = entry(2 * wi + c, 2 * wj + c);
      }
    }
  }
  const Eigen::SparseMatrix<double> Pt = P.transpose();
  bool c_hat_stale = true;  // the Schur route's ĉ (below) is of an older right-hand side
  // The right-hand side alone (the scale s or the sizes changed, not the weights).
  auto assemble_rhs = [&]() {
    c_hat_stale = true;
    Eigen::VectorXd r = Eigen::VectorXd::Zero(nX);
    for (int f = 0; f < nF; ++f)
      for (int i = 0; i < 3; ++i)
        for (int c = 0; c < 2; ++c) r[2 * wedge[3 * f + i] + c] += weight[f] * size[f] * r_term[6 * f + 2 * i + c];
    b = s * (Pt * r);
  };
  double epsilon = 0;
  auto add_epsilon = [&]() {
    // The map is defined up to a translation per component: a tiny pull of every unknown toward 0 makes the
    // system definite without moving anything else measurably (the right-hand side is orthogonal to translations).
    double diagonal = 0;
    for (int j = 0; j < nY; ++j) diagonal += K.coeff(j, j) - epsilon;
    const double next = 1e-11 * (nY > 0 ? diagonal / nY : 1.0);
    for (int j = 0; j < nY; ++j) K.coeffRef(j, j) += next - epsilon;
    epsilon = next;
  };
  {  // K from every face once; afterwards H's pattern alone is read (its values stay the unit weights')
    double* h = H.valuePtr();
    for (int f = 0; f < nF; ++f)
      for (int k = 0; k < 18; ++k) h[H_entry[18 * f + k]] += weight[f] * H_term[9 * f + k / 2];
    K = Pt * (H * P);
    add_epsilon();
    K.makeCompressed();
    assemble_rhs();
  }
  // After the weights of a few faces changed by `changes` (face, change): K changes by Pᵀ ΔH P, with ΔH from
  // those faces alone, added into K's values in place (its pattern is within K's). A product over the changed
  // faces instead of all of them: the stiffening changes the weights of the distorted faces only.
  auto reassemble = [&](const std::vector<std::pair<int, double>>& changes) {
    std::vector<Eigen::Triplet<double>> dt;
    for (const auto& [f, change] : changes) {
      weight[f] += change;
      for (int k = 0; k < 18; ++k) {
        const int at = H_entry[18 * f + k];
        dt.emplace_back(H.innerIndexPtr()[at], H_column[at], change * H_term[9 * f + k / 2]);
      }
    }
    Eigen::SparseMatrix<double> dH(nX, nX);
    dH.setFromTriplets(dt.begin(), dt.end());
    const Eigen::SparseMatrix<double> dK = Pt * (dH * P);
    for (int j = 0; j < nY; ++j) {
      const int* rows = K.innerIndexPtr();
      int k = K.outerIndexPtr()[j];
      const int end = K.outerIndexPtr()[j + 1];
      for (Eigen::SparseMatrix<double>::InnerIterator it(dK, j); it; ++it) {
        while (k < end && rows[k] < it.row()) ++k;
        if (k == end || rows[k] != it.row()) throw Error("param: internal error: a change of K outside its pattern");
        K.valuePtr()[k] += it.value();
      }
    }
    add_epsilon();
    assemble_rhs();
  };
  // Two routes to the map with some integers fixed. The integers are ordered last in the factorization, so that
  // the factor's trailing block gives their Schur complement S = K_ii − K_ir K_rr⁻¹ K_ri (the energy as a
  // function of the integers, the reals solved for them). When S is small beside the factor (the integers' m³
  // within a fifth of the factorization's flops), K is factored only when it changes: the integers' values come
  // from S (fixed ones held, free ones solving S_ff y_f = ĉ_f − S_fF v_F, ĉ = S x_i for x = K⁻¹ b), and the
  // reals from K_rr y_r = b_r − K_ri y_i with the factor's leading block L_rr (SparseCholesky::solve_rest; not
  // from a solve with K itself, which S's near-null translations would spoil while few integers are held).
  // Otherwise (many integers: a mesh with hundreds of singularities) the fixed rows and columns become the
  // identity and the matrix is factored again after each change of the fixed set.
  auto solver = std::make_unique<linalg::SparseCholesky>(K, "param", integer_free);
  const int nInt = static_cast<int>(integer_free.size());
  const bool through_schur = nInt > 0 && std::pow(static_cast<double>(nInt), 3) <= 0.2 * solver->factor_flops();
  std::vector<int> int_rank(nY, -1);  // per unknown, its place among the integers
  for (int a = 0; a < nInt; ++a) int_rank[integer_free[a]] = a;
  Eigen::MatrixXd S;           // the integers' Schur complement (through_schur), of the last factorization
  Eigen::VectorXd unconstrained, c_hat;  // x = K⁻¹ b and S x_i, of the last factorization and right-hand side
  std::vector<char> fixed(nY, 0);
  Eigen::VectorXd value = Eigen::VectorXd::Zero(nY);  // the fixed integers' values
  // Solve K y = b with the fixed unknowns held. The matrix factored depends on K and, on the identity route,
  // on which unknowns are fixed, not on their values: it is factored again only after K changed (refactor =
  // true; the identity route also after the fixed set changed, refix = true), so that trying other values (the
  // local searches below) costs one solve each.
  bool refactor = true, refix = true;
  Eigen::SparseMatrix<double> M;
  auto factor = [&](const Eigen::SparseMatrix<double>& A) {
    const int bad = solver->factorize(A);
    if (bad >= 0)
      throw Error("param: the map's system is not positive definite (unknown " + std::to_string(bad) + "); the mesh or the field is degenerate");
    ++q.factorizations;
  };
  auto solve_fixed = [&]() -> Eigen::VectorXd {
    if (through_schur) {
      if (refactor) {
        factor(K);
        S = solver->schur_complement();
        refactor = false, c_hat_stale = true;
      }
      if (c_hat_stale) {
        unconstrained = solver->solve(b);
        Eigen::VectorXd xi(nInt);
        for (int a = 0; a < nInt; ++a) xi[a] = unconstrained[integer_free[a]];
        c_hat = S * xi;
        c_hat_stale = false;
      }
      std::vector<char> held(nInt, 0);
      Eigen::VectorXd held_value = Eigen::VectorXd::Zero(nInt);
      for (int a = 0; a < nInt; ++a)
        if (fixed[integer_free[a]]) held[a] = 1, held_value[a] = value[integer_free[a]];
      if (std::find(held.begin(), held.end(), 1) == held.end()) return unconstrained;  // nothing held: K⁻¹ b itself
      const Eigen::VectorXd yi = integers_from_schur(S, c_hat, held, held_value);
      // The reals for those integers: K_rr y_r = b_r − K_ri y_i, with the factor's L_rr alone.
      Eigen::VectorXd r = b;
      for (int a = 0; a < nInt; ++a)
        for (Eigen::SparseMatrix<double>::InnerIterator it(K, integer_free[a]); it; ++it) r[it.row()] -= it.value() * yi[a];
      Eigen::VectorXd y_new = solver->solve_rest(r);
      for (int a = 0; a < nInt; ++a) y_new[integer_free[a]] = yi[a];
      return y_new;
    }
    Eigen::VectorXd r = b;
    for (int j = 0; j < nY; ++j)
      if (fixed[j])
        for (Eigen::SparseMatrix<double>::InnerIterator it(K, j); it; ++it)
          if (!fixed[it.row()]) r[it.row()] -= it.value() * value[j];
    for (int j = 0; j < nY; ++j)
      if (fixed[j]) r[j] = value[j];
    if (refactor || refix) {
      // M: K with the fixed rows and columns made the identity, kept between factorizations (its pattern is K's,
      // which every assembly keeps) so that its storage is not allocated and first touched each time.
      const bool same_pattern = M.nonZeros() == K.nonZeros() && M.cols() == K.cols() &&
                                std::equal(K.outerIndexPtr(), K.outerIndexPtr() + K.cols() + 1, M.outerIndexPtr()) &&
                                std::equal(K.innerIndexPtr(), K.innerIndexPtr() + K.nonZeros(), M.innerIndexPtr());
      if (!same_pattern) {
        M = K;
      } else {
        std::copy(K.valuePtr(), K.valuePtr() + K.nonZeros(), M.valuePtr());
      }
      for (int j = 0; j < nY; ++j)
        for (Eigen::SparseMatrix<double>::InnerIterator it(M, j); it; ++it) {
          const int i = static_cast<int>(it.row());
          if (fixed[i] || fixed[j]) it.valueRef() = i == j ? 1.0 : 0.0;
        }
      factor(M);
      refactor = refix = false;
    }
    return solver->solve(r);
  };
  q.seconds_setup = linalg::seconds_since(t1);

  // --- (u, v) per corner, flips, stiffening ------------------------------------------------------------------
  Eigen::VectorXd y, x(nX);
  auto corner_uv = [&]() {
    x = P_rows * y;  // by rows: Eigen's product runs on OpenMP's threads for a large matrix
    out.uv.resize(3 * nF, 2);
#pragma omp parallel for if (3 * nF >= linalg::kParallelMinElements)
    for (int c = 0; c < 3 * nF; ++c) out.uv(c, 0) = x[2 * wedge[c]], out.uv(c, 1) = x[2 * wedge[c] + 1];
  };
  auto uv_area = [&](int f) {
    return signed_area(out.uv.row(3 * f).transpose(), out.uv.row(3 * f + 1).transpose(), out.uv.row(3 * f + 2).transpose());
  };
  // (A face with two corners at one point of the surface, `collapsed` above, maps to a segment by construction:
  // not a fold unless turned over.)
  auto folded = [&](int f) {
    const double a = uv_area(f), tolerance = 1e-12 * face_area[f] * s * s;
    return !(a > tolerance) && !(collapsed[f] && !(a < -tolerance));
  };
  // Σ of the signed (u, v) corner angles at vertex v.
  auto uv_angle_sum = [&](int v, bool rough = false) {
    double angle = 0;
    for (int j = t.vertex_face_offsets[v]; j < t.vertex_face_offsets[v + 1]; ++j) {
      const int f = t.vertex_faces[j], k = t.corner_of(f, v);
      const Eigen::Vector2d p = out.uv.row(3 * f + k).transpose();
      const Eigen::Vector2d a = out.uv.row(3 * f + (k + 1) % 3).transpose() - p, c = out.uv.row(3 * f + (k + 2) % 3).transpose() - p;
      const double sine = a.x() * c.y() - a.y() * c.x(), cosine = a.dot(c);
      angle += rough ? rough_atan2(sine, cosine) : std::atan2(sine, cosine);
    }
    return angle;
  };
  // σ_max / σ_min of the map's Jacobian on face f (rows ∇u, ∇v in the face's frame); infinite when σ_min = 0.
  auto jacobian = [&](int f) {  // rows ∇u, ∇v in the face's frame
    Eigen::Matrix2d J = Eigen::Matrix2d::Zero();
    for (int i = 0; i < 3; ++i) {
      J.row(0) += out.uv(3 * f + i, 0) * grad[f][i].transpose();
      J.row(1) += out.uv(3 * f + i, 1) * grad[f][i].transpose();
    }
    return J;
  };
  auto distortion = [&](int f) {
    const Eigen::Matrix2d J = jacobian(f);
    // Singular values of a 2 × 2 matrix in closed form.
    const double e = (J(0, 0) + J(1, 1)) / 2, ff = (J(0, 0) - J(1, 1)) / 2, gg = (J(1, 0) + J(0, 1)) / 2, h = (J(1, 0) - J(0, 1)) / 2;
    const double qq = std::hypot(e, h), rr = std::hypot(ff, gg);
    const double smax = qq + rr, smin = std::abs(qq - rr);
    return smin > 0 ? smax / smin : std::numeric_limits<double>::infinity();
  };
  // The area-weighted mean of that ratio over the faces not folded (ParamQuality::mean_distortion's sense).
  auto mean_ratio = [&]() {
    double sum = 0, mapped = 0;
    for (int f = 0; f < nF; ++f)
      if (const double ratio = distortion(f); !folded(f) && std::isfinite(ratio)) sum += face_area[f] * ratio, mapped += face_area[f];
    return mapped > 0 ? sum / mapped : 0.0;
  };
  auto count_folds = [&]() {
    int n = 0;
#pragma omp parallel for reduction(+ : n) if (nF >= linalg::kParallelMinElements)
    for (int f = 0; f < nF; ++f) n += folded(f);
    return n;
  };
  // Stiffening (MIQ, Bommes et al. 2009, §5): while faces fold, each face weighs more by its distortion, so that
  // it keeps its shape and the distortion spreads over its neighbours; a folded face counts as very distorted.
  // Before the rounding (on the real-valued map, so that the integers are chosen on a map without folds) and
  // after it (the integers held). It ends when at most `few` faces fold.
  auto stiffen = [&](int rounds, int patience, double gain, int few) {
    int fewest = std::numeric_limits<int>::max(), stalled = 0;
    for (int round = 0; round < rounds; ++round) {
      check_cancelled();
      const int folds = count_folds();
      if (folds <= few) return;
      // Stop when `patience` rounds in a row found no fewer folds than `gain` times the fewest before them (a
      // round that removes less is not progress: each is a factorization), or after three rounds when more
      // than one face in 50 still folds (the map is wrong at large: far more singularities or feature lines than
      // the squares can separate; each round is a factorization, and the stiffening only redistributes it).
      if (folds < gain * fewest) fewest = folds, stalled = 0;
      else if (++stalled == patience) return;
      if (round >= 3 && folds > std::max(1000, nF / 50)) return;
      std::vector<std::pair<int, double>> changes;
      for (int f = 0; f < nF; ++f) {
        if (collapsed[f] && !folded(f)) continue;
        const double ratio = folded(f) ? 20.0 : distortion(f);
        if (ratio > 2) changes.emplace_back(f, std::min(ratio - 1, 20.0));
      }
      reassemble(changes);
      refactor = true;
      y = solve_fixed();
      corner_uv();
      ++q.stiffening_rounds;
    }
  };

  const auto t2 = linalg::Clock::now();
  y = solve_fixed();
  corner_uv();
  ++q.rounding_rounds;
  // With a target face count: the field's map does not keep area (around singularities, along an aligned
  // boundary that curves), so its (u, v) area can miss the target by a third. The real-valued map is linear in
  // the scale (nothing is fixed yet), so when it misses by more than 10 % it is rescaled exactly to cover
  // area / edge_length² unit squares, and the edge length reported is the one used. Before the sizing (which
  // reads the map's scale against s) and after it (which moves the area again).
  // A map folded at large (its signed area less than 9/10 of its unsigned area: an index ≥ 1 folds a whole cap)
  // has no area to fit: it is kept at the field's scale, since a rescale by its cancelled area could make the
  // unit vanish.
  auto fit_target = [&]() {
    if (options.edge_length > 0 || !(q.target_squares > 0)) return;
    double covered = 0, unsigned_area = 0;
    for (int f = 0; f < nF; ++f) {
      const double a = uv_area(f);
      covered += a, unsigned_area += std::abs(a);
    }
    if (!(covered > 0.9 * unsigned_area) || !std::isfinite(covered)) return;
    const double ratio = std::sqrt(target_here / covered);
    if (std::abs(ratio * ratio - 1) <= 0.1) return;  // within 10 % in area the map is kept as it is
    s *= ratio;
    out.edge_length /= ratio;
    assemble_rhs();  // the same matrix, the right-hand side of the new scale
    y *= ratio;
    corner_uv();
  };
  fit_target();
  // Sizing: the field's unit length everywhere cannot be integrated where the field turns (around a round hole,
  // along a curved feature line, near singularities): the least squares then stretch one direction against the
  // other. The target becomes s·e^φ (X, Y) per face instead (the same matrix: only the right-hand side changes),
  // φ bounded to [−1, 1] and normalized so that Σ area·e^{2φ} is the area; φ is the connection's own conformal
  // factor (Sizing::connection, connection_log_scale above, averaged over the face's corners) or follows the
  // real-valued map (Sizing::map: each round takes its scale along the field's two directions, a = ∇u·X and
  // d = ∇v·Y, φ = log(√(a d) / s), smoothed by three passes of half the face's value and half its neighbours'
  // mean). A conformal map's scale varies this way, and the mean singular-value ratio falls (docs/param.md,
  // "Sizing").
  auto resize = [&](const std::vector<double>& phi) {
    double covered = 0, total = 0;
    for (int f = 0; f < nF; ++f) {
      size[f] = std::exp(std::clamp(phi[f], -1.0, 1.0));
      covered += face_area[f] * size[f] * size[f], total += face_area[f];
    }
    for (int f = 0; f < nF; ++f) size[f] = size[f] / std::sqrt(covered / total) * least_size[f];
    assemble_rhs();
    y = solve_fixed();
    corner_uv();
  };
  if (options.sizing == Sizing::connection) {
    check_cancelled();
    const std::vector<double> phi_v = connection_log_scale(t, g, design.connection.x, face_area);
    if (!phi_v.empty()) {
      std::vector<double> phi(nF);
      for (int f = 0; f < nF; ++f) phi[f] = (phi_v[t.F(f, 0)] + phi_v[t.F(f, 1)] + phi_v[t.F(f, 2)]) / 3;
      resize(phi);
      q.sizing = Sizing::connection;
    }
  } else if (options.sizing == Sizing::map) {
    for (int round = 0; round < options.sizing_rounds; ++round) {
      check_cancelled();
      std::vector<double> phi(nF);
      for (int f = 0; f < nF; ++f) {
        const Eigen::Matrix2d J = jacobian(f);
        const Eigen::Vector2d X(std::cos(theta[f]), std::sin(theta[f])), Y(-X.y(), X.x());
        const double a = J.row(0).dot(X), d = J.row(1).dot(Y);
        phi[f] = a > 0 && d > 0 ? std::log(std::sqrt(a * d) / (s * least_size[f])) : std::log(size[f] / least_size[f]);  // a folded face keeps its size
      }
      for (int pass = 0; pass < 3; ++pass) {
        std::vector<double> next = phi;
        for (int f = 0; f < nF; ++f) {
          double sum = 0;
          int n = 0;
          for (int k = 0; k < 3; ++k) {
            const int e = t.face_edges(f, k);
            const int other = t.edge_faces(e, 0) == f ? t.edge_faces(e, 1) : t.edge_faces(e, 0);
            if (other >= 0) sum += phi[other], ++n;
          }
          if (n > 0) next[f] = 0.5 * phi[f] + 0.5 * sum / n;
        }
        phi = std::move(next);
      }
      resize(phi);
      ++q.sizing_rounds;
      q.sizing = Sizing::map;
    }
  }
  if (q.sizing != Sizing::uniform) fit_target();
  q.folds_real_valued = count_folds();
  stiffen(options.max_stiffening_rounds, 3, 1.0, 0);
  // --- Greedy rounding: the integers nearest to whole numbers first, a fraction of those left per solve --------
  // An aligned edge whose two ends both sit on integers in the coordinate along it (a feature edge from a corner
  // or a junction of feature lines to a singularity, both on integer points) has a whole length: rounded to 0,
  // the edge and its faces collapse. Its length along, as a combination of integers, keeps the sign of the
  // real-valued map's and at least one unit: when the rounding of one of its integers would make it 0 or turn
  // it, that integer is rounded the other way (or further).
  struct Segment {
    std::vector<std::pair<int, double>> terms;  // free unknown, coefficient: the (along) length
    double real = 0;                           // in the real-valued map
    double least = 1;                          // the fewest units it keeps
    bool either_sign = false;                  // kept from 0 only, not from turning (a face's extent)
    std::vector<char> held;                    // per term: never the one changed to open it (empty: none held)
    bool strip = false;                        // a strip's width (kept at the rounding itself)
  };
  std::vector<Segment> segments;
  std::vector<std::vector<int>> segments_of(nY);  // per free integer, the segments it enters
  {
    // Coordinate c of wedge w, as free unknowns, added to acc with `sign`.
    auto along_row = [&](int w, int c, std::map<int, double>& acc, double sign) {
      for (Eigen::SparseMatrix<double, Eigen::RowMajor>::InnerIterator it(P_rows, 2 * w + c); it; ++it)
        acc[static_cast<int>(it.col())] += sign * it.value();
    };
    // Kept when its terms are all integers and the real-valued map gives it a sign.
    auto add_segment = [&](const std::map<int, double>& acc, double least, const std::set<int>& held = {}, bool either_sign = false) {
      Segment seg;
      seg.least = least;
      seg.either_sign = either_sign;
      for (auto [j, coefficient] : acc) {
        if (std::abs(coefficient) <= 1e-12) continue;
        if (!is_integer[j]) return;
        seg.terms.emplace_back(j, coefficient), seg.real += coefficient * y[j];
        if (!held.empty()) seg.held.push_back(held.count(j) ? 1 : 0);
      }
      if (seg.terms.empty() || std::abs(seg.real) < 1e-6) return;
      for (auto [j, coefficient] : seg.terms) segments_of[j].push_back(static_cast<int>(segments.size()));
      segments.push_back(std::move(seg));
    };
    // A length's nonzero terms: the key under which the chains and the face extents are each listed once.
    auto terms_of = [](const std::map<int, double>& acc) {
      std::vector<std::pair<int, double>> key;
      for (auto [j, coefficient] : acc)
        if (std::abs(coefficient) > 1e-12) key.emplace_back(j, coefficient);
      return key;
    };
    // The same up to its sign (a length found from either end), its first term's coefficient positive.
    auto unsigned_terms_of = [&](const std::map<int, double>& acc) {
      std::vector<std::pair<int, double>> key = terms_of(acc);
      if (!key.empty() && key.front().second < 0)
        for (auto& term : key) term.second = -term.second;
      return key;
    };
    for (int i = 0; i < nAligned; ++i) {
      const auto [e, f] = aligned[i];
      const int c = aligned_coordinate[i];
      std::map<int, double> along;  // the edge's own length in the other coordinate
      along_row(wedge_at(f, t.edge_vertices(e, 0)), 1 - c, along, -1.0);
      along_row(wedge_at(f, t.edge_vertices(e, 1)), 1 - c, along, 1.0);
      add_segment(along, 1);
    }
    // The same along a chain of aligned edges between two such points with points between that are not whole
    // along it (two singularities moved onto one feature line a unit or so apart, a singularity and a corner): the
    // chain's length along keeps its sign and a unit, or the rounding puts both ends on one integer and the faces
    // along the chain fold. The chain is followed within one chart (each point between two of its edges in one
    // wedge, the same coordinate constant), where the lengths of its edges add up to its ends' difference; a
    // point where more than one aligned edge goes on ends it unkept.
    {
      auto whole_along = [&](int w, int c) {
        for (Eigen::SparseMatrix<double, Eigen::RowMajor>::InnerIterator it(P_rows, 2 * w + c); it; ++it)
          if (!is_integer[it.col()]) return false;
        return true;
      };
      std::vector<std::vector<int>> entries_at(nV);
      for (int i = 0; i < nAligned; ++i)
        for (int end = 0; end < 2; ++end) entries_at[t.edge_vertices(aligned[i].first, end)].push_back(i);
      std::set<std::vector<std::pair<int, double>>> chains;
      for (int i = 0; i < nAligned; ++i)
        for (int end = 0; end < 2; ++end) {
          const int c = aligned_coordinate[i];
          const int a = t.edge_vertices(aligned[i].first, end);
          const int wa = wedge_at(aligned[i].second, a);
          if (!whole_along(wa, 1 - c)) continue;
          int at = i, from = a;
          for (int steps = 0; steps < nV; ++steps) {
            const auto [e, f] = aligned[at];
            const int to = t.edge_vertices(e, 0) == from ? t.edge_vertices(e, 1) : t.edge_vertices(e, 0);
            const int w = wedge_at(f, to);
            if (whole_along(w, 1 - c)) {
              if (steps == 0 || to == a) break;  // one edge: its own segment above
              std::map<int, double> along;
              along_row(wa, 1 - c, along, -1.0);
              along_row(w, 1 - c, along, 1.0);
              const std::vector<std::pair<int, double>> key = unsigned_terms_of(along);
              if (!key.empty() && chains.insert(key).second) add_segment(along, 1);
              break;
            }
            int next = -1;
            bool unique = true;
            for (int j : entries_at[to]) {
              const int other = aligned[j].first;
              if (other == e || aligned_coordinate[j] != c || wedge_at(aligned[j].second, to) != w) continue;
              if (next >= 0 && aligned[next].first != other) unique = false;
              next = j;
            }
            if (next < 0 || !unique) break;
            at = next, from = to;
          }
        }
    }
    // A face whose three corners all sit on whole values of one coordinate (each on an aligned line, or a
    // singularity's point: the face between two feature lines less than a unit apart, or beside a singularity
    // next to one) would be degenerate were those values equal: its extent in that coordinate, from its least to
    // its greatest corner in the real-valued map, is kept from 0 (either sign: the corners may swap, as long as
    // they do not meet). Each such pair of lines or points once.
    std::set<std::vector<std::pair<int, double>>> extents;
    auto add_extent = [&](const std::map<int, double>& to, const std::map<int, double>& from) {
      std::map<int, double> extent = to;
      for (auto [j, coefficient] : from) extent[j] -= coefficient;
      const std::vector<std::pair<int, double>> key = terms_of(extent);
      if (!key.empty() && extents.insert(key).second) add_segment(extent, 1, {}, true);
    };
    for (int f = 0; f < nF; ++f) {
      if (folded(f)) continue;  // the real-valued map's order of its corners is no guide there
      std::array<std::array<double, 2>, 3> real{};
      std::array<std::array<bool, 2>, 3> whole;
      int whole_corners = 0;
      for (int k = 0; k < 3; ++k)
        for (int c = 0; c < 2; ++c) {
          whole[k][c] = true;
          for (Eigen::SparseMatrix<double, Eigen::RowMajor>::InnerIterator it(P_rows, 2 * wedge[3 * f + k] + c); it; ++it)
            whole[k][c] = whole[k][c] && is_integer[it.col()], real[k][c] += it.value() * y[it.col()];
          whole_corners += whole[k][c];
        }
      if (whole_corners < 3) continue;  // most faces: no extent to keep
      std::array<std::array<std::map<int, double>, 2>, 3> corner;
      for (int k = 0; k < 3; ++k)
        for (int c = 0; c < 2; ++c)
          if (whole[k][c]) along_row(wedge[3 * f + k], c, corner[k][c], 1.0);
      for (int c = 0; c < 2; ++c) {
        if (!whole[0][c] || !whole[1][c] || !whole[2][c]) continue;
        int lo = 0, hi = 0;
        for (int k = 1; k < 3; ++k) {
          if (real[k][c] < real[lo][c]) lo = k;
          if (real[k][c] > real[hi][c]) hi = k;
        }
        add_extent(corner[hi][c], corner[lo][c]);
      }
    }
    // With keep_strips: two parallel aligned lines less than kStripUnits apart with vertices between them (a strip
    // between a hole's rim and a plate's outer edge, or a thin wall between two rims, meshed more than one triangle
    // across): rounded onto one integer, the strip collapses and the vertices inside fold over the lines (a strip
    // one triangle across collapses to segments, counted apart, and its faces' extents are kept above). The strip's
    // width, line to line, keeps its real-valued sign and a unit. It is found by walking the real-valued map from
    // each aligned edge straight across (along the coordinate constant on it), face by face, to the first aligned
    // edge reached: kept when that one has the same coordinate constant and a vertex off the lines was passed. A
    // cut is crossed with its transition (the width then gathers the cut's translation); a walk that meets the
    // boundary, a folded face or a line across it ends unkept.
    if (keep_strips) {
      constexpr double kStripUnits = 2.0;
      std::vector<int> coordinate_in(3 * static_cast<size_t>(nF), -1);  // per (face, edge slot): its aligned coordinate, 2 both
      std::vector<char> on_line(nV, 0);                                 // an end of an aligned edge
      for (int i = 0; i < nAligned; ++i) {
        const auto [e, f] = aligned[i];
        on_line[t.edge_vertices(e, 0)] = on_line[t.edge_vertices(e, 1)] = 1;
        for (int k = 0; k < 3; ++k)
          if (t.face_edges(f, k) == e) coordinate_in[3 * f + k] = coordinate_in[3 * f + k] == -1 ? aligned_coordinate[i] : 2;
      }
      auto corners_of = [&](int f) {  // in the real-valued map
        return std::array<Eigen::Vector2d, 3>{out.uv.row(3 * f).transpose(), out.uv.row(3 * f + 1).transpose(), out.uv.row(3 * f + 2).transpose()};
      };
      std::set<std::vector<std::pair<int, double>>> strips;
      for (int i = 0; i < nAligned; ++i) {
        const auto [e0, f0] = aligned[i];
        if (folded(f0)) continue;
        int k0 = 0;
        while (t.face_edges(f0, k0) != e0) ++k0;  // edge slot k joins corners k and k + 1
        std::array<Eigen::Vector2d, 3> p = corners_of(f0);
        // The start's coordinate c0 in the current chart: sign · (its coordinate c) + offset.
        const int c0 = aligned_coordinate[i];
        int c = c0;
        double sign = 1;
        std::map<int, double> offset;
        const double across = p[(k0 + 2) % 3][c] - 0.5 * (p[k0][c] + p[(k0 + 1) % 3][c]);
        if (std::abs(across) < 1e-9) continue;
        Eigen::Vector2d d = Eigen::Vector2d::Zero();
        d[c] = across > 0 ? 1.0 : -1.0;
        Eigen::Vector2d at = 0.5 * (p[k0] + p[(k0 + 1) % 3]);
        int f = f0, entry = e0;
        double travelled = 0;
        bool inner = false;
        for (int steps = 0; steps < nF; ++steps) {
          for (int k = 0; k < 3; ++k) inner = inner || !on_line[t.F(f, k)];
          // The edge of f (other than the entry) the ray leaves through, the nearest ahead.
          int exit_slot = -1;
          double exit_at = std::numeric_limits<double>::infinity();
          for (int k = 0; k < 3; ++k) {
            if (t.face_edges(f, k) == entry) continue;
            const Eigen::Vector2d ab = p[(k + 1) % 3] - p[k], r = p[k] - at;
            const double det = ab.x() * d.y() - ab.y() * d.x();
            if (std::abs(det) < 1e-14) continue;
            const double ahead = (ab.x() * r.y() - ab.y() * r.x()) / det, u = (d.x() * r.y() - d.y() * r.x()) / det;  // at + ahead d = p_k + u ab
            if (ahead > 1e-12 && u >= -1e-9 && u <= 1 + 1e-9 && ahead < exit_at) exit_at = ahead, exit_slot = k;
          }
          if (exit_slot < 0) break;
          travelled += exit_at;
          if (travelled >= kStripUnits) break;
          const int e = t.face_edges(f, exit_slot), line = coordinate_in[3 * f + exit_slot];
          if (line == c) {
            std::map<int, double> width = offset;
            along_row(wedge[3 * f + exit_slot], c, width, sign);
            along_row(wedge[3 * f0 + k0], c0, width, -1.0);
            const std::vector<std::pair<int, double>> key = unsigned_terms_of(width);
            const size_t before = segments.size();
            if (inner && !key.empty() && strips.insert(key).second) add_segment(width, 1);
            if (segments.size() > before) segments.back().strip = true, ++q.strip_widths;
            break;
          }
          if (line >= 0) break;  // a line across the walk, or a point on both
          const int next = t.edge_faces(e, 0) == f ? t.edge_faces(e, 1) : t.edge_faces(e, 0);
          if (next < 0 || folded(next)) break;
          at += exit_at * d;
          const std::array<Eigen::Vector2d, 3> p_next = corners_of(next);
          const int v0 = t.edge_vertices(e, 0), v1 = t.edge_vertices(e, 1);
          const int w0 = wedge_at(f, v0), w0_next = wedge_at(next, v0);
          if (w0 != w0_next || wedge_at(f, v1) != wedge_at(next, v1)) {
            // A cut: φ_next = J^r φ_f + T at both its ends, r from the edge's direction in the two charts. Then
            // φ_f[c] = Σ_b J^{−r}[c][b] (φ_next[b] − T[b]), one b, with T[b] = φ_next(v0)[b] − (J^r φ_f(v0))[b].
            const Eigen::Vector2d in_f = p[t.corner_of(f, v1)] - p[t.corner_of(f, v0)];
            const Eigen::Vector2d in_next = p_next[t.corner_of(next, v1)] - p_next[t.corner_of(next, v0)];
            const double turn = std::atan2(in_f.x() * in_next.y() - in_f.y() * in_next.x(), in_f.dot(in_next));
            const int r = static_cast<int>(((std::lround(turn / (kPi / 2)) % 4) + 4) % 4);
            int b = 0;
            while (rotation_entry(4 - r, c, b) == 0) ++b;
            std::map<int, double> T;
            along_row(w0_next, b, T, 1.0);
            for (int a = 0; a < 2; ++a)
              if (const double j = rotation_entry(r, b, a); j != 0) along_row(w0, a, T, -j);
            sign *= rotation_entry(4 - r, c, b);
            for (auto [j, x] : T) offset[j] -= sign * x;
            c = b;
            at = rotate(r, at) + (p_next[t.corner_of(next, v0)] - rotate(r, p[t.corner_of(f, v0)]));
            d = rotate(r, d);
          }
          f = next, entry = e, p = p_next;
        }
      }
    }
    // A boundary loop's extent: its width and height in (u, v) are kept at least one unit the same way, so that a
    // hole smaller than a square does not round to a point or to a slit one unit long (whose two sides would be
    // one quad edge: the quad mesh would close it). The loop is developed into the chart of its first edge's
    // face: each boundary edge's (u, v) difference, turned by the quarter turns of the cut edges crossed so far in
    // the fans between consecutive edges. A loop that closes there (no net turn, and back to its start within half
    // a unit: a hole in a disk, not the rim of a cylinder) gives two segments, from its least to its greatest u
    // and v (kept when both ends are integers, on aligned sides). A slit (one extent 0 whatever the integers: its
    // sides share their ends) keeps two units along: with one, its two sides would be one quad edge.
    std::vector<int> fan;
    for (const std::vector<int>& loop : t.boundary_loops) {
      const int n = static_cast<int>(loop.size());
      if (n < 3) continue;
      std::vector<std::array<std::map<int, double>, 2>> step(n);  // the developed (u, v) difference along edge i
      std::vector<Eigen::Vector2d> at(n + 1, Eigen::Vector2d::Zero());  // the developed point at vertex i, real map
      int turn = 0;
      bool ok = true;
      for (int i = 0; i < n && ok; ++i) {
        const int a = loop[i], c = loop[(i + 1) % n];
        const int e = edge_between(t, a, c);
        const int f = e >= 0 ? (t.edge_faces(e, 0) >= 0 ? t.edge_faces(e, 0) : t.edge_faces(e, 1)) : -1;
        vertex_fan(t, c, fan);
        if (f < 0 || fan.empty() || fan.back() != f) {
          ok = false;
          break;
        }
        std::array<std::map<int, double>, 2>& d = step[i];
        for (int k = 0; k < 2; ++k) {
          along_row(wedge_at(f, a), k, d[k], -1.0);
          along_row(wedge_at(f, c), k, d[k], 1.0);
        }
        for (int r = ((turn % 4) + 4) % 4; r > 0; --r) {  // J (u, v) = (−v, u)
          std::swap(d[0], d[1]);
          for (auto& term : d[0]) term.second = -term.second;
        }
        at[i + 1] = at[i];
        for (int k = 0; k < 2; ++k)
          for (auto [j, x] : d[k]) at[i + 1][k] += x * y[j];
        turn += fan_turn(c, fan);  // into the next edge's chart: its face starts c's fan, this edge's face ends it
      }
      if (!ok || ((turn % 4) + 4) % 4 != 0 || at[n].lpNorm<Eigen::Infinity>() > 0.5) continue;
      std::array<std::map<int, double>, 2> extent;
      bool empty[2];
      for (int k = 0; k < 2; ++k) {
        int lo = 0, hi = 0;
        for (int i = 1; i < n; ++i) {
          if (at[i][k] < at[lo][k]) lo = i;
          if (at[i][k] > at[hi][k]) hi = i;
        }
        for (int i = lo; i != hi; i = (i + 1) % n)
          for (auto [j, x] : step[i][k]) extent[k][j] += x;
        empty[k] = std::all_of(extent[k].begin(), extent[k].end(), [](const auto& term) { return std::abs(term.second) <= 1e-12; });
      }
      // The loop's closure (the translations of the cuts it crosses, 0 in a hole's) is not what opens it: changed,
      // the hole's image would tear open at a cut instead.
      std::array<std::map<int, double>, 2> sum;
      for (int i = 0; i < n; ++i)
        for (int k = 0; k < 2; ++k)
          for (auto [j, x] : step[i][k]) sum[k][j] += x;
      std::set<int> closure;
      for (int k = 0; k < 2; ++k)
        for (auto [j, x] : sum[k])
          if (std::abs(x) > 1e-12) closure.insert(j);
      for (int k = 0; k < 2; ++k) add_segment(extent[k], empty[1 - k] ? 2 : 1, closure);
    }
  }
  // After a round's integers are given values: every segment now whole that the round completed, and that would be
  // 0 or turned, gets one unit in the real map's sense through one of its integers of coefficient ±1: one whose
  // change closes no other whole segment if there is one, and of those the one in the fewest other segments (a
  // corner between two segments moves neither); the segments that integer enters are looked at again, after
  // those waiting, a bounded number of times.
  // Segment seg's length in the real map's sense with integer j1 changed by d1 and j2 by d2 (−1: none); `whole`
  // tells whether all its integers are fixed.
  // `signed_length`, when given, gets the length as the integers' sum (before the real map's sense).
  auto open_length = [&](const Segment& seg, bool& whole, int j1 = -1, double d1 = 0, int j2 = -1, double d2 = 0,
                         double* signed_length = nullptr) {
    double length = 0;
    whole = true;
    for (auto [i, coefficient] : seg.terms)
      whole &= fixed[i] != 0, length += coefficient * (value[i] + (i == j1 ? d1 : 0.0) + (i == j2 ? d2 : 0.0));
    if (signed_length) *signed_length = length;
    return seg.either_sign ? std::abs(length) : seg.real > 0 ? length : -length;
  };
  // Whether those changes close segment k, whole and open before.
  auto closes = [&](int k, int j1, double d1, int j2 = -1, double d2 = 0) {
    const Segment& seg = segments[k];
    bool whole = false;
    return open_length(seg, whole) > seg.least - 0.5 && whole && !(open_length(seg, whole, j1, d1, j2, d2) > seg.least - 0.5);
  };
  auto closes_another = [&](int k, int j, double change) {
    for (int other : segments_of[j])
      if (other != k && closes(other, j, change)) return true;
    return false;
  };
  auto keep_segments_open = [&](const std::vector<int>& round) {
    std::vector<int> queue;
    for (int j : round) queue.insert(queue.end(), segments_of[j].begin(), segments_of[j].end());
    const size_t budget = 4 * queue.size() + 16;
    for (size_t head = 0; head < queue.size() && head < budget; ++head) {
      const int k = queue[head];
      const Segment& seg = segments[k];
      bool whole = false;
      double length = 0;
      if (open_length(seg, whole, -1, 0, -1, 0, &length) > seg.least - 0.5 || !whole) continue;
      int pick = -1;
      double pick_coefficient = 0;
      bool pick_closes = true;
      for (size_t m = 0; m < seg.terms.size(); ++m) {
        const auto [i, coefficient] = seg.terms[m];
        if (!(std::abs(std::abs(coefficient) - 1) < 1e-9) || (!seg.held.empty() && seg.held[m])) continue;
        const bool closes = closes_another(k, i, ((seg.real > 0 ? seg.least : -seg.least) - length) * coefficient);
        if (pick < 0 || (pick_closes && !closes) || (pick_closes == closes && segments_of[i].size() < segments_of[pick].size()))
          pick = i, pick_coefficient = coefficient, pick_closes = closes;
      }
      if (pick < 0) continue;
      // The length becomes ±least; not when that moves the integer more than two units from its rounding (the
      // segments disagree: a map folded at large, whose signs are no guide).
      const double opened = value[pick] + ((seg.real > 0 ? seg.least : -seg.least) - length) * pick_coefficient;
      if (std::abs(opened - std::round(y[pick])) > 2) continue;
      value[pick] = opened;
      ++q.segments_opened;
      for (int other : segments_of[pick])
        if (other != k) queue.push_back(other);
    }
  };
  // Whether changing fixed integers j1 by d1 and j2 by d2 would close a segment open before (as
  // keep_segments_open means it): the moves after the rounding (the descent, the singularities' and the other
  // integers' local searches) refuse those.
  auto closes_segment = [&](int j1, double d1, int j2 = -1, double d2 = 0) {
    for (int k : segments_of[j1])
      if (closes(k, j1, d1, j2, d2)) return true;
    if (j2 >= 0)
      for (int k : segments_of[j2])
        if (closes(k, j1, d1, j2, d2)) return true;
    return false;
  };
  // The value integer j is rounded to: the whole number nearest its real value that keeps open every strip's width
  // it completes (its other terms already fixed), within three units; its plain rounding when there is none. (The
  // other segments are opened after the round, above: at the rounding itself they would move fandisk's map.)
  auto rounded_keeping_strips = [&](int j) {
    struct Bound {
      double a, rest, least;  // a x + rest, in the real map's sense, at least `least`
    };
    std::vector<Bound> bounds;
    for (int k : segments_of[j]) {
      const Segment& seg = segments[k];
      if (!seg.strip) continue;
      Bound b{0, 0, seg.least};
      bool complete = true;
      for (auto [i, coefficient] : seg.terms) {
        if (i == j) b.a += coefficient;
        else complete = complete && fixed[i] != 0, b.rest += coefficient * value[i];
      }
      if (!complete || b.a == 0) continue;
      if (seg.real < 0) b.a = -b.a, b.rest = -b.rest;
      bounds.push_back(b);
    }
    const double nearest = std::round(y[j]);
    if (bounds.empty()) return nearest;
    std::vector<double> candidates;
    for (int d = -3; d <= 3; ++d) candidates.push_back(nearest + d);
    std::stable_sort(candidates.begin(), candidates.end(), [&](double a, double c) { return std::abs(a - y[j]) < std::abs(c - y[j]); });
    for (double x : candidates)
      if (std::all_of(bounds.begin(), bounds.end(), [&](const Bound& b) { return b.a * x + b.rest > b.least - 0.5; })) return x;
    return nearest;
  };
  std::vector<int> left = integer_free;
  while (!left.empty()) {
    check_cancelled();
    std::sort(left.begin(), left.end(), [&](int a, int c) {
      const double da = whole_offset(y[a]), dc = whole_offset(y[c]);
      return da != dc ? da < dc : a < c;
    });
    size_t take = std::max<size_t>(1, static_cast<size_t>(std::ceil(options.rounding_fraction * left.size())));
    if (static_cast<int>(left.size()) <= options.round_all_below) take = left.size();  // the last few at once
    while (take < left.size() && whole_offset(y[left[take]]) < 1e-9) ++take;  // already whole: free to fix
    for (size_t k = 0; k < take; ++k) fixed[left[k]] = 1, value[left[k]] = rounded_keeping_strips(left[k]);
    if (!segments.empty()) keep_segments_open(std::vector<int>(left.begin(), left.begin() + static_cast<long>(take)));
    refix = true;
    left.erase(left.begin(), left.begin() + static_cast<long>(take));
    y = solve_fixed();
    ++q.rounding_rounds;
  }
  corner_uv();
  // Local search on the singularities' integer points: a singularity that shares its point with another of one of
  // its faces (they were closer than a unit), or whose ring folds (the ring winds around it once too few or too
  // many times), tries the 8 integer points around its own; the one with the fewest folded faces, then the least
  // energy, is kept (staying is a candidate unless it coincides). Each singularity is tried once.
  // The energy ½ yᵀK y − bᵀy along y0 + dx·gu + dy·gv, a quadratic in (dx, dy): three products with K instead
  // of one per candidate.
  struct EnergyAlong {
    double e0;
    Eigen::Vector2d linear;
    Eigen::Matrix2d quadratic;
    double operator()(double dx, double dy) const {
      const Eigen::Vector2d d(dx, dy);
      return e0 + linear.dot(d) + 0.5 * d.dot(quadratic * d);
    }
  };
  auto energy_along = [&](const Eigen::VectorXd& y0, const Eigen::VectorXd& gu, const Eigen::VectorXd& gv) {
    const Eigen::VectorXd Ky0 = K * y0, Kgu = K * gu, Kgv = K * gv;
    EnergyAlong e;
    e.e0 = 0.5 * y0.dot(Ky0) - b.dot(y0);
    e.linear = Eigen::Vector2d(gu.dot(Ky0) - b.dot(gu), gv.dot(Ky0) - b.dot(gv));
    e.quadratic << gu.dot(Kgu), gu.dot(Kgv), gv.dot(Kgu), gv.dot(Kgv);
    return e;
  };
  // The same on the Schur route with every integer fixed, for the steps of integers ju and jv (−1: none): the
  // slope (K y0 − b)_j from K's column j, the curvature from S; e0 left 0 (the same for every step compared).
  auto energy_of_handles = [&](const Eigen::VectorXd& y0, int ju, int jv) {
    EnergyAlong e;
    e.e0 = 0;
    const std::array<int, 2> j{ju, jv};
    for (int c = 0; c < 2; ++c) {
      e.linear[c] = 0;
      if (j[c] < 0) continue;
      e.linear[c] = -b[j[c]];
      for (Eigen::SparseMatrix<double>::InnerIterator it(K, j[c]); it; ++it) e.linear[c] += it.value() * y0[it.row()];
    }
    for (int c = 0; c < 2; ++c)
      for (int d = 0; d < 2; ++d) e.quadratic(c, d) = j[c] >= 0 && j[d] >= 0 ? S(int_rank[j[c]], int_rank[j[d]]) : 0.0;
    return e;
  };
  auto ring_is_bad = [&](int v) {
    for (int j = t.vertex_face_offsets[v]; j < t.vertex_face_offsets[v + 1]; ++j) {
      const int f = t.vertex_faces[j];
      if (folded(f)) return true;
      const int i = t.corner_of(f, v);
      for (int k = 1; k < 3; ++k)
        if (singular[t.F(f, (i + k) % 3)] && (out.uv.row(3 * f + i) - out.uv.row(3 * f + (i + k) % 3)).lpNorm<Eigen::Infinity>() < 1e-6)
          return true;
    }
    return false;
  };
  // The response of the solution to a unit change of fixed value j (one solve with the current factorization).
  // Its right-hand side has a nonzero per neighbour of j: a sparse solve.
  // (On the Schur route, where every integer is fixed by now, the reals' part is −K_rr⁻¹ K_rj with L_rr alone.)
  auto response = [&](int j) {
    std::vector<std::pair<int, double>> r;
    for (Eigen::SparseMatrix<double>::InnerIterator it(K, j); it; ++it)
      if (!fixed[it.row()]) r.emplace_back(static_cast<int>(it.row()), -it.value());
    if (through_schur) {
      Eigen::VectorXd g = solver->solve_rest_sparse(r);
      g[j] = 1.0;
      return g;
    }
    r.emplace_back(j, 1.0);
    return solver->solve_sparse(r);
  };
  // Descent on the integers: the greedy rounding fixes each integer on the map of its round, before the later
  // ones; held at the end, one often lies a whole unit or more from its best value. The energy along a change t
  // of fixed integer j (the others held, the reals solved again) is E(y + t g_j) = E + t ρ_j + ½ t² c_j, with
  // g_j the response to a unit change, c_j = g_jᵀK g_j (which depends on which unknowns are fixed, not on their
  // values) and ρ = K y − b (its free rows are 0, so ρ_j is the whole slope; a step s of j adds s K g_j).
  // Coordinate descent: the step of the largest decrease, round(−ρ_j / c_j), is taken, ρ updated, and so on
  // while one decreases the energy. A step is refused when it leaves more folded faces or closes an aligned
  // edge (keep_segments_open's sense). It costs a solve per integer taking part: only where the rounded map
  // misses a goal (folds, or a mean singular-value ratio above kMapDistortionGoal), and at most 32 integers
  // (those of the largest |ρ_j| / K_jj, a bound from below on |ρ_j| / c_j).
  if (options.descend_integers && (count_folds() > 0 || mean_ratio() > kMapDistortionGoal)) {
    Eigen::VectorXd slope = K * y - b;
    std::vector<std::pair<double, int>> order;
    for (int j : integer_free) order.emplace_back(-std::abs(slope[j]) / K.coeff(j, j), j);
    std::sort(order.begin(), order.end());
    order.resize(std::min<size_t>(order.size(), 32));
    std::vector<int> candidates;
    std::vector<double> curvature;
    for (const auto& [bound, j] : order) {
      check_cancelled();
      // c_j = g_jᵀ K g_j: S_jj on the Schur route (without a solve)
      const double c = through_schur ? S(int_rank[j], int_rank[j]) : [&] {
        const Eigen::VectorXd gj = response(j);
        return gj.dot(K * gj);
      }();
      if (c > 0) candidates.push_back(j), curvature.push_back(c);
    }
    std::vector<char> refused(candidates.size(), 0);
    for (int moves = 0; moves < 2 * static_cast<int>(candidates.size()); ++moves) {
      int pick = -1;
      double pick_step = 0, largest = 1e-12;
      for (size_t k = 0; k < candidates.size(); ++k) {
        if (refused[k]) continue;
        const double rho = slope[candidates[k]], step = std::round(-rho / curvature[k]);
        if (const double decrease = -(step * rho + 0.5 * step * step * curvature[k]); step != 0 && decrease > largest)
          pick = static_cast<int>(k), pick_step = step, largest = decrease;
      }
      if (pick < 0) break;
      check_cancelled();
      const int j = candidates[pick];
      if (closes_segment(j, pick_step)) {
        refused[pick] = 1;
        continue;
      }
      const int folds = count_folds();
      const Eigen::VectorXd y0 = y, gj = response(j);
      y = y0 + pick_step * gj;
      corner_uv();
      if (count_folds() > folds) {
        refused[pick] = 1;
        y = y0;
        corner_uv();
        continue;
      }
      value[j] += pick_step;
      slope += pick_step * (K * gj);
      ++q.integers_descended;
    }
  }
  // The free integers that move a singularity's point by a whole unit in u and in v (its handles, −1 for none):
  // each coordinate's own integer, or for a singularity on an aligned line the line's across it (the move
  // shifts the whole line) and its own along it, whichever the elimination kept; none for a coordinate that is
  // a sum of several integers (a line's value through a cut's translation).
  struct Handles {
    int u = -1, v = -1;
    Eigen::VectorXd gu, gv;  // the solution's response to a unit change of each (0 without a handle)
    bool movable() const { return u >= 0 || v >= 0; }
  };
  auto cone_handles = [&](int k) {
    Handles h;
    for (int c = 0; c < 2; ++c) {
      const Terms terms = elim.resolve(cone0 + 2 * k + c);
      if (terms.size() == 1 && std::abs(std::abs(terms[0].second) - 1) < 1e-12) (c == 0 ? h.u : h.v) = free_index[terms[0].first];
    }
    if (h.v == h.u) h.v = -1;
    return h;
  };
  // The responses (a solve each, with the current factorization): the solution is affine in the two values.
  auto respond = [&](Handles& h) {
    h.gu = h.u >= 0 ? response(h.u) : Eigen::VectorXd::Zero(nY);
    h.gv = h.v >= 0 ? response(h.v) : Eigen::VectorXd::Zero(nY);
  };
  // The steps (dx, dy) a singularity's point may take: ±1 in each coordinate with a handle.
  auto steps = [](const Handles& h) {
    std::vector<std::pair<int, int>> out;
    for (int dx = h.u >= 0 ? -1 : 0; dx <= (h.u >= 0 ? 1 : 0); ++dx)
      for (int dy = h.v >= 0 ? -1 : 0; dy <= (h.v >= 0 ? 1 : 0); ++dy) out.emplace_back(dx, dy);
    return out;
  };
  auto closes_step = [&](const Handles& h, int dx, int dy) { return h.u >= 0 ? closes_segment(h.u, dx, h.v, dy) : closes_segment(h.v, dy); };
  auto take_step = [&](const Handles& h, int dx, int dy) {
    if (h.u >= 0) value[h.u] += dx;
    if (h.v >= 0) value[h.v] += dy;
  };
  std::vector<char> tried(nCone, 0);
  // At most this many singularities tried (two solves each): on a map folded at large (far more singularities
  // than the target's squares can separate) the search would otherwise cost a solve pair per singularity.
  int searches_left = 64 + nV / 500;
  for (int k = 0; k < nCone && searches_left > 0; ++k) {
    const int v = out.cones[k];
    if (tried[k] || !ring_is_bad(v)) continue;
    Handles h = cone_handles(k);
    if (!h.movable()) continue;
    tried[k] = 1;
    --searches_left;
    // The solution is affine in the two values: y + dx·g_u + dy·g_v, with g_j the response to a unit change of
    // fixed value j (two solves with the current factorization, instead of one per candidate).
    respond(h);
    const Eigen::VectorXd y0 = y;
    const EnergyAlong energy = through_schur ? energy_of_handles(y0, h.u, h.v) : energy_along(y0, h.gu, h.gv);
    std::pair<int, double> best{std::numeric_limits<int>::max(), std::numeric_limits<double>::infinity()};
    Eigen::Vector2d step(0, 0);
    for (auto [dx, dy] : steps(h)) {
      if (closes_step(h, dx, dy)) continue;
      y = y0 + dx * h.gu + dy * h.gv;
      corner_uv();
      const std::pair<int, double> score{count_folds() + (ring_is_bad(v) ? 1 : 0), energy(dx, dy)};
      if (score < best) best = score, step = Eigen::Vector2d(dx, dy);
    }
    y = y0 + step.x() * h.gu + step.y() * h.gv;
    take_step(h, static_cast<int>(step.x()), static_cast<int>(step.y()));
    corner_uv();
    if (step.squaredNorm() > 0) ++q.cones_moved;
    k = -1;  // a move changes the others' rings: look again from the first untried one
  }
  // Then the other integers a folded or degenerate face depends on (an iso-line rounded onto its neighbour, a
  // translation): each, once, tries ±1, kept when it leaves fewer folds (the solution is affine in it: one solve).
  {
    std::vector<char> is_cone_value(nY, 0), seen(nY, 0);
    for (int k = 0; k < nCone; ++k)
      for (int c = 0; c < 2; ++c)
        if (!elim.eliminated(cone0 + 2 * k + c)) is_cone_value[free_index[cone0 + 2 * k + c]] = 1;
    int budget = std::min(400, 64 + nV / 500);  // candidate integers tried in all (a solve each)
    for (int f = 0; f < nF && budget > 0; ++f) {
      if (!folded(f)) continue;
      std::vector<int> candidates;
      for (int i = 0; i < 3; ++i)
        for (int c = 0; c < 2; ++c)
          for (Eigen::SparseMatrix<double, Eigen::RowMajor>::InnerIterator it(P_rows, 2 * wedge[3 * f + i] + c); it; ++it) {
            const int j = static_cast<int>(it.col());
            if (fixed[j] && !is_cone_value[j] && !seen[j]) seen[j] = 1, candidates.push_back(j);
          }
      for (int j : candidates) {
        if (budget-- <= 0 || !folded(f)) break;
        const Eigen::VectorXd y0 = y, gj = response(j);
        int fewest = count_folds(), step = 0;
        for (int d : {-1, 1}) {
          if (closes_segment(j, d)) continue;
          y = y0 + d * gj;
          corner_uv();
          if (const int folds = count_folds(); folds < fewest) fewest = folds, step = d;
        }
        y = y0 + step * gj;
        value[j] += step;
        corner_uv();
        if (step != 0) ++q.integers_moved;
      }
    }
  }
  q.folds_rounded = count_folds();
  q.seconds_rounding = linalg::seconds_since(t2);

  // --- Stiffening, then untangling: the folds left opened locally, every integer held (src/quad/untangle.h) ---
  // Stiffening (global re-solves) first, because it would undo local work. Then around each folded or
  // degenerate face, the real unknowns of the wedges within `rings` rings become the variables of the barrier
  // energy of Garanzha et al. 2021, the rest of the map held; its energy covers every face those unknowns
  // move, so that no new fold appears. Kept only when the map is better after it (Badness); the region grows
  // when a fold is left; singularities whose rings cannot open are moved to a neighbouring integer point.
  const auto t3 = linalg::Clock::now();
  std::vector<int> wedge_corner_start(W + 1, 0), wedge_corners(3 * nF);
  for (int c = 0; c < 3 * nF; ++c) ++wedge_corner_start[wedge[c] + 1];
  for (int w = 0; w < W; ++w) wedge_corner_start[w + 1] += wedge_corner_start[w];
  {
    std::vector<int> next(wedge_corner_start.begin(), wedge_corner_start.end() - 1);
    for (int c = 0; c < 3 * nF; ++c) wedge_corners[next[wedge[c]]++] = c;
  }
  // Per interior vertex: whether its (u, v) corner angles fail to sum to 2π(1 − k) (k its index, 0 off the
  // singularities). An unfolded ring can still wind around its vertex once too often or too few times, which
  // would give the quad mesh a vertex of another valence (or one more irregular vertex).
  std::vector<double> expected_angle(nV, 2 * kPi);
  for (int i = 0; i < nCone; ++i) expected_angle[out.cones[i]] = 2 * kPi * (1 - out.cone_index[i] / 4.0);
  for (int v = 0; v < nV; ++v)
    if (boundary_quarters[v] > 0) expected_angle[v] = boundary_quarters[v] * kPi / 2;
  // With every integer whole, a ring's angles sum to 2π(1 − k) up to whole turns (the transitions rotate by
  // quarter turns that add up to the index): the test tells whole turns apart, the rough atan2 is enough.
  // At a boundary vertex between aligned edges, the same with the angle between them.
  auto checks_winding = [&](int v) { return t.is_interior_vertex(v) || boundary_quarters[v] > 0; };
  auto winds_wrong = [&](int v) { return checks_winding(v) && std::abs(uv_angle_sum(v, true) - expected_angle[v]) > 1; };
  auto cone_winds_wrong = [&](int i) { return winds_wrong(out.cones[i]); };
  // The folded faces and the interior vertices winding wrong, over the whole map or over a part of it (faces and
  // vertices given): a change of the map that moves only some faces compares the badness of those faces and of
  // their vertices, the rest being the same before and after.
  struct Badness {
    int folds = 0;
    std::vector<int> wrong;  // the vertices winding wrong, ascending
    int total() const { return folds + static_cast<int>(wrong.size()); }
    // Better: fewer problems in all, and no vertex winding wrong that did not before.
    bool better_than(const Badness& before) const {
      return std::includes(before.wrong.begin(), before.wrong.end(), wrong.begin(), wrong.end()) && total() < before.total();
    }
  };
  // Over the whole map: on several threads on a large mesh (a winding per vertex, read-only).
  std::vector<char> wrong_scratch(nV, 0);
  auto badness = [&]() {
    Badness b;
    b.folds = count_folds();
#pragma omp parallel for schedule(static) if (nF > linalg::kParallelMinElements)
    for (int v = 0; v < nV; ++v) wrong_scratch[v] = winds_wrong(v);
    for (int v = 0; v < nV; ++v)
      if (wrong_scratch[v]) b.wrong.push_back(v);
    return b;
  };
  auto badness_of = [&](const std::vector<int>& faces, const std::vector<int>& vertices) {
    Badness b;
    for (int f : faces) b.folds += folded(f);
    for (int v : vertices)
      if (winds_wrong(v)) b.wrong.push_back(v);
    return b;
  };
  // (u, v) of the corners of `faces` only, from y (corner_uv does every corner).
  auto corner_uv_of = [&](const std::vector<int>& faces) {
    for (int f : faces)
      for (int c = 3 * f; c < 3 * f + 3; ++c)
        for (int r = 0; r < 2; ++r) {
          double value_r = 0;
          for (Eigen::SparseMatrix<double, Eigen::RowMajor>::InnerIterator it(P_rows, 2 * wedge[c] + r); it; ++it) value_r += it.value() * y[it.col()];
          out.uv(c, r) = value_r;
        }
  };
  // Untangles the region within `rings` rings of the vertices `seeds`; kept when the whole map has fewer folds
  // after it (returns true), else undone.
  // Bounds on the untangling's work, so that a map that cannot be untangled (a singularity of index ≥ 1 folds by
  // necessity) costs little: at most this many regions and this much work in all, and none when the folds are
  // more than a small share of the faces (the map is then wrong at large, not locally).
  // A map that another map follows gets `untangle_share` of them (kUntangleShareFollowed, parametrize).
  int regions_left = static_cast<int>(untangle_share * (64 + nF / 256)), relief_left = static_cast<int>(untangle_share * (64 + nF / 1024));
  double work_left = untangle_share * (2000.0 * nF + 2e7);  // faces × L-BFGS steps, over all regions
  const int too_many_folds = std::max(100, nF / 200);
  std::vector<char> inside_scratch(nV, 0), moved_scratch(nF, 0);
  std::vector<int> variable_scratch(nY, -1);
  // `restart`: the untangling starts from the region's least squares (quad::least_squares_start), not from the
  // map as it is.
  // Σ area · σ_max/σ_min over `faces` (a flat or folded face counts as kReliefFlat).
  auto stretch_of = [&](const std::vector<int>& faces) {
    double sum = 0;
    for (int f : faces) {
      const double ratio = distortion(f);
      sum += face_area[f] * (folded(f) || !std::isfinite(ratio) ? kReliefFlat : std::min(ratio, kReliefFlat));
    }
    return sum;
  };
  // `pass`: `open` untangles folds (kept when the region is better, Badness::better_than). `relieve`: the
  // region holds no fold but a face left nearly flat; the barrier runs until every face has
  // det J > kReliefDeterminant. `shape`: the barrier's shape term alone, Σ area · |J|² / χ(det J, ε) (scale-free,
  // so it lowers σ_max/σ_min, not the size), for the budget of rounds. Relief and shape are kept when no face folds
  // that did not, no vertex winds wrong that did not, and the region's stretch (stretch_of) is lower.
  enum class Pass { open, relieve, shape };
  std::vector<int> shape_keep_out;  // vertices the shape pass leaves where they are (never in its region)
  auto untangle_around = [&](const std::vector<int>& seeds, int rings, bool restart = false, Pass pass = Pass::open) {
    const bool by_stretch = pass != Pass::open;  // kept by the stretch rule (relief and shape), not Badness
    if (pass == Pass::relieve ? relief_left <= 0 : pass == Pass::open && (regions_left <= 0 || work_left <= 0)) return false;
    if (pass == Pass::relieve) --relief_left;
    if (pass == Pass::open) --regions_left;
    std::vector<char>& inside = inside_scratch;
    std::vector<int> frontier, region;
    if (pass == Pass::shape)
      for (int v : shape_keep_out) inside[v] = 1;
    for (int v : seeds)
      if (!inside[v]) inside[v] = 1, frontier.push_back(v), region.push_back(v);
    for (int r = 0; r < rings; ++r) {
      std::vector<int> next;
      for (int v : frontier)
        for (int j = t.vertex_face_offsets[v]; j < t.vertex_face_offsets[v + 1]; ++j)
          for (int k = 0; k < 3; ++k)
            if (const int u = t.F(t.vertex_faces[j], k); !inside[u]) inside[u] = 1, next.push_back(u), region.push_back(u);
      frontier = std::move(next);
    }
    // The corners at the region's vertices, in order; their real free unknowns are the variables, and the faces
    // those move carry the energy.
    std::vector<int> corners;
    for (int v : region)
      for (int j = t.vertex_face_offsets[v]; j < t.vertex_face_offsets[v + 1]; ++j)
        corners.push_back(3 * t.vertex_faces[j] + t.corner_of(t.vertex_faces[j], v));
    std::sort(corners.begin(), corners.end());
    std::vector<int>& variable = variable_scratch;
    std::vector<int> variables;
    for (int v : region) inside[v] = 0;  // the scratch arrays are left clear for the next region
    if (pass == Pass::shape)
      for (int v : shape_keep_out) inside[v] = 0;
    for (int c : corners) {
      for (int r = 0; r < 2; ++r)
        for (Eigen::SparseMatrix<double, Eigen::RowMajor>::InnerIterator it(P_rows, 2 * wedge[c] + r); it; ++it) {
          const int j = static_cast<int>(it.col());
          if (!is_integer[j] && variable[j] < 0) variable[j] = static_cast<int>(variables.size()), variables.push_back(j);
        }
    }
    if (variables.empty()) return false;
    std::vector<char>& moved = moved_scratch;
    std::vector<int> faces;
    for (int j : variables)
      for (Eigen::SparseMatrix<double>::InnerIterator it(P, j); it; ++it) {
        const int w = static_cast<int>(it.row()) / 2;
        if (w >= W) continue;
        for (int k = wedge_corner_start[w]; k < wedge_corner_start[w + 1]; ++k)
          if (const int f = wedge_corners[k] / 3; !moved[f]) moved[f] = 1, faces.push_back(f);
      }
    for (int f : faces) moved[f] = 0;
    std::vector<int> touched;  // the vertices of the faces that move
    for (int f : faces)
      for (int k = 0; k < 3; ++k) touched.push_back(t.F(f, k));
    std::sort(touched.begin(), touched.end());
    touched.erase(std::unique(touched.begin(), touched.end()), touched.end());
    const Badness before = badness_of(faces, touched);
    const double stretch_before = by_stretch ? stretch_of(faces) : 0.0;
    quad::UntangleProblem problem;
    problem.num_variables = static_cast<int>(variables.size());
    for (int f : faces) {
      const Eigen::Vector2d X(std::cos(theta[f]), std::sin(theta[f])), Y(-X.y(), X.x());
      std::array<Eigen::Vector2d, 3> gradient;
      std::array<std::array<quad::AffineForm, 2>, 3> corner;
      for (int i = 0; i < 3; ++i) {
        // Relative to the ideal s·(X Y)ᵀ: the field's unit size, also where the sizing changed the target (the
        // untangling only opens folds; measured against the sized target it opened fewer, BENCHMARKS.md).
        gradient[i] = Eigen::Vector2d(grad[f][i].dot(X), grad[f][i].dot(Y)) / s;
        for (int r = 0; r < 2; ++r)
          for (Eigen::SparseMatrix<double, Eigen::RowMajor>::InnerIterator it(P_rows, 2 * wedge[3 * f + i] + r); it; ++it) {
            const int j = static_cast<int>(it.col());
            if (variable[j] >= 0) corner[i][r].terms.emplace_back(variable[j], it.value());
            else corner[i][r].constant += it.value() * y[j];
          }
      }
      problem.area.push_back(face_area[f]);
      problem.gradient.push_back(gradient);
      problem.corner.push_back(std::move(corner));
    }
    for (int j : variables) variable[j] = -1;
    Eigen::VectorXd z(problem.num_variables);
    for (size_t k = 0; k < variables.size(); ++k) z[static_cast<int>(k)] = y[variables[k]];
    const Eigen::VectorXd z0 = z;
    if (restart) z = quad::least_squares_start(problem, z);
    const quad::UntangleResult result = pass == Pass::shape ? quad::untangle(problem, z, 1e-3, 0.0, kShapeRounds, kShapeSteps)
                                                            : quad::untangle(problem, z, by_stretch ? kReliefDeterminant : 1e-3, 0.5, 30, 30);
    if (!by_stretch) work_left -= static_cast<double>(faces.size()) * (result.inner_iterations + result.outer_iterations);
    for (size_t k = 0; k < variables.size(); ++k) y[variables[k]] = z[static_cast<int>(k)];
    corner_uv_of(faces);
    const Badness after = badness_of(faces, touched);
    if (by_stretch ? after.folds <= before.folds && std::includes(before.wrong.begin(), before.wrong.end(), after.wrong.begin(), after.wrong.end()) &&
                      stretch_of(faces) < stretch_before
                : after.better_than(before)) {
      if (pass == Pass::shape) q.shaped_faces = static_cast<int>(faces.size());
      if (pass == Pass::relieve) ++q.relieved_regions;
      if (pass == Pass::open) ++q.untangling_regions;
      return true;
    }
    for (size_t k = 0; k < variables.size(); ++k) y[variables[k]] = z0[static_cast<int>(k)];
    corner_uv_of(faces);
    return false;
  };
  std::vector<int> cone_of(nV, -1);
  for (int k = 0; k < nCone; ++k) cone_of[out.cones[k]] = k;
  // Each folded face in turn (the first still folded), in regions of 2, 4 and 8 rings.
  // Faces within 2 rings of a singularity of index ≥ 1 are left: its (u, v) angle 2π(1 − k) ≤ 0 needs folds.
  std::vector<char> hopeless(nF, 0);
  for (int i = 0; i < nCone; ++i) {
    if (out.cone_index[i] < 4) continue;
    const int v = out.cones[i];
    for (int j = t.vertex_face_offsets[v]; j < t.vertex_face_offsets[v + 1]; ++j)
      for (int k = 0; k < 3; ++k) {
        const int u = t.F(t.vertex_faces[j], k);
        for (int l = t.vertex_face_offsets[u]; l < t.vertex_face_offsets[u + 1]; ++l) hopeless[t.vertex_faces[l]] = 1;
      }
  }
  auto untangle_faces = [&]() {
    std::vector<char> given_up(hopeless);
    for (int f = 0; f < nF && regions_left > 0 && work_left > 0; ++f) {
      if (given_up[f] || !folded(f)) continue;
      check_cancelled();
      for (int rings : {2, 4, 8})
        if (untangle_around({t.F(f, 0), t.F(f, 1), t.F(f, 2)}, rings) && !folded(f)) break;
      if (folded(f)) given_up[f] = 1;
      f = -1;  // the regions overlap: look again from the first face
    }
  };
  // Where a fold is left within 2 rings of a singularity whose integer point is free, that point is moved to
  // its neighbours (the solution is affine in it: two solves), the `candidates` that leave the fewest folds
  // before untangling first, the region around it untangled; the first that leaves fewer folds is kept.
  auto move_cones = [&](size_t candidates, bool restart = false) {
    std::vector<char> cone_tried(nCone, 0);
    std::vector<int> trouble;  // folded faces, and a face of each singularity whose ring winds wrong
    for (int f = 0; f < nF; ++f)
      if (folded(f)) trouble.push_back(f);
    for (int i = 0; i < nCone; ++i)
      if (cone_winds_wrong(i)) trouble.push_back(t.vertex_faces[t.vertex_face_offsets[out.cones[i]]]);
    if (restart)  // and a face of each other vertex winding wrong (a cone's turn passed to it)
      for (int v = 0; v < nV; ++v)
        if (cone_of[v] < 0 && winds_wrong(v)) trouble.push_back(t.vertex_faces[t.vertex_face_offsets[v]]);
    for (int f : trouble) {
      if (regions_left <= 0 || work_left <= 0) return;
      if (hopeless[f]) continue;
      std::vector<int> near, ring{t.F(f, 0), t.F(f, 1), t.F(f, 2)};
      for (int step = 0; step < 2; ++step) {
        std::vector<int> next;
        for (int v : ring)
          for (int j = t.vertex_face_offsets[v]; j < t.vertex_face_offsets[v + 1]; ++j)
            for (int k = 0; k < 3; ++k) next.push_back(t.F(t.vertex_faces[j], k));
        std::sort(next.begin(), next.end());
        next.erase(std::unique(next.begin(), next.end()), next.end());
        ring = std::move(next);
      }
      for (int v : ring)
        if (const int c = cone_of[v]; c >= 0 && !cone_tried[c]) near.push_back(c);
      for (int c : near) {
        if (cone_tried[c]) continue;
        Handles h = cone_handles(c);
        if (!h.movable()) continue;  // its point is not free
        cone_tried[c] = 1;
        check_cancelled();
        respond(h);
        const Eigen::VectorXd y0 = y;
        const EnergyAlong energy = energy_along(y0, h.gu, h.gv);
        const Badness before = badness();
        std::vector<std::tuple<int, double, int, int>> order;
        for (auto [dx, dy] : steps(h)) {
          if ((dx == 0 && dy == 0) || closes_step(h, dx, dy)) continue;
          y = y0 + dx * h.gu + dy * h.gv;
          corner_uv();
          order.emplace_back(count_folds(), energy(dx, dy), dx, dy);
        }
        std::sort(order.begin(), order.end());
        bool kept = false;
        for (size_t k = 0; k < std::min(candidates, order.size()) && !kept; ++k) {
          const auto [folds, e, dx, dy] = order[k];
          y = y0 + dx * h.gu + dy * h.gv;
          corner_uv();
          for (int rings : {4, 8}) {
            untangle_around({out.cones[c]}, rings, restart);
            if (!restart || badness().total() < before.total()) break;
          }
          if (badness().better_than(before)) {
            take_step(h, dx, dy);
            ++q.cones_moved;
            kept = true;
          }
        }
        if (!kept) {
          y = y0;
          corner_uv();
        }
      }
    }
  };
  auto untangle_all = [&]() {
    for (size_t candidates : {3, 8}) {
      untangle_faces();
      if (badness().total() == 0) return;
      move_cones(candidates);
    }
    untangle_faces();
  };
  // A ring that winds once too often beside one that winds once too few (a cone's turn passed to a neighbour)
  // is fold-free, so the barrier keeps it: around each vertex winding wrong, with those of its neighbours, the
  // region (2, 4, 8 rings) is untangled again from its least squares, which winds as the field does.
  auto rewind = [&]() {
    std::vector<char> tried(nV, 0);
    for (int v = 0; v < nV && regions_left > 0 && work_left > 0; ++v) {
      if (tried[v] || !winds_wrong(v)) continue;
      check_cancelled();
      std::vector<int> seeds{v};
      for (int j = t.vertex_face_offsets[v]; j < t.vertex_face_offsets[v + 1]; ++j)
        for (int k = 0; k < 3; ++k)
          if (const int u = t.F(t.vertex_faces[j], k); u != v && winds_wrong(u)) seeds.push_back(u);
      std::sort(seeds.begin(), seeds.end());
      seeds.erase(std::unique(seeds.begin(), seeds.end()), seeds.end());
      for (int u : seeds) tried[u] = 1;
      for (int rings : {2, 4, 8})
        if (untangle_around(seeds, rings, true) && !winds_wrong(v)) {
          ++q.rewound_regions;
          break;
        }
    }
    // Still wrong: the singularities nearby are moved to a neighbouring integer point, each try untangled from
    // its least squares.
    if (!badness().wrong.empty()) move_cones(8, true);
  };
  auto untangle_folds = [&]() {
    const int folds_before = count_folds();
    if (folds_before > too_many_folds) return;
    untangle_all();
    q.untangled_faces += folds_before - count_folds();
    rewind();
  };
  // After the rounding, two rounds without a fifth fewer folds end it, and so do 8 folds or fewer: the untangling
  // below opens what is left locally (a region each), and each round of the stiffening is a factorization.
  stiffen(options.max_stiffening_rounds, 2, 0.8, 8);
  q.seconds_stiffening = linalg::seconds_since(t3);
  const auto t5 = linalg::Clock::now();
  untangle_folds();
  // Relief: a face can be left nearly flat without folding (a corner at a singularity opened to about π, its
  // σ_max/σ_min in the thousands), which alone moves the area-weighted mean ratio by a whole unit. Around each
  // face above kReliefRatio, worst (area · ratio) first, the region of 2, then 4 rings is opened with the barrier
  // (untangle_around with Pass::relieve), kept only when it stretches less and folds and winds no worse.
  {
    std::vector<std::pair<double, int>> strained;
    for (int f = 0; f < nF; ++f)
      if (const double ratio = distortion(f); !folded(f) && !(collapsed[f]) && ratio > kReliefRatio)
        strained.emplace_back(-face_area[f] * std::min(ratio, kReliefFlat), f);
    std::sort(strained.begin(), strained.end());
    for (auto [key, f] : strained) {
      if (relief_left <= 0) break;
      if (folded(f) || !(distortion(f) > kReliefRatio)) continue;  // relieved with an earlier one
      check_cancelled();
      for (int rings : {2, 4})
        if (untangle_around({t.F(f, 0), t.F(f, 1), t.F(f, 2)}, rings, false, Pass::relieve)) break;
    }
  }
  // The shape pass: the least squares follow the field, and where the integers do not fit it (feature lines a
  // whole number of units apart that the field's own lengths put elsewhere, thin walls, strips) the faces stretch
  // along one direction; here they may also turn a little. Only on a map past the distortion goal: within it the
  // least squares' map, which follows the field more closely, is kept (and the pass's cost saved). None when the
  // map is folded at large (it will be made again or refused); where a few faces fold or vertices wind wrong, the
  // faces around them stay as the untangling left them (the barrier would spend its steps there, and the region
  // could not be kept).
  if (options.shape && count_folds() <= too_many_folds && mean_ratio() > kMapDistortionGoal) {
    std::vector<int> seeds;
    std::vector<char> taken(nV, 0);  // kept out, or a seed already
    // Kept out: the vertices winding wrong and those of folded faces, with the ring of faces around them.
    std::vector<int> trouble = badness().wrong;
    for (int f = 0; f < nF; ++f)
      if (folded(f))
        for (int k = 0; k < 3; ++k) trouble.push_back(t.F(f, k));
    for (int v : trouble)
      for (int j = t.vertex_face_offsets[v]; j < t.vertex_face_offsets[v + 1]; ++j)
        for (int k = 0; k < 3; ++k)
          if (const int u = t.F(t.vertex_faces[j], k); !taken[u]) taken[u] = 1, shape_keep_out.push_back(u);
    // Seeds: the vertices of the faces stretched past the goal.
    for (int f = 0; f < nF; ++f)
      if (const double ratio = distortion(f); !folded(f) && !collapsed[f] && ratio > kMapDistortionGoal)
        for (int k = 0; k < 3; ++k)
          if (const int v = t.F(f, k); !taken[v]) taken[v] = 1, seeds.push_back(v);
    check_cancelled();
    if (!seeds.empty()) untangle_around(seeds, kShapeRings, false, Pass::shape);
  }
  q.seconds_untangling = linalg::seconds_since(t5);

  // --- What the map promises, checked on the result --------------------------------------------------------
  const auto t4 = linalg::Clock::now();
  std::vector<char> tiny(t.components.size(), 0);  // ParamQuality::tiny_components
  {
    const std::vector<double> squares = component_squares();
    for (size_t c = 0; c < squares.size(); ++c)
      if (squares[c] < 1) {
        tiny[c] = 1;
        if (q.tiny_components++ == 0) q.first_tiny_face = t.components[c].first_face, q.first_tiny_squares = squares[c];
      }
  }
  double mapped_area = 0;  // of the faces neither flipped nor degenerate: the mean distortion's weights
  for (int f = 0; f < nF; ++f) {
    const double a = uv_area(f);
    if (collapsed[f] && !folded(f)) {
      ++q.collapsed_faces;
      continue;
    }
    const double ratio = distortion(f);
    q.max_distortion = std::max(q.max_distortion, ratio);
    const bool flipped = a < -1e-12 * face_area[f] * s * s, degenerate = !flipped && !(a > 1e-12 * face_area[f] * s * s);
    if (flipped || degenerate) {
      ++(flipped ? q.flipped_faces : q.degenerate_faces);
      if (q.first_flipped.size() < 10) q.first_flipped.push_back(f);
      q.tiny_component_folds += tiny[t.face_component[f]];
    } else if (std::isfinite(ratio)) {
      q.mean_distortion += g.face_area[f] * ratio;
      mapped_area += g.face_area[f];
    }
    q.unit_squares += a;
  }
  if (mapped_area > 0) q.mean_distortion /= mapped_area;
  for (int i = 0; i < nCut; ++i) {
    const int e = out.cut_edges[i];
    const int L = t.edge_faces(e, 0), R = t.edge_faces(e, 1), r = out.rotation[e];
    Eigen::Vector2d d[2];
    for (int end = 0; end < 2; ++end) {
      const int v = t.edge_vertices(e, end);
      const Eigen::Vector2d pL = out.uv.row(3 * L + t.corner_of(L, v)).transpose(), pR = out.uv.row(3 * R + t.corner_of(R, v)).transpose();
      d[end] = pR - rotate(r, pL);
    }
    const Eigen::Vector2d whole(std::round(d[0].x()), std::round(d[0].y()));
    out.translation(e, 0) = static_cast<int>(whole.x()), out.translation(e, 1) = static_cast<int>(whole.y());
    q.max_transition_residual = std::max({q.max_transition_residual, (d[0] - whole).lpNorm<Eigen::Infinity>(), (d[1] - whole).lpNorm<Eigen::Infinity>()});
  }
  for (int i = 0; i < nCone; ++i) {
    const int v = out.cones[i];
    for (int j = t.vertex_face_offsets[v]; j < t.vertex_face_offsets[v + 1]; ++j) {
      const int f = t.vertex_faces[j], k = t.corner_of(f, v);
      q.max_cone_offset = std::max({q.max_cone_offset, whole_offset(out.uv(3 * f + k, 0)), whole_offset(out.uv(3 * f + k, 1))});
    }
  }
  // Every interior vertex's angle sum against 2π(1 − k), once: the cones' errors and the windings (and at the
  // boundary vertices between aligned edges, against the angle between them).
  for (int v = 0; v < nV; ++v) {
    if (!checks_winding(v)) continue;
    const double error = std::abs(uv_angle_sum(v) - expected_angle[v]);
    if (singular[v]) q.max_cone_angle_error = std::max(q.max_cone_angle_error, error);
    q.winding_errors += error > 1e-6;
  }
  for (int i = 0; i < nAligned; ++i) {
    const auto [e, f] = aligned[i];
    const int c = aligned_coordinate[i];
    const double a = out.uv(3 * f + t.corner_of(f, t.edge_vertices(e, 0)), c), bb = out.uv(3 * f + t.corner_of(f, t.edge_vertices(e, 1)), c);
    q.max_alignment_error = std::max({q.max_alignment_error, whole_offset(a), std::abs(a - bb)});
  }
  q.seamless = q.max_transition_residual < 1e-6 && q.max_cone_offset < 1e-6 && q.max_alignment_error < 1e-6 && q.non_unimodular == 0;
  q.seconds_check = linalg::seconds_since(t4);
  return out;
}

int problems(const ParamQuality& q) { return q.flipped_faces + q.degenerate_faces + q.winding_errors; }

// Whether `other` is to be kept over `best`: seamless, with fewer problems, or as few and less stretched.
bool better_map(const Parametrization& other, const Parametrization& best) {
  const int p = problems(other.quality), b = problems(best.quality);
  return other.quality.seamless && (p < b || (p == b && other.quality.mean_distortion < best.quality.mean_distortion));
}

// The sizing moves the rounding's integers: where its map keeps problems, the maps of the other sizings (the
// map's and the connection's, the one not asked for first) and of the field's unit size are made too, until one
// has none, and the one with the fewest problems kept; the retries try the map's sizing and the unit size.
std::vector<ParamOptions> size_variants(const ParamOptions& options) {
  std::vector<ParamOptions> variants{options};
  if (options.sizing == Sizing::uniform) return variants;
  // The other sizing, unless it would size nothing (the map's with no rounds).
  const Sizing other = options.sizing == Sizing::map ? Sizing::connection : Sizing::map;
  if (other == Sizing::connection || options.sizing_rounds > 0) {
    variants.push_back(options);
    variants.back().sizing = other;
  }
  variants.push_back(options);
  variants.back().sizing = Sizing::uniform;
  return variants;
}

// The untangling's share for sizing variant v of `count` (parametrize_at): each but the last untangles on
// kUntangleShareFollowed of the bounds (the next sizing is the cheaper remedy for the folds a long untangling would
// fight), the last on options.untangle_share.
double variant_share(size_t v, size_t count, const ParamOptions& options) {
  return v + 1 < count ? kUntangleShareFollowed : options.untangle_share;
}

// The near-miss retries from `best`, the first map (or its unit-size variant) with the search's time so far.
Parametrization retry_near_miss(const FieldDesigner& designer, const Design& design, const ParamOptions& options, Parametrization best,
                                linalg::Clock::time_point start, double seconds_before) {
  const int first_factorizations = best.quality.first_factorizations;
  int retry_factorizations = 0;
  const int near_miss = std::max(16, best.quality.faces / 20000);
  const bool necessary = folds_necessary(best);
  std::vector<ParamOptions> variants = size_variants(options);
  variants.erase(std::remove_if(variants.begin(), variants.end(), [](const ParamOptions& o) { return o.sizing == Sizing::connection; }),
                 variants.end());  // the map's sizing and the unit size
  const int n = static_cast<int>(variants.size());
  int attempts = best.quality.attempts, retried = 0;
  best.quality.seconds_retries = 0;
  // Still with problems: the sizing variants again with the second rounding, which also keeps the widths of strips
  // between parallel aligned lines open (parametrize_at). Not first: where the first rounding has no problems its
  // map is kept as it was; where it has, this one often has fewer (plates with holes near their edges, thin walls).
  // None when the first of them finds no strip (its map would be the first rounding's); none in a screening.
  const std::vector<ParamOptions> sized = size_variants(options);
  for (size_t v = 0; v < sized.size() && problems(best.quality) > 0 && options.retries > 0 && !necessary; ++v) {
    Parametrization other = parametrize_at(designer, design, sized[v], 1.0, variant_share(v, sized.size(), options), true);
    ++attempts;
    if (other.quality.strip_widths == 0) break;
    if (better_map(other, best)) best = std::move(other);
  }
  const bool keep_strips = best.quality.strip_widths > 0;  // the rounding of the map kept
  if (problems(best.quality) > 0 && problems(best.quality) <= near_miss && !necessary)
    for (double scale : {0.97, 1.03, 0.94, 1.06})
      for (const ParamOptions& variant : variants) {
        // At most `retries` edge lengths, and while they have cost less than twice the first per variant, counted
        // in factorizations (each a solve's main cost; unlike wall time, the same on every machine, so the same map
        // everywhere).
        if (problems(best.quality) == 0 || retried >= options.retries * n || retry_factorizations >= 2 * n * first_factorizations) break;
        Parametrization other = parametrize_at(designer, design, variant, scale, 1.0, keep_strips);
        ++attempts, ++retried;
        retry_factorizations += other.quality.factorizations;
        if (other.quality.seamless && problems(other.quality) < problems(best.quality)) best = std::move(other);
      }
  best.quality.attempts = attempts;
  best.quality.first_factorizations = first_factorizations;
  best.quality.seconds_retries = seconds_before + linalg::seconds_since(start) - best.quality.seconds_total();  // the attempts not kept
  return best;
}

}  // namespace

// A map left with problems is made again with the second rounding (the widths of strips kept, retry_near_miss).
// The rounding's outcome is sensitive to the scale: a map left with a few folds or wrong windings (a near miss)
// is made again at quad edge lengths 3 % and 6 % shorter and longer (while those attempts have cost less than
// twice the first), the first without any kept, else the one with the fewest. Not when a singularity has index ≥ 1 (its folds are necessary) or the problems are many (the
// map is wrong at large: other scales would not mend it).
Parametrization parametrize(const FieldDesigner& designer, const Design& design, const ParamOptions& options) {
  const auto start = linalg::Clock::now();
  const std::vector<ParamOptions> variants = size_variants(options);
  auto share = [&](size_t v) { return variant_share(v, variants.size(), options); };
  Parametrization best = parametrize_at(designer, design, options, 1.0, share(0));
  const int first_factorizations = best.quality.factorizations;
  int attempts = 1;
  for (size_t v = 1; v < variants.size(); ++v) {
    // A map without problems past the distortion goal tries the other sized variant too, for the lower ratio.
    const bool stretched = best.quality.mean_distortion > kMapDistortionGoal && variants[v].sizing != Sizing::uniform;
    if (problems(best.quality) == 0 && !stretched) break;
    Parametrization other = parametrize_at(designer, design, variants[v], 1.0, share(v));
    ++attempts;
    if (better_map(other, best)) best = std::move(other);
  }
  best.quality.attempts = attempts;
  best.quality.first_factorizations = first_factorizations;
  return retry_near_miss(designer, design, options, std::move(best), start, 0.0);
}

Parametrization parametrize_retries(const FieldDesigner& designer, const Design& design, const ParamOptions& options,
                                    const Parametrization& screened) {
  if (screened.quality.first_factorizations <= 0) throw Error("param: the map to resume was not made by parametrize");
  return retry_near_miss(designer, design, options, screened, linalg::Clock::now(), screened.quality.seconds_total());
}

bool folds_necessary(const Parametrization& param) {
  return std::any_of(param.cone_index.begin(), param.cone_index.end(), [](int n) { return n >= 4; });  // index n/4 ≥ 1
}

Eigen::MatrixXd input_corner_uv(const Parametrization& param, const Topology& topology, const MatrixX3i& F) {
  if (F.rows() != topology.num_faces || param.uv.rows() != 3 * F.rows()) throw Error("param: the faces do not belong to the map's mesh");
  Eigen::MatrixXd out(F.rows(), 6);
  for (int f = 0; f < F.rows(); ++f)
    for (int k = 0; k < 3; ++k) {
      const int c = topology.corner_of(f, F(f, k));
      if (c < 0) throw Error("param: face " + std::to_string(f) + " does not match the map's mesh");
      out(f, 2 * k) = param.uv(3 * f + c, 0), out(f, 2 * k + 1) = param.uv(3 * f + c, 1);
    }
  return out;
}

const char* sizing_name(Sizing sizing) {
  switch (sizing) {
    case Sizing::map:
      return "map";
    case Sizing::connection:
      return "connection";
    default:
      return "uniform";
  }
}

Sizing sizing_from_name(const std::string& name) {
  for (Sizing s : {Sizing::map, Sizing::connection, Sizing::uniform})
    if (name == sizing_name(s)) return s;
  throw Error("sizing: expected 'map', 'connection' or 'uniform', not '" + name + "'");
}

std::string param_warning(const Parametrization& param) {
  const ParamQuality& q = param.quality;
  std::ostringstream s;
  if (!q.seamless) {
    s << "the map is not exactly seamless (transition residual " << q.max_transition_residual << ", cone offset " << q.max_cone_offset
      << ", alignment error " << q.max_alignment_error << ", " << q.non_unimodular << " integer relations not kept whole)";
  }
  const int bad = q.flipped_faces + q.degenerate_faces;
  if (bad > 0) {
    if (!s.str().empty()) s << "; ";
    s << bad << " of " << q.faces << " faces are flipped or degenerate in (u, v) (first: ";
    for (size_t i = 0; i < q.first_flipped.size(); ++i) s << (i ? ", " : "") << q.first_flipped[i];
    s << ")";
    if (q.max_cone_angle_error > 1e-6) s << ", folding around singularities (cone angles off by up to " << q.max_cone_angle_error << " rad)";
    s << " after " << q.stiffening_rounds << " stiffening rounds";
    if (q.tiny_component_folds < bad) s << ": a larger edge length, or singularities further apart, usually removes them";
    if (q.tiny_component_folds > 0) s << " (" << q.tiny_component_folds << " of them in components smaller than one unit square)";
    for (size_t k = 0; k < param.cones.size(); ++k)
      if (param.cone_index[k] >= 4) {
        s << "; singular vertex " << param.cones[k] << " has index " << param.cone_index[k] << "/4 >= 1: its (u, v) angle 2pi(1 - k) <= 0 "
          << "cannot be made without folding (a quad mesh needs indices below 1)";
        break;
      }
  }
  if (q.half_turn_edges > 0) {
    if (!s.str().empty()) s << "; ";
    s << "the connection turns by pi or more across " << q.half_turn_edges << " edge(s): the per-face field, which the map follows, turns by "
      << "2pi less there and shows singularities of index +1 and -1 at their ends that were not prescribed (singularities a triangle or two "
      << "apart: fewer of them, or a finer mesh there)";
  }
  if (q.tiny_components > 0) {
    if (!s.str().empty()) s << "; ";
    s << q.tiny_components << " component(s) of the mesh are smaller than one unit square (first: the one of face " << q.first_tiny_face << ", "
      << q.first_tiny_squares << " unit squares): no quad fits in them whatever the singularities; a smaller edge length, or the mesh "
      << "without them";
  }
  return s.str();
}

}  // namespace trivcon
