// SPDX-License-Identifier: MIT
// Automatic singularities from the globally smoothest field (trivcon/auto.h).
#include "trivcon/auto.h"
#include "trivcon/cancel.h"

#include <algorithm>
#include <array>
#include <cmath>
#include <complex>
#include <exception>
#include <limits>
#include <memory>
#include <queue>
#include <random>
#include <set>
#include <string>

#include "linalg/ordering.h"
#include "linalg/parallel.h"
#include "linalg/inverse_iteration.h"
#include "linalg/substitution.h"
#include "linalg/supernodal.h"
#include "linalg/symbolic.h"
#include "linalg/timing.h"
#include "field/edge_dijkstra.h"
#include "trivcon/constraints.h"
#include "trivcon/curvature.h"
#include "trivcon/design.h"
#include "trivcon/error.h"

namespace trivcon {

namespace {

using linalg::Clock;
using linalg::seconds_since;
using Complex = std::complex<double>;

double edge_length(const MatrixX3d& V, const Topology& t, int e) {
  return (V.row(t.edge_vertices(e, 1)) - V.row(t.edge_vertices(e, 0))).norm();
}

// The per-face mass and per-edge weight of docs/auto.md ("The field").
struct Weights {
  Eigen::VectorXd mass, w;
};

Weights face_weights(const MatrixX3d& V, const Topology& t, const Geometry& g) {
  Weights k;
  double total = 0;
  for (int f = 0; f < t.num_faces; ++f) total += g.face_area[f];
  if (!(total > 0) || !std::isfinite(total))
    throw Error("automatic singularities: every face of the mesh has zero area, so no field can be measured on it");
  const double floor = 1e-12 * total / t.num_faces;
  k.mass = g.mollified_area.cwiseMax(floor);
  k.w = Eigen::VectorXd::Zero(t.num_edges);
  for (int e = 0; e < t.num_edges; ++e) {
    if (t.is_boundary_edge(e)) continue;
    const double len = edge_length(V, t, e) + g.component_epsilon[t.face_component[t.edge_faces(e, 0)]];
    k.w[e] = len * len / (k.mass[t.edge_faces(e, 0)] + k.mass[t.edge_faces(e, 1)]);
  }
  return k;
}

// A_gf for neighbouring faces g ≠ f across interior edge e: −w e^{iNρ} from L to R, its conjugate back.
Complex off_diagonal(const Topology& t, const Geometry& g, const Weights& k, int N, int e, int row_face) {
  const double a = N * g.rho[e];
  const Complex r(std::cos(a), std::sin(a));
  return -k.w[e] * (row_face == t.edge_faces(e, 1) ? r : std::conj(r));
}

// The symbolic factorization of the smoothest-field matrix (its upper triangle's pattern: outer, inner;
// rows are the unknown faces face_of; src/linalg/symbolic.h) and the name of its order.
//
// Two candidate orders, analysed side by side on two threads, and the one with fewer flops (CHOLMOD's
// count, SymbolicFactor::flops) kept: AMD, and a nested dissection by the faces' centroids
// (src/linalg/ordering.h). Neither wins everywhere: on a regular grid of faces (AMD's worst case) the
// dissection needs far fewer flops; on scans it needs several times AMD's. (METIS would need fewer flops on
// both, but METIS_NodeND alone takes several times as long as either analysis here.) Small meshes, or one
// thread, take AMD alone. Both are postordered (as cholmod_analyze with postorder = 1, which this replaces).
// Supernodes are amalgamated less than CHOLMOD's default (zrelax 0.8, 0.1, 0.05): the explicit zeros that
// buys are read again by each solve and first-touched by the factorization (the factor has a sixth fewer
// entries); the factorization itself did not get measurably slower. The figures: BENCHMARKS.md, "Figures
// that were in code comments".
struct SmoothestAnalysis {
  linalg::SymbolicFactor factor;
  std::string ordering;
  bool done = false;
};

SmoothestAnalysis analyse_smoothest_matrix(const MatrixX3d& V, const Topology& t, const std::vector<int>& face_of,
                                           const std::vector<int>& outer, const std::vector<int>& inner) {
  const int n = static_cast<int>(face_of.size());
  linalg::SymbolicOptions options;
  options.zrelax = {0.4, 0.05, 0.02};
  SmoothestAnalysis candidate[2];  // by AMD, by the dissection
  candidate[0].ordering = "AMD", candidate[1].ordering = "coordinate dissection";
  const bool compare = n >= linalg::kParallelMinElements && linalg::max_threads() > 1;
  std::exception_ptr error;
#pragma omp parallel num_threads(2) if (compare)
  {
    try {
      if (omp_get_thread_num() == 0) {
        candidate[0].factor = linalg::symbolic_analysis(outer, inner, n, linalg::amd_ordering(outer, inner, n), options);
        candidate[0].done = true;
      } else if (compare) {
        std::vector<std::array<double, 3>> centroid(n);
        for (int j = 0; j < n; ++j)
          for (int a = 0; a < 3; ++a)
            centroid[j][a] = (V(t.F(face_of[j], 0), a) + V(t.F(face_of[j], 1), a) + V(t.F(face_of[j], 2), a)) / 3;
        const std::vector<int> order = linalg::coordinate_dissection(linalg::leading_block_pattern(outer, inner, n), centroid);
        candidate[1].factor = linalg::symbolic_analysis(outer, inner, n, order, options);
        candidate[1].done = true;
      }
    } catch (...) {  // an exception must not leave an OpenMP region
#pragma omp critical
      error = std::current_exception();
    }
  }
  if (error) std::rethrow_exception(error);
  const bool dissect = candidate[1].done && candidate[1].factor.flops < candidate[0].factor.flops;
  return std::move(candidate[dissect ? 1 : 0]);
}

// The smoothest field's system (docs/auto.md, "The field"): the unknown faces (those not fixed), the upper
// triangle of the Hermitian A + εM over them in compressed columns (values as (real, imaginary) pairs), and the
// right-hand side of the fixed faces' values.
struct SmoothestSystem {
  std::vector<Complex> u;                 // per face: the fixed faces' values, 0 elsewhere
  std::vector<int> unknown, face_of;      // face -> unknown (or −1), unknown -> face
  std::vector<char> dirichlet_component;  // per component: 1 when it has fixed faces
  Eigen::VectorXd diag;                   // per face: Σ w over its interior edges
  double eps = 0;                         // the shift
  std::vector<int> outer, inner;
  std::vector<double> values;
  std::vector<double> dirichlet;          // b_g = −Σ A_gf u_f over fixed neighbours f, per unknown (real, imaginary)
  int size() const { return static_cast<int>(face_of.size()); }
};

SmoothestSystem assemble_smoothest_system(const Topology& t, const Geometry& g, const Weights& k, const AutoOptions& o) {
  const int N = o.N;
  SmoothestSystem S;
  S.u.assign(t.num_faces, Complex(0, 0));
  S.unknown.assign(t.num_faces, -1);
  S.dirichlet_component.assign(t.components.size(), 0);
  for (auto [f, angle] : o.fixed) {
    if (f < 0 || f >= t.num_faces) throw Error("automatic singularities: fixed face " + std::to_string(f) + " out of range");
    if (!std::isfinite(angle)) throw Error("automatic singularities: fixed face " + std::to_string(f) + " has a non-finite angle");
    S.u[f] = std::polar(1.0, N * angle);
    S.dirichlet_component[t.face_component[f]] = 1;
  }
  for (int f = 0; f < t.num_faces; ++f)
    if (!o.fixed.count(f)) S.unknown[f] = static_cast<int>(S.face_of.size()), S.face_of.push_back(f);
  const int n = S.size();
  if (n == 0) return S;
  S.diag = Eigen::VectorXd::Zero(t.num_faces);
  for (int e = 0; e < t.num_edges; ++e)
    if (!t.is_boundary_edge(e)) S.diag[t.edge_faces(e, 0)] += k.w[e], S.diag[t.edge_faces(e, 1)] += k.w[e];
  // The ratio of the sums, not the mean of the ratios: a zero-area face has the floor mass and an ordinary
  // diagonal, so its ratio is ~1e12 times the others', and a mean over faces would make the shift swamp A
  // on any mesh with a few such faces (the inverse iteration then barely moves from its random start).
  S.eps = 1e-8 * S.diag.sum() / k.mass.sum();
  // No interior edge at all (e.g. lone triangles): every field is equally smooth; the shift alone makes it definite.
  if (!(S.eps > 0)) S.eps = 1;
  S.outer.assign(n + 1, 0);
  S.inner.reserve(static_cast<size_t>(n) * 3), S.values.reserve(static_cast<size_t>(n) * 6);
  std::vector<std::pair<int, Complex>> column;
  for (int j = 0; j < n; ++j) {
    const int f = S.face_of[j];
    column.clear();
    for (int c = 0; c < 3; ++c) {
      const int e = t.face_edges(f, c);
      if (t.is_boundary_edge(e)) continue;
      const int h = t.edge_faces(e, 0) == f ? t.edge_faces(e, 1) : t.edge_faces(e, 0);
      if (h != f && S.unknown[h] >= 0 && S.unknown[h] < j) column.emplace_back(S.unknown[h], off_diagonal(t, g, k, N, e, h));
    }
    std::sort(column.begin(), column.end(), [](const auto& a, const auto& b) { return a.first < b.first; });
    for (auto [i, a] : column) S.inner.push_back(i), S.values.push_back(a.real()), S.values.push_back(a.imag());
    S.inner.push_back(j), S.values.push_back(S.diag[f] + S.eps * k.mass[f]), S.values.push_back(0.0);
    S.outer[j + 1] = static_cast<int>(S.inner.size());
  }
  S.dirichlet.assign(2 * static_cast<size_t>(n), 0.0);
  for (int e = 0; e < t.num_edges; ++e) {
    if (t.is_boundary_edge(e)) continue;
    for (int side = 0; side < 2; ++side) {
      const int row = t.edge_faces(e, side), col = t.edge_faces(e, 1 - side);
      if (S.unknown[row] < 0 || S.unknown[col] >= 0) continue;
      const Complex b = -off_diagonal(t, g, k, N, e, row) * S.u[col];
      S.dirichlet[2 * S.unknown[row]] += b.real(), S.dirichlet[2 * S.unknown[row] + 1] += b.imag();
    }
  }
  return S;
}

// Curvature alignment (docs/auto.md): the field x found so far is replaced, on each component with curvature,
// by the solution of (A − t·λ̂ M) u = M q + b_D toward the guidance q; with t ≠ 0 the factor L is refactored.
void align_to_guidance(const Topology& t, const Geometry& g, const Weights& k, const AutoOptions& o, const std::vector<Complex>& guidance,
                       SmoothestSystem& S, const linalg::SymbolicFactor& L, linalg::FactorValues<Complex>& Lx,
                       const linalg::Substitution<Complex>& substitution, std::vector<double>& x) {
  const int N = o.N, n = S.size(), components = static_cast<int>(t.components.size());
  // Per component: the Rayleigh quotient λ̂ of the field found so far (the smoothest field's eigenvalue, or the
  // energy of the Dirichlet solution) and the guidance's scale (area-weighted mean |q| = 1).
  auto value = [&](int f) { return S.unknown[f] >= 0 ? Complex(x[2 * S.unknown[f]], x[2 * S.unknown[f] + 1]) : S.u[f]; };
  std::vector<double> energy(components, 0), norm(components, 0), zsum(components, 0), msum(components, 0);
  for (int e = 0; e < t.num_edges; ++e) {
    if (t.is_boundary_edge(e)) continue;
    const int L_ = t.edge_faces(e, 0), R = t.edge_faces(e, 1);
    energy[t.face_component[L_]] += k.w[e] * std::norm(value(R) - std::polar(1.0, N * g.rho[e]) * value(L_));
  }
  std::vector<Complex> q(t.num_faces);  // M q, before scaling
  for (int f = 0; f < t.num_faces; ++f) {
    const int comp = t.face_component[f];
    norm[comp] += k.mass[f] * std::norm(value(f)), msum[comp] += k.mass[f];
    const Complex z = guidance[f];
    const double a = std::abs(z);
    q[f] = a > 0 ? a * std::pow(z / a, N / 2) : Complex(0, 0);
    zsum[comp] += a;
  }
  std::vector<char> guided(components, 0);
  for (int comp = 0; comp < components; ++comp) guided[comp] = zsum[comp] > 0 && std::isfinite(zsum[comp]);
  if (o.curvature_t != 0) {
    // A − λ_t M with λ_t = t λ̂ per component (the shift ε kept), refactored on the same analysis.
    for (int j = 0; j < n; ++j) {
      const int f = S.face_of[j], comp = t.face_component[f];
      const double lambda = norm[comp] > 0 ? energy[comp] / norm[comp] : 0.0;
      S.values[2 * (S.outer[j + 1] - 1)] = S.diag[f] + (S.eps - o.curvature_t * lambda) * k.mass[f];
    }
    if (linalg::factorize_complex(L, Lx, S.outer, S.inner, S.values) < n)
      throw Error("automatic singularities: curvature alignment with t = " + std::to_string(o.curvature_t) +
                  " makes the system indefinite (t must be below 1, and a little below 1 can already exceed the smallest "
                  "eigenvalue's estimate): use a smaller t");
  }
  Eigen::VectorXd b(2 * n);
  for (int j = 0; j < n; ++j) {
    const int f = S.face_of[j], comp = t.face_component[f];
    const Complex mq = guided[comp] ? q[f] * (msum[comp] / zsum[comp]) : Complex(0, 0);
    b[2 * j] = mq.real() + S.dirichlet[2 * j], b[2 * j + 1] = mq.imag() + S.dirichlet[2 * j + 1];
  }
  substitution.solve(reinterpret_cast<Complex*>(b.data()));
  for (int j = 0; j < n; ++j)  // components without curvature (flat, umbilic) keep the smoothest field
    if (guided[t.face_component[S.face_of[j]]]) x[2 * j] = b[2 * j], x[2 * j + 1] = b[2 * j + 1];
}

// The smoothest field's complex values per face (see docs/auto.md, "The eigen-solve"): the system, its
// factorization, the inverse iteration (src/linalg/inverse_iteration.h), the curvature alignment.
std::vector<Complex> smoothest_values(const MatrixX3d& V, const Topology& t, const Geometry& g, const Weights& k, const AutoOptions& o,
                                      const std::vector<Complex>* guidance, AutoTimings& time, std::string& ordering_used) {
  auto t0 = Clock::now();
  SmoothestSystem S = assemble_smoothest_system(t, g, k, o);
  const int n = S.size();
  if (n == 0) return S.u;
  time.assemble = seconds_since(t0);
  check_cancelled();  // trivcon/cancel.h: here, after the analysis, per iteration

  t0 = Clock::now();
  const SmoothestAnalysis analysis = analyse_smoothest_matrix(V, t, S.face_of, S.outer, S.inner);
  check_cancelled();
  const linalg::SymbolicFactor& L = analysis.factor;
  ordering_used = analysis.ordering;
  // The numeric factor by trivcon's own supernodal code (src/linalg/supernodal.h, the same that factors the
  // trivial-connection system), on both cores: cholmod_factorize visits the supernodes one after another.
  linalg::FactorValues<Complex> Lx;  // the factor's values
  if (const int minor = linalg::factorize_complex(L, Lx, S.outer, S.inner, S.values); minor < n)
    throw Error("automatic singularities: the smoothest-field matrix is not positive definite (column " + std::to_string(minor) +
                " of " + std::to_string(n) + "): a non-finite or degenerate weight");
  // The solves below on both cores (src/linalg/substitution.h): CHOLMOD's own, on one core, were several times slower.
  const linalg::Substitution<Complex> substitution(L, Lx);
  time.factor = seconds_since(t0);

  t0 = Clock::now();
  const int components = static_cast<int>(t.components.size());
  linalg::InverseIterationProblem problem;
  problem.mass.resize(n), problem.group.resize(n);
  for (int j = 0; j < n; ++j) problem.mass[j] = k.mass[S.face_of[j]], problem.group[j] = t.face_component[S.face_of[j]];
  problem.normalised.resize(components);
  for (int comp = 0; comp < components; ++comp) problem.normalised[comp] = !S.dirichlet_component[comp];
  problem.affine = S.dirichlet;
  problem.iterations = o.iterations;
  problem.what = "automatic singularities";
  // A fixed start, ‖x‖_M = 1 on every component without fixed faces: the result is deterministic.
  std::vector<double> x(2 * static_cast<size_t>(n));
  std::mt19937 random(20131);
  std::uniform_real_distribution<double> uniform(-1.0, 1.0);
  for (double& v : x) v = uniform(random);
  {
    std::vector<double> norm(components, 0);
    for (int j = 0; j < n; ++j) norm[problem.group[j]] += problem.mass[j] * (x[2 * j] * x[2 * j] + x[2 * j + 1] * x[2 * j + 1]);
    for (int j = 0; j < n; ++j) {
      const int comp = problem.group[j];
      if (!problem.normalised[comp]) continue;
      if (!(norm[comp] > 0) || !std::isfinite(norm[comp]))
        throw Error("automatic singularities: the inverse iteration lost the field on component " + std::to_string(comp) + " (norm " +
                    std::to_string(norm[comp]) + ")");
      x[2 * j] /= std::sqrt(norm[comp]), x[2 * j + 1] /= std::sqrt(norm[comp]);
    }
  }
  linalg::inverse_iteration(substitution, problem, x);
  time.iterate = seconds_since(t0);
  if (guidance) {
    t0 = Clock::now();
    align_to_guidance(t, g, k, o, *guidance, S, L, Lx, substitution, x);
    time.align = seconds_since(t0);
  }
  for (int j = 0; j < n; ++j) {
    if (!std::isfinite(x[2 * j]) || !std::isfinite(x[2 * j + 1]))
      throw Error("automatic singularities: the smoothest field is not finite at face " + std::to_string(S.face_of[j]));
    S.u[S.face_of[j]] = Complex(x[2 * j], x[2 * j + 1]);
  }
  return S.u;
}

}  // namespace

// Opposite singularities at most `distance` apart along edges, closest first (ties: smaller vertex ids). Whole
// pairs (+n, −n) vanish, each vertex in one pair at most; with `partial`, any +a and −b also meet, min(a, b)
// leaving each (the larger keeps the rest), and a vertex may meet several.
std::map<int, int> cancel_singularity_pairs(const MatrixX3d& V, const Topology& t, const std::map<int, int>& vertex, double distance,
                                            std::vector<std::pair<int, int>>* pairs, bool partial, int* met) {
  if (!(distance >= 0) || !std::isfinite(distance))
    throw Error("singularity cancellation: invalid distance " + std::to_string(distance) + " (need a finite number >= 0)");
  std::map<int, int> left = vertex;
  if (distance == 0) return left;
  // Candidate pairs from a Dijkstra search of radius `distance` around each positive singularity.
  struct Candidate {
    double d;
    int plus, minus;
  };
  std::vector<Candidate> candidates;
  std::vector<double> dist(t.num_vertices, std::numeric_limits<double>::infinity());
  for (auto [source, n] : vertex) {
    if (n <= 0) continue;
    if (source < 0 || source >= t.num_vertices) throw Error("singularity cancellation: vertex " + std::to_string(source) + " out of range");
    field::edge_dijkstra(V, t, source, distance, true, dist, [&, source = source, n = n](int v, double d) {
      if (v != source)
        if (auto it = vertex.find(v); it != vertex.end() && (partial ? it->second < 0 : it->second == -n)) candidates.push_back({d, source, v});
      return true;
    });
  }
  std::sort(candidates.begin(), candidates.end(), [](const Candidate& a, const Candidate& b) {
    return a.d != b.d ? a.d < b.d : a.plus != b.plus ? a.plus < b.plus : a.minus < b.minus;
  });
  for (const Candidate& k : candidates) {
    auto plus = left.find(k.plus), minus = left.find(k.minus);
    if (plus == left.end() || minus == left.end()) continue;
    const int m = std::min(plus->second, -minus->second);
    if (plus->second == m && minus->second == -m) {
      if (pairs) pairs->emplace_back(k.plus, k.minus);
    } else if (met) {
      ++*met;
    }
    if ((plus->second -= m) == 0) left.erase(plus);
    if ((minus->second += m) == 0) left.erase(minus);
  }
  return left;
}

namespace {

// The split of AutoOptions::split_above: each singularity of |n| > limit, and each of n > 1 (a quad vertex of
// valence N − n ≤ N − 2: for N = 4 two quads folded onto each other, or one with a vertex twice), becomes |n| of
// sign(n) · 1 on interior vertices about `distance` from it along edges (Dijkstra: those first reached at or past
// it) that hold no singularity yet (given, or placed by an earlier split whose ring overlaps this one's), chosen
// far from each other (farthest-point order, in space, from the one nearest to `distance`); where too few such
// vertices exist, it stays as it is.
std::map<int, int> split_singularities(const MatrixX3d& V, const Topology& t, const std::map<int, int>& given, int limit,
                                       double distance, int& split) {
  std::map<int, int> out;
  std::vector<double> dist(t.num_vertices, std::numeric_limits<double>::infinity());
  // First, singularities of one sign closer than `distance` (along edges) are gathered into one of their summed
  // index at the member nearest to their centroid: two +1/4 on neighbouring vertices cannot sit on two integer
  // points of a map one unit apart, but their sum split below can. Clusters join closest pair first, and only
  // while every member stays within `distance` of every other (complete linkage): a row of −1/4 each a little
  // less than a unit from the next is not one singularity of their whole sum.
  std::map<int, int> vertex;
  std::set<int> spread;  // gathered positive clusters, split again whatever their sum
  {
    struct Near {
      double d;
      int a, b;
    };
    std::vector<Near> close;
    std::set<std::pair<int, int>> within;  // (a, b) with a < b, of one sign, at most `distance` apart
    for (auto [source, n] : given)
      field::edge_dijkstra(V, t, source, distance, false, dist, [&, source = source, n = n](int v, double d) {
        if (auto it = given.find(v); v > source && it != given.end() && (it->second > 0) == (n > 0))
          close.push_back({d, source, v}), within.insert({source, v});
        return true;
      });
    std::sort(close.begin(), close.end(), [](const Near& x, const Near& y) {
      return x.d != y.d ? x.d < y.d : x.a != y.a ? x.a < y.a : x.b < y.b;
    });
    std::map<int, int> cluster;  // vertex → its cluster's key (a member)
    std::map<int, std::vector<int>> members;
    for (auto [v, n] : given) cluster[v] = v, members[v] = {v};
    for (const Near& k : close) {
      int ca = cluster[k.a], cb = cluster[k.b];
      if (ca == cb) continue;
      bool all = true;
      for (int x : members[ca])
        for (int y : members[cb]) all = all && within.count({std::min(x, y), std::max(x, y)});
      if (!all) continue;
      if (members[ca].size() < members[cb].size()) std::swap(ca, cb);
      for (int y : members[cb]) cluster[y] = ca, members[ca].push_back(y);
      members.erase(cb);
    }
    for (auto& [r, list] : members) {
      std::sort(list.begin(), list.end());
      Eigen::RowVector3d centroid = Eigen::RowVector3d::Zero();
      int total = 0;
      for (int v : list) centroid += V.row(v), total += given.at(v);
      centroid /= static_cast<double>(list.size());
      if (list.size() == 1) {
        vertex[list[0]] += total;
        continue;
      }
      // Several: gathered at the member nearest their centroid. Negative ones stay gathered unless their sum is
      // split below (two −1 closer than a unit fold the map between them; one −2 is a vertex of valence 6);
      // positive ones are spread again one `distance` apart (gathered, two +1 would make a vertex of valence 2).
      int centre = list[0];
      for (int v : list)
        if ((V.row(v) - centroid).norm() < (V.row(centre) - centroid).norm()) centre = v;
      vertex[centre] += total;
      if (total > 0) spread.insert(centre);
    }
  }
  for (auto [source, n] : vertex) {
    if (std::abs(n) <= limit && n <= 1 && !spread.count(source)) {
      out[source] += n;
      continue;
    }
    std::vector<std::pair<double, int>> reached;  // the first free interior vertices at or past `distance`
    field::edge_dijkstra(V, t, source, std::numeric_limits<double>::infinity(), true, dist, [&](int v, double d) {
      if (d < distance) return true;
      if (t.is_interior_vertex(v) && !given.count(v) && !out.count(v)) reached.emplace_back(d, v);
      return false;  // the ring: no further
    });
    std::sort(reached.begin(), reached.end());  // nearest first, then by id
    std::vector<int> ring;
    for (auto [d, v] : reached) ring.push_back(v);
    const int count = std::abs(n);
    std::vector<int> chosen;
    if (static_cast<int>(ring.size()) >= count) {
      chosen.push_back(ring[0]);
      std::vector<double> nearest(ring.size(), std::numeric_limits<double>::infinity());
      while (static_cast<int>(chosen.size()) < count) {
        size_t best = 0;
        for (size_t i = 0; i < ring.size(); ++i) {
          nearest[i] = std::min(nearest[i], (V.row(ring[i]) - V.row(chosen.back())).norm());
          if (nearest[i] > nearest[best]) best = i;
        }
        chosen.push_back(ring[best]);
      }
    }
    if (chosen.empty()) {
      out[source] += n;
      continue;
    }
    ++split;
    for (int v : chosen) out[v] += n > 0 ? 1 : -1;
  }
  for (auto it = out.begin(); it != out.end();) it = it->second == 0 ? out.erase(it) : std::next(it);
  return out;
}

}  // namespace

std::map<int, int> merge_coincident_singularities(const MatrixX3d& V, const Topology& t, const std::map<int, int>& vertex) {
  // Clusters of vertices joined by zero-length edges (union-find with path halving).
  std::vector<int> parent(t.num_vertices);
  for (int v = 0; v < t.num_vertices; ++v) parent[v] = v;
  auto root = [&](int v) {
    while (parent[v] != v) v = parent[v] = parent[parent[v]];
    return v;
  };
  bool any = false;
  for (int e = 0; e < t.num_edges; ++e) {
    const int i = t.edge_vertices(e, 0), j = t.edge_vertices(e, 1);
    if (!zero_length_edge(V, t, e)) continue;
    any = true;
    const int a = root(i), b = root(j);
    if (a != b) parent[std::max(a, b)] = std::min(a, b);  // the root is the cluster's smallest id
  }
  if (!any) return vertex;
  std::vector<char> touches_boundary(t.num_vertices, 0);
  for (int v = 0; v < t.num_vertices; ++v)
    if (t.is_boundary_vertex(v)) touches_boundary[root(v)] = 1;
  std::map<int, int> merged;
  for (auto [v, n] : vertex) {
    const int c = root(v);
    merged[touches_boundary[c] ? v : c] += n;  // a cluster on the boundary keeps its interior vertices' own
  }
  for (auto it = merged.begin(); it != merged.end();) it = it->second == 0 ? merged.erase(it) : std::next(it);
  return merged;
}

namespace {

// AutoOptions::cancel_distance in the mesh's units, checked.
double cancel_distance_of(const MatrixX3d& V, const Topology& t, const AutoOptions& o) {
  if (!(o.cancel_distance >= 0) || !std::isfinite(o.cancel_distance))
    throw Error("automatic singularities: invalid cancel distance " + std::to_string(o.cancel_distance) + " (need a finite number >= 0)");
  return o.cancel_absolute ? o.cancel_distance : o.cancel_distance * mean_edge_length(V, t);
}

// The singularities of `free` at `held` vertices, taken out of it.
std::map<int, int> take_held(const Topology& t, std::map<int, int>& free, const std::vector<int>& held_vertices) {
  std::map<int, int> held;
  for (int v : held_vertices) {
    if (v < 0 || v >= t.num_vertices) throw Error("automatic singularities: held vertex " + std::to_string(v) + " out of range");
    if (auto it = free.find(v); it != free.end()) held.insert(*it), free.erase(it);
  }
  return held;
}

// `held` put back into `vertex` (an index that sums to 0 with one there leaves no singularity).
void put_back(std::map<int, int>& vertex, const std::map<int, int>& held) {
  for (auto [v, n] : held)
    if ((vertex[v] += n) == 0) vertex.erase(v);
}

// AutoOptions::split_above's gathering and split, then the meeting of opposite singularities within `distance`.
std::map<int, int> split_and_meet(const MatrixX3d& V, const Topology& t, const std::map<int, int>& free, const AutoOptions& o,
                                  double distance, AutoResult& r) {
  if (!(o.split_distance > 0) || !std::isfinite(o.split_distance))
    throw Error("automatic singularities: invalid split distance " + std::to_string(o.split_distance) + " (need a finite number > 0)");
  const std::map<int, int> split = split_singularities(V, t, free, o.split_above, o.split_distance, r.split);
  return cancel_singularity_pairs(V, t, split, distance, &r.pairs, true, &r.met);
}

}  // namespace

AutoResult auto_singularities(const MatrixX3d& V, const Topology& t, const Geometry& g, const Cycles& cycles, const AutoOptions& o) {
  if (o.N < 1) throw Error("automatic singularities: invalid N = " + std::to_string(o.N) + " (need N >= 1)");
  if (o.iterations < 1) throw Error("automatic singularities: invalid iterations = " + std::to_string(o.iterations) + " (need at least 1)");
  if (V.rows() != t.num_vertices)
    throw Error("automatic singularities: V has " + std::to_string(V.rows()) + " rows, the mesh " + std::to_string(t.num_vertices) +
                " vertices");
  AutoResult r;
  r.field.N = o.N;
  r.field.angle = Eigen::VectorXd::Zero(t.num_faces);
  if (t.num_faces == 0) return r;
  if (o.align_curvature && o.N % 2 != 0)
    throw Error("automatic singularities: curvature alignment needs an even N (principal directions are lines), not N = " +
                std::to_string(o.N));
  if (o.align_curvature && !(o.curvature_t < 1))
    throw Error("automatic singularities: invalid curvature alignment strength t = " + std::to_string(o.curvature_t) + " (need t < 1)");
  const Weights k = face_weights(V, t, g);
  std::vector<Complex> guidance;
  if (o.align_curvature) guidance = curvature_tensors(V, t, g);
  check_cancelled();
  std::vector<Complex> u = smoothest_values(V, t, g, k, o, o.align_curvature ? &guidance : nullptr, r.seconds, r.ordering);
  check_cancelled();

  auto t0 = Clock::now();
  // Energy (the Rayleigh quotient), then faces where the field vanishes (trivcon/auto.h).
  double energy = 0, norm = 0;
  for (int e = 0; e < t.num_edges; ++e) {
    if (t.is_boundary_edge(e)) continue;
    const int L = t.edge_faces(e, 0), R = t.edge_faces(e, 1);
    energy += k.w[e] * std::norm(u[R] - std::polar(1.0, o.N * g.rho[e]) * u[L]);
  }
  std::vector<double> largest(t.components.size(), 0);
  for (int f = 0; f < t.num_faces; ++f) {
    norm += k.mass[f] * std::norm(u[f]);
    largest[t.face_component[f]] = std::max(largest[t.face_component[f]], std::abs(u[f]));
  }
  r.energy = norm > 0 ? energy / norm : 0;
  std::vector<Complex> filled = u;
  for (int f = 0; f < t.num_faces; ++f) {
    const double small = 1e-9 * largest[t.face_component[f]];
    if (std::abs(u[f]) > small) continue;
    ++r.vanishing_faces;
    Complex sum(0, 0);
    for (int c = 0; c < 3; ++c) {
      const int e = t.face_edges(f, c);
      if (t.is_boundary_edge(e)) continue;
      const int L = t.edge_faces(e, 0), R = t.edge_faces(e, 1);
      const Complex r_e = std::polar(1.0, o.N * g.rho[e]);
      sum += f == R ? r_e * u[L] : std::conj(r_e) * u[R];
    }
    filled[f] = std::abs(sum) > small ? sum : Complex(1, 0);
  }
  for (int f = 0; f < t.num_faces; ++f) {
    double a = std::arg(filled[f]) / o.N;
    if (a < 0) a += kTwoPi / o.N;
    r.field.angle[f] = std::min(a, std::nextafter(kTwoPi / o.N, 0.0));
  }
  const FieldIndices indices = field_indices(t, g, cycles, r.field);
  for (int v = 0; v < t.num_vertices; ++v)
    if (indices.vertex[v] != 0) r.found[v] = indices.vertex[v];
  // Turning of whole 2π/N steps at boundary vertices beside fixed faces goes to an interior neighbour, where
  // the exact solve can place it (trivcon/constraints.h).
  for (auto [v, n] : boundary_turns_moved_inside(t, g, o.fixed, r.field)) {
    r.boundary_moved += std::abs(n);
    if ((r.found[v] += n) == 0) r.found.erase(v);
  }
  r.seconds.indices = seconds_since(t0);
  const std::map<int, int> merged = merge_coincident_singularities(V, t, r.found);
  r.coincident_removed = static_cast<int>(r.found.size() - merged.size());

  t0 = Clock::now();
  const double distance = cancel_distance_of(V, t, o);
  std::map<int, int> free = merged;
  const std::map<int, int> held = take_held(t, free, o.held);
  r.vertex = cancel_singularity_pairs(V, t, free, distance, &r.pairs);
  if (o.split_above > 0) r.vertex = split_and_meet(V, t, r.vertex, o, distance, r);
  put_back(r.vertex, held);
  r.seconds.cancel = seconds_since(t0);
  return r;
}

std::map<int, int> split_auto_singularities(const MatrixX3d& V, const Topology& t, const std::map<int, int>& vertex,
                                            const AutoOptions& o, AutoResult& result) {
  if (o.split_above <= 0) return vertex;
  const double distance = cancel_distance_of(V, t, o);
  std::map<int, int> free = vertex;
  const std::map<int, int> held = take_held(t, free, o.held);
  std::map<int, int> out = split_and_meet(V, t, free, o, distance, result);
  put_back(out, held);
  return out;
}

AutoResult auto_singularities(const FieldDesigner& designer, const AutoOptions& options) {
  return auto_singularities(designer.V(), designer.topology(), designer.geometry(), designer.cycles(), options);
}

AutoResult auto_singularities(const MatrixX3d& V, const MatrixX3i& F, const AutoOptions& options) {
  check_finite(V);
  const Topology t = build_topology(F, static_cast<int>(V.rows()));
  check_coordinate_range(V, t);
  const Geometry g = compute_geometry(V, t);
  const Cycles cycles = compute_cycles(t);
  return auto_singularities(V, t, g, cycles, options);
}

std::vector<std::pair<int, double>> roots_toward(const FieldDesigner& designer, const Field& field, const Field& guide,
                                                 const std::vector<std::pair<int, double>>& roots, const std::map<int, double>& fixed) {
  const Topology& t = designer.topology();
  const Geometry& g = designer.geometry();
  if (field.angle.size() != t.num_faces || guide.angle.size() != t.num_faces)
    throw Error("roots_toward: the field and the guide need one angle per face (" + std::to_string(t.num_faces) + ")");
  if (field.N != guide.N) throw Error("roots_toward: the field has N = " + std::to_string(field.N) + ", the guide N = " + std::to_string(guide.N));
  std::vector<char> decided(t.components.size(), 0);
  for (auto [f, angle] : roots)
    if (f >= 0 && f < t.num_faces) decided[t.face_component[f]] = 1;
  for (const auto& entry : fixed)
    if (entry.first >= 0 && entry.first < t.num_faces) decided[t.face_component[entry.first]] = 1;
  std::vector<std::complex<double>> sum(t.components.size(), 0.0);
  for (int f = 0; f < t.num_faces; ++f) {
    const int c = t.face_component[f];
    if (decided[c]) continue;
    sum[c] += g.face_area(f) * std::polar(1.0, field.N * (guide.angle(f) - field.angle(f)));
  }
  std::vector<std::pair<int, double>> out = roots;
  for (size_t c = 0; c < t.components.size(); ++c) {
    if (decided[c] || std::abs(sum[c]) <= 1e-300) continue;
    const int f = t.components[c].first_face;
    out.emplace_back(f, wrap_angle(field.angle(f) + std::arg(sum[c]) / field.N));
  }
  return out;
}

void turn_toward(const FieldDesigner& designer, Field& field, const Field& guide, const std::map<int, double>& fixed,
                 const std::vector<std::pair<int, double>>& roots) {
  const Topology& t = designer.topology();
  std::vector<double> turn(t.components.size(), 0.0);
  const std::vector<std::pair<int, double>> out = roots_toward(designer, field, guide, roots, fixed);
  for (size_t k = roots.size(); k < out.size(); ++k) turn[t.face_component[out[k].first]] = out[k].second - field.angle(out[k].first);
  for (int f = 0; f < t.num_faces; ++f) {
    field.angle(f) = wrap_two_pi(field.angle(f) + turn[t.face_component[f]]);
  }
}

}  // namespace trivcon
