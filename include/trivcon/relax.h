// SPDX-License-Identifier: MIT
// trivcon/relax.h: singularity relaxation — moving the prescribed singularities, one edge at a time,
// to where the field is smoother (lower Connection::energy), keeping their indices.
//
//   trivcon::RelaxResult r = trivcon::relax(designer, p);     // p: e.g. singularities placed by hand
//   designer.design(r.prescription) ...                        // the relaxed field
//
// A move takes a singular vertex v's whole index n/N to an interior neighbour u (one edge away) that is
// not singular, or with reach k > 1 to such a vertex up to k edges away; with cancel_distance > 0 it may
// also take it onto a vertex holding −n/N at most that many edges away, where both vanish. Boundary vertices never receive a singularity, pinned vertices neither
// move nor receive one, avoided vertices receive none, a step within `separation` of another singularity
// is not taken (see RelaxOptions), nothing moves between components, so each component keeps its multiset
// of indices (less the cancelled pairs). Generator and loop indices, and the fixed directions, stay as the
// prescription gives them (free ones are chosen smoothest by every solve, as in any design). A move is
// accepted only when a real solve (designer.solver().solve) lowers the energy by more than 1e-12 of it;
// relax stops when no candidate does, after max_moves moves, or after max_solves candidate solves.
//
// Periods (docs/solver.md, "Periods"). Let s_e = x_e / w_e on the primal edges. At every face f that is not
// fixed, Σ_{e∈f} g_fe s_e = 0 (g_fe = +1 where f = edge_faces(e, 0), −1 where f = edge_faces(e, 1)): rotating
// f's direction changes no constraint, so the minimum is stationary in it. So s = dφ locally: e^φ is the scale
// that makes the field's frame integrable, a conformal map's. Around a component C of fixed faces (connected
// through shared vertices: a boundary loop's aligned strip, a feature network, fixed faces) φ changes by the
// period T_C = Σ_{f∈C} Σ_{e∈f} g_fe s_e, which no scale can absorb: a map of this field must stretch by e^{|T_C|}
// somewhere around C. T_C is linear in the right-hand sides: ∂T_C/∂b = (A W Aᵀ)⁻¹ A σ_C with σ_C(e) = Σ_{f∈C∋e}
// g_fe (ConnectionSolver::vertex_duals of σ_C), so a move changes it by exactly c (∂T_C/∂b_v − ∂T_C/∂b_u) with
// the cycle indices held; with period_weight > 0 that change enters the ranking below.
//
// Ranking (docs/solver.md, "Singularity relaxation"). The energy is E = bᵀ M⁻¹ b with M = A W Aᵀ and b the
// right-hand sides (trivcon/solver.h; vertex rows b_v = K_v − 2π n_v/N). Moving n from v to u is
// δb = c (e_v − e_u), c = 2πn/N, so with the cycle rows' right-hand sides held, exactly
//   ΔE = 2c (λ_v − λ_u) + c² R_vu,   λ = M⁻¹ b (ConnectionSolver::vertex_duals),
//   R_vu = (e_v − e_u)ᵀ M⁻¹ (e_v − e_u) ≥ 0, the effective resistance between v and u of the network M.
// The first term costs nothing per candidate once λ is known (one solve per accepted move); R_vu would
// cost a solve each, so it is estimated: R̃ = (1/d_v + 1/d_u)(1 + (√3/π) ln r), d the weighted degree
// Σ w_e at a vertex and r the edges between v and u (1 for a step): between neighbours, the 2/d of an
// edge-transitive network (e.g. a regular triangulation), growing with r as the continuum's (1/π) ln r
// does there; it ignores anisotropy and cycles. A step across an edge that a cycle with a chosen index
// crosses (a free generator, a fixed-face path) may change that index too: moved along
// (δb = c s A e_e, s = +1 when v is the edge's larger id), the first order is the edge's own
// 2c s x_e / w_e, and the smaller of the two first orders is used (a held generator would make R_vu large
// instead, which R̃ does not see). Candidates are ranked by first order + c² R̃, and only those whose
// first order is negative are solved, in that order: since R_vu ≥ 0 no other can lower E unless a solve
// chooses other free indices than the move carries. Each accepted move is the first candidate in rank
// order whose real energy is lower; the duals are then recomputed and the candidates ranked again. A solved
// move's second-order term is kept (exact with the cycles held) and ranks it from then on. When every cycle
// index is held (no free generator, no fixed-face path), a candidate whose lower_bound (or exact prediction) is
// not negative is not solved: it cannot lower the energy; otherwise relax ends with a pass that solves every
// candidate with a negative first order again. Either way the result is a local minimum for single moves
// (greedy: e.g. a cancellation taken early is not undone).
#pragma once
#include <vector>

