// SPDX-License-Identifier: MIT
// Singularity relaxation (trivcon/relax.h): candidates ranked by the vertex duals, verified by real solves.
#include "trivcon/relax.h"

#include <algorithm>
#include <cmath>
#include <limits>
#include <map>
#include <optional>
#include <utility>
#include <string>

#include "field/edge_dijkstra.h"
#include "linalg/timing.h"
#include "trivcon/cancel.h"
#include "trivcon/error.h"

namespace trivcon {

namespace {

// A move must lower the energy by more than this fraction of it.
constexpr double kRelativeDecrease = 1e-12;
// A move predicted (or bounded) to raise it by more than this fraction is not solved: round-off in the
// predictions stays well below it.
constexpr double kBoundMargin = 1e-9;

std::vector<char> pinned_vertices(const Topology& t, const RelaxOptions& options) {
  if (options.max_moves < 0) throw Error("relax: max_moves must be at least 0, not " + std::to_string(options.max_moves));
  if (options.cancel_distance < 0) throw Error("relax: cancel_distance must be at least 0, not " + std::to_string(options.cancel_distance));
  if (options.reach < 1) throw Error("relax: reach must be at least 1, not " + std::to_string(options.reach));
  if (!(options.period_weight >= 0) || !std::isfinite(options.period_weight)) throw Error("relax: period_weight must be a finite number of at least 0");
  if (!(options.max_seconds >= 0)) throw Error("relax: max_seconds must be at least 0");
  if (options.max_solves < 0) throw Error("relax: max_solves must be at least 0, not " + std::to_string(options.max_solves));
  if (!(options.separation >= 0) || !std::isfinite(options.separation)) throw Error("relax: separation must be a finite distance of at least 0");
  std::vector<char> pinned(t.num_vertices, 0);
  for (int v : options.pins) {
    if (v < 0 || v >= t.num_vertices)
      throw Error("relax: pinned vertex " + std::to_string(v) + " out of range (mesh has " + std::to_string(t.num_vertices) + " vertices)");
    pinned[v] = 1;
  }
  for (int v : options.avoid) {
    if (v < 0 || v >= t.num_vertices)
      throw Error("relax: avoided vertex " + std::to_string(v) + " out of range (mesh has " + std::to_string(t.num_vertices) + " vertices)");
    if (!pinned[v]) pinned[v] = 2;
  }
  return pinned;
}

int index_at(const IndexPrescription& p, int v) {
  const auto it = p.vertex.find(v);
  return it == p.vertex.end() ? 0 : it->second;
}

void apply(const RelaxCandidate& move, IndexPrescription& p) {
  p.vertex.erase(move.from);
  if (move.cancels)
    p.vertex.erase(move.to);
  else
    p.vertex[move.to] = move.index;
}

// The period term of the objective (trivcon/relax.h, "Periods").
struct Periods {
  double weight = 0;
  std::vector<std::vector<int>> components;  // fixed faces, connected through shared vertices
  std::vector<Eigen::VectorXd> sensitivity;  // ∂T_C/∂b per vertex (0 where a vertex has no row)

  bool used() const { return !components.empty(); }