#include "trivcon/design.h"

namespace trivcon {

struct RelaxOptions {
  std::vector<int> pins;    // vertices that keep their index (none moves away, none arrives)
  std::vector<int> avoid;   // vertices no singularity moves onto (one there may leave)
  double separation = 0;    // > 0: no step brings a singularity closer than this (along edges, mesh units) to
                            // another one, unless they were closer already and it brings them no closer
  int max_moves = 10000;    // accepted moves at most (≥ 0)
  int cancel_distance = 0;  // > 0: an index n may meet a −n at most this many edges away, both vanishing; 0: never
  int reach = 1;            // ≥ 1: a singularity may move to a free vertex at most this many edges away in one move
  double max_seconds = 0;   // > 0: stop after about this long (checked between solves), with the moves made so far
  int max_solves = 0;       // > 0: stop after this many candidate solves, with the moves made so far (unlike
                            // max_seconds, the same result on every machine)
  // > 0: the objective is E + period_weight · P, P = Σ_C T_C² the squared periods of the conformal scale around
  // the components C of fixed faces (see "Periods" above); 0: E alone. Ignored (RelaxResult::periods_used false)
  // with fewer than two components, or when their sensitivities would take more than kMaxPeriodValues numbers.
  double period_weight = 0;
};

// The most numbers (components × vertices) the period sensitivities may take (about 160 MB).
constexpr double kMaxPeriodValues = 2e7;

struct RelaxMove {
  int from = 0, to = 0;
  int index = 0;           // n (index n/N) that moved from `from` to `to`
  double energy = 0;       // the objective after the move (E, plus period_weight · P when the periods are used)
  bool cancelled = false;  // `to` held −n: both vanished
};

struct RelaxResult {
  IndexPrescription prescription;  // the relaxed one (only its vertex indices differ from the start)
  double energy_before = 0, energy_after = 0;  // the field's energy E (Connection::energy)
  std::vector<RelaxMove> moves;
  std::vector<double> energies;  // the objective before, then after each move: strictly decreasing
  bool periods_used = false;     // the objective had the period term (RelaxOptions::period_weight)
  double periods_before = 0, periods_after = 0;  // P = Σ_C T_C² (0 when not used)
  int candidates_evaluated = 0;  // real solves of candidate moves
  bool converged = false;        // stopped because no candidate lowers the energy (not at max_moves, max_seconds or max_solves)
  bool out_of_time = false;      // stopped at max_seconds
  bool out_of_solves = false;    // stopped at max_solves
  double seconds = 0;
};

// A candidate move and its estimated change of energy (see above).
struct RelaxCandidate {
  int from = 0, to = 0;
  int index = 0;         // n moved
  int distance = 1;      // edges between `from` and `to`
  bool cancels = false;  // `to` holds −n
  // 2c (λ_from − λ_to), c = 2πn/N: the exact first-order change with the cycle indices held; across an edge
  // of a free cycle, the smaller of that and 2c s x_e / w_e (the index carried along).
  double first_order = 0;
  double estimate = 0;  // first_order + c² R̃
  // A bound below ΔE when the cycle indices are held: first_order + c² R_lb, R_lb ≤ R_vu the resistance between
  // v and u with every other vertex shorted to one node (Rayleigh's monotonicity: shorting, and the cycle rows'
  // Schur complement, only lower it): 1 / (w_vu + 1 / (1/(d_v − w_vu) + 1/(d_u − w_vu))) for neighbours; for a
  // cancellation further away, and across an edge of a free cycle, just first_order (R ≥ 0).
  double lower_bound = 0;
};

// Every candidate move of `prescription` whose connection from designer.solver() is `connection`, lowest
// estimate first (ties: by from, then to). A cancellation is listed once per pair, from its smaller vertex.
std::vector<RelaxCandidate> relax_candidates(const FieldDesigner& designer, const IndexPrescription& prescription,
                                             const Connection& connection, const RelaxOptions& options = {});

// Whether relax with period_weight > 0 would use the periods with designer's fixed faces (RelaxResult::periods_used:
// at least two components, and their sensitivities within kMaxPeriodValues numbers).
bool periods_usable(const FieldDesigner& designer);
// Relaxes `start` as above; throws trivcon::Error for an invalid prescription (as a design would), a pin out
// of range, a negative max_moves, cancel_distance, max_seconds, max_solves or period_weight, or a reach below 1. Polls
// trivcon/cancel.h once per candidate solve.
RelaxResult relax(const FieldDesigner& designer, const IndexPrescription& start, const RelaxOptions& options = {});

}  // namespace trivcon