  // T_C of a connection.
  std::vector<double> values(const FieldDesigner& designer, const Connection& connection) const {
    const Topology& t = designer.topology();
    const Eigen::VectorXd& w = designer.solver().weights();
    std::vector<double> out;
    for (const std::vector<int>& faces : components) {
      double sum = 0;
      for (int f : faces)
        for (int k = 0; k < 3; ++k) {
          const int e = t.face_edges(f, k);
          if (w(e) > 0) sum += (t.edge_faces(e, 0) == f ? 1.0 : -1.0) * connection.x(e) / w(e);
        }
      out.push_back(sum);
    }
    return out;
  }
  double penalty(const std::vector<double>& T) const {
    double p = 0;
    for (double x : T) p += x * x;
    return p;
  }
  // The change of P when c moves from v to u, with the cycle indices held (exact then).
  double change(const std::vector<double>& T, int v, int u, double c) const {
    double d = 0;
    for (size_t k = 0; k < T.size(); ++k) {
      const double dT = c * (sensitivity[k](v) - sensitivity[k](u));
      d += 2 * T[k] * dT + dT * dT;
    }
    return d;
  }
};

// The components of the fixed faces through shared vertices (union-find over their vertices), in the order of
// their first face.
std::vector<std::vector<int>> fixed_face_components(const FieldDesigner& designer) {
  const Topology& t = designer.topology();
  const std::vector<int>& fixed = designer.solver().fixed_faces();
  std::vector<int> parent(t.num_vertices, -1);
  auto find = [&](int a) {
    while (parent[a] != a) a = parent[a] = parent[parent[a]];
    return a;
  };
  for (int f : fixed)
    for (int k = 0; k < 3; ++k)
      if (parent[t.F(f, k)] < 0) parent[t.F(f, k)] = t.F(f, k);
  for (int f : fixed)
    for (int k = 1; k < 3; ++k) parent[find(t.F(f, k))] = find(t.F(f, 0));
  std::vector<std::vector<int>> components;
  std::map<int, int> component_of_root;
  for (int f : fixed) {
    const auto [it, added] = component_of_root.emplace(find(t.F(f, 0)), static_cast<int>(components.size()));
    if (added) components.emplace_back();
    components[it->second].push_back(f);
  }
  return components;
}

bool usable(const std::vector<std::vector<int>>& components, const Topology& t) {
  return components.size() >= 2 && static_cast<double>(components.size()) * t.num_vertices <= kMaxPeriodValues;
}

Periods make_periods(const FieldDesigner& designer, double weight) {
  Periods p;
  if (!(weight > 0)) return p;
  const Topology& t = designer.topology();
  const ConnectionSolver& solver = designer.solver();
  p.components = fixed_face_components(designer);
  if (!usable(p.components, t)) {
    p.components.clear();
    return p;
  }
  p.weight = weight;
  const Eigen::VectorXd& w = solver.weights();
  Connection sigma;
  sigma.N = 1;
  for (const std::vector<int>& faces : p.components) {
    sigma.x = Eigen::VectorXd::Zero(t.num_edges);
    for (int f : faces)
      for (int k = 0; k < 3; ++k) {
        const int e = t.face_edges(f, k);
        if (w(e) > 0) sigma.x(e) += t.edge_faces(e, 0) == f ? 1.0 : -1.0;
      }
    p.sensitivity.push_back(solver.vertex_duals(sigma));
  }
  return p;
}

// The distances from a vertex x to the nearest singular vertex other than `self` below the separation
// (candidates_of's `nearest_other`), kept between the relaxation's rounds: one depends only on the singular
// vertices within the separation of x, so a move forgets those of the vertices near its two ends (and those of
// a singularity that moved).
class SeparationCache {
 public:
  explicit SeparationCache(int num_vertices)
      : by_x_(num_vertices), xs_of_self_(num_vertices), dist_(num_vertices, std::numeric_limits<double>::infinity()) {}
  const double* find(int x, int self) const {
    for (const auto& [s, d] : by_x_[x])
      if (s == self) return &d;
    return nullptr;
  }
  void add(int x, int self, double d) { by_x_[x].emplace_back(self, d), xs_of_self_[self].push_back(x); }
  // After a move between `a` and `b` (or a cancellation of both): every value near either, and every value of a
  // singularity at either.
  void forget(const MatrixX3d& V, const Topology& t, double separation, int a, int b) {
    for (int z : {a, b}) {
      // Slightly beyond the separation and inclusive: the distance from z and from x may differ in the last bit.
      field::edge_dijkstra(V, t, z, separation * (1 + 1e-9), true, dist_, [&](int x, double) {
        by_x_[x].clear();
        return true;
      });
      for (int x : xs_of_self_[z]) by_x_[x].erase(std::remove_if(by_x_[x].begin(), by_x_[x].end(), [&](const auto& e) { return e.first == z; }), by_x_[x].end());
      xs_of_self_[z].clear();
    }
  }

 private:
  std::vector<std::vector<std::pair<int, double>>> by_x_;
  std::vector<std::vector<int>> xs_of_self_;
  std::vector<double> dist_;  // edge_dijkstra's work vector (infinities between calls)
};

std::vector<RelaxCandidate> candidates_of(const FieldDesigner& designer, const IndexPrescription& prescription,
                                          const Connection& connection, const RelaxOptions& options, const Periods& periods,
                                          SeparationCache* cache = nullptr);

}  // namespace

bool periods_usable(const FieldDesigner& designer) { return usable(fixed_face_components(designer), designer.topology()); }

std::vector<RelaxCandidate> relax_candidates(const FieldDesigner& designer, const IndexPrescription& prescription,
                                             const Connection& connection, const RelaxOptions& options) {
  return candidates_of(designer, prescription, connection, options, make_periods(designer, options.period_weight));
}

namespace {

std::vector<RelaxCandidate> candidates_of(const FieldDesigner& designer, const IndexPrescription& prescription,
                                          const Connection& connection, const RelaxOptions& options, const Periods& periods,
                                          SeparationCache* cache) {
  const Topology& t = designer.topology();
  const std::vector<char> pinned = pinned_vertices(t, options);
  const ConnectionSolver& solver = designer.solver();
  const Eigen::VectorXd lambda = solver.vertex_duals(connection);
  const Eigen::VectorXd& w = solver.weights();
  // 1 / weighted degree: each vertex's share of the estimated resistance (trivcon/relax.h).
  Eigen::VectorXd degree = Eigen::VectorXd::Zero(t.num_vertices);
  for (int e = 0; e < t.num_edges; ++e) degree(t.edge_vertices(e, 0)) += w(e), degree(t.edge_vertices(e, 1)) += w(e);
  auto spread = [&](int v) { return degree(v) > 0 ? 1 / degree(v) : 0.0; };
  // The edges a cycle whose index each solve chooses crosses: free generators and fixed-face paths (a loop
  // cycle only crosses edges with a boundary end, which no move takes).
  std::vector<char> free_cycle_edge(t.num_edges, 0);
  const Cycles& cycles = designer.cycles();
  for (int g = 0; g < static_cast<int>(cycles.generators.size()); ++g)
    if (!prescription.generator.count(g))
      for (int e : cycles.generators[g].edges) free_cycle_edge[e] = 1;
  for (const FixedPath& path : solver.fixed_paths())
    for (int e : path.path.edges) free_cycle_edge[e] = 1;
  const double step = 2 * kPi / prescription.N;
  const std::vector<double> T = periods.used() ? periods.values(designer, connection) : std::vector<double>{};
  std::vector<RelaxCandidate> out;
  auto add = [&](int v, int u, int n, int distance, bool cancels, int edge) {
    const double c = step * n;
    RelaxCandidate m;
    m.from = v, m.to = u, m.index = n, m.distance = distance, m.cancels = cancels;
    m.first_order = 2 * c * (lambda(v) - lambda(u));
    // Across such an edge the move may carry the cycle's index along: δb = c s A e_e (s = +1 when v is the
    // edge's larger id), whose first-order change is the edge's own 2 c s x_e / w_e.
    if (edge >= 0 && free_cycle_edge[edge] && w(edge) > 0) {
      const double s = t.edge_vertices(edge, 1) == v ? 1.0 : -1.0;
      m.first_order = std::min(m.first_order, 2 * c * s * connection.x(edge) / w(edge));
    }
    const double resistance = (spread(v) + spread(u)) * (1 + std::sqrt(3.0) / kPi * std::log(static_cast<double>(distance)));
    m.estimate = m.first_order + c * c * resistance;
    m.lower_bound = m.first_order;
    if (distance == 1 && edge >= 0 && !free_cycle_edge[edge]) {  // shorted bound (trivcon/relax.h)
      const double direct = std::max(0.0, w(edge)), rest_v = degree(v) - direct, rest_u = degree(u) - direct;
      const double conductance = direct + (rest_v > 0 && rest_u > 0 ? 1 / (1 / rest_v + 1 / rest_u) : 0.0);
      if (conductance > 0) m.lower_bound += c * c / conductance;
    }
    if (periods.used()) {  // the period term's change, exact with the cycle indices held
      const double dP = periods.weight * periods.change(T, v, u, c);
      m.first_order += dP, m.estimate += dP, m.lower_bound += dP;
    }
    out.push_back(m);
  };
  auto other_end = [&](int e, int v) { return t.edge_vertices(e, 0) == v ? t.edge_vertices(e, 1) : t.edge_vertices(e, 0); };
  // With a separation: the distance (along edges, below the separation) from x to the nearest singular vertex
  // other than `self`; the separation when there is none that close (kept in `cache` between rounds).
  std::vector<double> dist(options.separation > 0 ? t.num_vertices : 0, std::numeric_limits<double>::infinity());
  auto nearest_other = [&](int x, int self) {
    if (cache)
      if (const double* known = cache->find(x, self)) return *known;
    double found = options.separation;
    field::edge_dijkstra(designer.V(), t, x, options.separation, false, dist, [&](int y, double d) {
      if (found < options.separation) return false;  // found (nearest first): expand nothing more
      if (y != self && index_at(prescription, y) != 0) found = d;
      return found == options.separation;
    });
    if (cache) cache->add(x, self, found);
    return found;
  };
  std::vector<int> seen(t.num_vertices, -1), frontier, next;
  for (auto [v, n] : prescription.vertex) {
    if (n == 0 || pinned[v] == 1) continue;
    const double room = options.separation > 0 ? nearest_other(v, v) : 0.0;
    for (int a = t.vertex_edge_offsets[v]; a < t.vertex_edge_offsets[v + 1]; ++a) {
      const int e = t.vertex_edges[a], u = other_end(e, v);
      if (!t.is_interior_vertex(u) || pinned[u] || index_at(prescription, u) != 0) continue;
      // Not closer to another singularity than the separation, unless it was closer still.
      if (options.separation > 0 && nearest_other(u, v) < std::min(room, options.separation)) continue;
      add(v, u, n, 1, false, e);
    }
    // Breadth-first to the farther of `reach` and cancel_distance edges: with a reach, the free vertices 2 to
    // `reach` edges away too (a jump over a rise of the objective that steps would not cross); with a cancel
    // distance, the vertices holding −n (each pair once, from its smaller vertex).
    const int depth = std::max(options.reach > 1 ? options.reach : 0, options.cancel_distance);
    if (depth == 0) continue;
    seen[v] = v;
    frontier.assign(1, v);
    for (int distance = 1; distance <= depth && !frontier.empty(); ++distance) {
      next.clear();
      for (int x : frontier)
        for (int a = t.vertex_edge_offsets[x]; a < t.vertex_edge_offsets[x + 1]; ++a) {
          const int u = other_end(t.vertex_edges[a], x);
          if (seen[u] == v) continue;
          seen[u] = v;
          next.push_back(u);
          if (pinned[u]) continue;
          const int held = index_at(prescription, u);
          if (distance <= options.cancel_distance && u > v && held == -n) add(v, u, n, distance, true, -1);
          if (distance >= 2 && distance <= options.reach && held == 0 && t.is_interior_vertex(u) &&
              !(options.separation > 0 && nearest_other(u, v) < std::min(room, options.separation)))
            add(v, u, n, distance, false, -1);
        }
      frontier.swap(next);
    }
  }
  std::sort(out.begin(), out.end(), [](const RelaxCandidate& a, const RelaxCandidate& b) {
    if (a.estimate != b.estimate) return a.estimate < b.estimate;
    return a.from != b.from ? a.from < b.from : a.to < b.to;
  });
  return out;
}

}  // namespace

RelaxResult relax(const FieldDesigner& designer, const IndexPrescription& start, const RelaxOptions& options) {
  const auto t0 = linalg::Clock::now();
  pinned_vertices(designer.topology(), options);  // checks the options before the first solve
  const ConnectionSolver& solver = designer.solver();
  const double step = 2 * kPi / start.N;
  RelaxResult r;
  r.prescription = start;
  const Periods periods = make_periods(designer, options.period_weight);
  r.periods_used = periods.used();
  // The objective: E, plus weight · P with the periods.
  auto objective = [&](const Connection& c, double* P = nullptr) {
    if (!periods.used()) return c.energy;
    const double p = periods.penalty(periods.values(designer, c));
    if (P) *P = p;
    return c.energy + periods.weight * p;
  };
  SeparationCache separation(designer.topology().num_vertices);
  Connection current = solver.solve(start);
  double current_objective = objective(current, &r.periods_before);
  r.energy_before = current.energy;
  r.energies.push_back(current_objective);
  // The second-order term of a move, measured by its real solve: (ΔE − first order) / c². With the cycle
  // indices held it is R_vu exactly, a property of the mesh and not of the placement, so a move solved once is
  // ranked exactly ever after (keyed by its unordered pair of vertices; a cancellation has its own entry).
  std::map<std::pair<int, int>, double> measured;
  // R_vu / R̃_vu of the measured moves: their median scales the estimate of the moves not measured yet (R̃ is off
  // by a factor that depends on the mesh: its triangulation's regularity and anisotropy), so that a move whose
  // estimate looks negative only because R̃ is too small is tried later.
  std::vector<double> ratios;
  double scale = 1;
  auto key = [](const RelaxCandidate& m) { return std::make_pair(std::min(m.from, m.to), std::max(m.from, m.to)); };
  // A candidate whose measured estimate is not negative is not solved again, except in the check before
  // stopping: only a full pass that solves every candidate with a negative first order ends the search.
  bool checking = false;
  // With every cycle index held, each prediction is exact or a true bound below ΔE, and nothing needs checking.
  const Cycles& cycles = designer.cycles();
  bool held = solver.fixed_paths().empty();
  for (int g = 0; g < static_cast<int>(cycles.generators.size()); ++g) held = held && start.generator.count(g);
  while (static_cast<int>(r.moves.size()) < options.max_moves) {
    std::vector<RelaxCandidate> candidates = candidates_of(designer, r.prescription, current, options, periods, &separation);
    for (RelaxCandidate& m : candidates)
      if (const auto it = measured.find(key(m)); it != measured.end()) {
        const double c = step * m.index;
        m.estimate = m.first_order + c * c * it->second;
      } else {
        m.estimate = m.first_order + scale * (m.estimate - m.first_order);
      }
    std::stable_sort(candidates.begin(), candidates.end(),
                     [](const RelaxCandidate& a, const RelaxCandidate& b) { return a.estimate < b.estimate; });
    bool moved = false;
    for (const RelaxCandidate& move : candidates) {
      if (!(move.first_order < 0)) continue;  // ΔE = first order + c² R with R ≥ 0: cannot lower E
      if (held) {
        const double c = step * move.index;
        const auto it = measured.find(key(move));
        const double lowest = it != measured.end() ? move.first_order + c * c * it->second : move.lower_bound;
        if (lowest > kBoundMargin * std::abs(current_objective)) continue;  // cannot lower the objective
      } else if (!checking && !(move.estimate < 0) && measured.count(key(move))) {
        continue;
      }
      check_cancelled();
      if (options.max_seconds > 0 && linalg::seconds_since(t0) > options.max_seconds) {
        r.out_of_time = true;
        break;
      }
      if (options.max_solves > 0 && r.candidates_evaluated >= options.max_solves) {
        r.out_of_solves = true;
        break;
      }
      IndexPrescription p = r.prescription;
      apply(move, p);
      // A candidate is ranked by its energy alone (ConnectionSolver::energy: the forward half of a solve); the
      // move taken is solved in full below. With the periods the objective needs the connection itself, and
      // where the solves need iterative refinement (extreme weights) the energy alone is not as exact as theirs.
      std::optional<Connection> next;
      if (periods.used() || current.refinements > 0) next = solver.solve(p);
      const double next_objective = next ? objective(*next) : solver.energy(p);
      ++r.candidates_evaluated;
      const double c = step * move.index;
      const double second = std::max(0.0, (next_objective - current_objective - move.first_order) / (c * c));
      if (!measured.count(key(move)) && move.estimate > move.first_order) {  // R̃ (as scaled) against R
        ratios.push_back(scale * second * c * c / (move.estimate - move.first_order));
        if (ratios.size() >= 8) {
          std::vector<double> sorted = ratios;
          std::nth_element(sorted.begin(), sorted.begin() + sorted.size() / 2, sorted.end());
          scale = sorted[sorted.size() / 2];
        }
      }
      measured[key(move)] = second;
      if (!(next_objective < current_objective - kRelativeDecrease * std::abs(current_objective))) continue;
      if (!next) next = solver.solve(p);
      r.prescription = std::move(p);
      if (options.separation > 0) separation.forget(designer.V(), designer.topology(), options.separation, move.from, move.to);
      current = std::move(*next);
      current_objective = objective(current);
      r.moves.push_back({move.from, move.to, move.index, current_objective, move.cancels});
      r.energies.push_back(current_objective);
      moved = true;
      break;
    }
    if (r.out_of_time || r.out_of_solves) break;
    if (moved) {
      checking = false;
    } else if (!checking && !held) {
      checking = true;  // nothing found among the unmeasured and the promising: solve every candidate once more
    } else {
      r.converged = true;
      break;
    }
  }
  r.energy_after = current.energy;
  objective(current, &r.periods_after);
  r.seconds = linalg::seconds_since(t0);
  return r;
}

}  // namespace trivcon
