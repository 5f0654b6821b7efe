// SPDX-License-Identifier: MIT
// trivcon/solver.h: the trivial connection closest to Levi-Civita (paper Sections 2.3–2.6, 3).
// How it is solved and why (the two routes, ordering, edits, refinement, fixed-face paths, free indices):
// docs/solver.md.
//
// Unknowns: one adjustment angle x_e per interior edge, with the sign convention of trivcon/geometry.h:
// a direction at angle β_L in L = edge_faces(e, 0) is carried to β_R = β_L + ρ_e − x_e in
// R = edge_faces(e, 1) (paper Eq. 3). Constraints, with indices k = n/N:
//   interior vertex v:      Σ_e s_ve x_e = K_v − 2π k_v      (s_ve = +1 if v is e's larger id, else −1)
//   boundary loop ℓ:        Σ_e c_e x_e  = K_ℓ − 2π k_ℓ      (c: the loop cycle, K_ℓ its loop_curvature)
//   generator γ:            Σ_e c_e x_e  = z_γ − 2π k_γ      (z_γ = levi_civita_holonomy)
//   fixed-face path:        a whole number of 1/N turns between two fixed directions (trivcon/constraints.h)
// Objective: minimise Σ x_e² / w_e (cotan or unit weights, trivcon/geometry.h). x_e = 0 where w_e = 0,
// except on the edges given 1e-6 × the median positive weight where x = 0 would make the constraints
// unsatisfiable (regularized_edges()). Generator and loop indices not prescribed, and every path's turns,
// are chosen so that the field is smoothest. Every solve is verified; above 2.5e-10 × max(1, rhs_scale)
// up to 3 steps of iterative refinement follow. Angles in radians; errors throw trivcon::Error.
#pragma once
#include <Eigen/Core>
#include <functional>
#include <memory>
#include <string>
#include <vector>

#include "trivcon/constraints.h"
#include "trivcon/cycles.h"
#include "trivcon/geometry.h"
#include "trivcon/indices.h"
#include "trivcon/topology.h"

namespace trivcon {

enum class WeightKind { Cotan, Unit };
enum class SolverKind { Cholesky, QR };
// Who computes the Cholesky route's numeric factor: trivcon's own supernodal factorization on several
// threads (Parallel: the default, independent subtrees of the elimination tree on OpenMP threads, then the
// top of the tree with multithreaded BLAS), or CHOLMOD's cholmod_factorize (Cholmod: the reference, slower; it and
// SolverKind::QR only in a build with -DTRIVCON_WITH_SUITESPARSE=ON, as CHOLMOD's Debian build has GPL modules and
// SuiteSparseQR is GPL: elsewhere asking for them throws trivcon::Error saying so). Construction throws trivcon::Error
// if the BLAS (or CHOLMOD, where linked) loaded is not the kind the library was built for (src/linalg/numeric_libraries.h).
enum class Factorization { Parallel, Cholmod };

struct SolverOptions {
  WeightKind weights = WeightKind::Cotan;
  SolverKind solver = SolverKind::Cholesky;
  Factorization factorization = Factorization::Parallel;
  // With cotan weights: every interior edge gets at least weight_floor × the median positive weight (0:
  // none, the default). A floor lets the field turn across edges whose clamped cotangents are 0 or
  // nearly so, instead of piling that turning onto their neighbours (BENCHMARKS.md "Weights that spread
  // turning" measures what it does to large turns and energies). In [0, 1].
  double weight_floor = 0;
  // Per edge (empty: none): each interior edge's weight is multiplied by edge_weight_scale[e] > 0 after the
  // rest of the policy (split_large_turns, trivcon/split_large_turns.h, lowers the weights of edges that keep turning
  // by π/N or more). Its size must be the edge count.
  std::vector<double> edge_weight_scale = {};
  // Beyond this many fixed-face paths the Cholesky route keeps them out of the dense block and rounds each
  // path's turn on its own (docs/solver.md, "Fixed-face paths"); up to it, every path's turn is chosen with
  // the cycles (nearest lattice point), the smoother field. The dense block costs about paths³ (BENCHMARKS.md,
  // "Fixed-face paths: the dense route up to 2,048"). 0: always the sparse route.
  int max_dense_paths = 2048;
};

struct Connection {
  int N = 1;
  Eigen::VectorXd x;                   // per edge; 0 on boundary edges and on edges of zero weight
  std::vector<int> generator_index;    // n per generator (index n/N), as used
  std::vector<int> loop_index;         // n per boundary loop, as used
  std::vector<char> generator_chosen;  // 1 where the solver chose the index
  std::vector<char> loop_chosen;
  std::vector<int> path_turn;  // per fixed-face path, the whole number j of 1/N turns chosen
  // How they were chosen: with the cycles (the dense route), or path by path (SolverOptions::max_dense_paths) from
  // IndexPrescription::path_guide when given, else as the smallest turn.
  enum class PathTurns { WithTheCycles, FromTheGuide, Smallest } path_turns = PathTurns::WithTheCycles;
  double energy = 0;           // Σ x_e² / w_e
  // Verification: largest |Σ coefficient · x − right-hand side| over all interior vertices (including
  // the dropped ones), all loops and all generators, and the scale of the right-hand sides.
  double max_vertex_residual = 0, max_cycle_residual = 0, rhs_scale = 0;
  // Steps of iterative refinement the solve took, at most 3 (0 on most meshes; docs/solver.md).
  int refinements = 0;
};

struct SetupTimings {
  // assemble: weights, constraint rows, A W Aᵀ; factor: ordering, symbolic analysis (unless a
  // SolverAnalysis was adopted), numeric factorization; schur: the Schur complement's inverse factor and
  // the stored forward substitution; analysis_wait: time spent waiting for a given SolverAnalysis.
  double assemble = 0, factor = 0, schur = 0, analysis_wait = 0;
  bool analysis_adopted = false;  // the factorization used the given SolverAnalysis
  // Who computed the Cholesky factor's values: "trivcon" (Factorization::Parallel) or "cholmod"
  // (Factorization::Cholmod); "" on the QR route and for an empty system.
  std::string numeric_factorization;
};

namespace connection {
struct AnalysisState;
}

// The fill-reducing order and the symbolic factorization of the Cholesky route's A W Aᵀ for a mesh
// without fixed faces. The pattern of A W Aᵀ is that of the mesh's vertices, interior edges and cycles
// (an edge of zero weight is an explicit zero): it does not depend on the geometry or the weights, so
// this part of the set-up can run on another thread while the geometry is computed (FieldDesigner does).
// A ConnectionSolver given one adopts it when the pattern it assembles is exactly the one analysed
// (compared entry by entry), and analyses its own otherwise.
class SolverAnalysis {
 public:
  SolverAnalysis(const Topology& topology, const Cycles& cycles);
  ~SolverAnalysis();
  SolverAnalysis(SolverAnalysis&&) noexcept;
  SolverAnalysis& operator=(SolverAnalysis&&) noexcept;
  double seconds() const;  // how long the analysis took (on whichever thread ran it)

 private:
  std::unique_ptr<connection::AnalysisState> state_;
  friend class ConnectionSolver;
};

class ConnectionSolver {
 public:
  // Builds and factors everything that does not depend on the prescription. Throws trivcon::Error if a
  // factorization fails (e.g. cycle rows made dependent by the weights).
  // `fixed_faces`: faces whose direction each prescription fixes (trivcon/constraints.h); they change the
  // matrix, their angles only the right-hand side. `analysis`, if given, is called once A W Aᵀ is
  // assembled, for a SolverAnalysis of this topology and these cycles (e.g. one computed concurrently);
  // only the Cholesky route without fixed faces calls it. The solver keeps references to `topology`,
  // `geometry` and `cycles`: they must outlive it.
  ConnectionSolver(const Topology& topology, const Geometry& geometry, const Cycles& cycles, SolverOptions options = {},
                   const std::vector<int>& fixed_faces = {}, const std::function<SolverAnalysis()>& analysis = {});
  ~ConnectionSolver();
  ConnectionSolver(const ConnectionSolver&) = delete;
  ConnectionSolver& operator=(const ConnectionSolver&) = delete;

  // Validates the prescription and returns the connection. Only right-hand sides change per call.
  Connection solve(const IndexPrescription& prescription) const;
  // The energy of that connection (Connection::energy) without the connection itself: the forward half of the
  // substitution only, for ranking many prescriptions (the relaxation's candidates). It equals solve()'s energy
  // up to round-off, before solve()'s iterative refinement (which only meshes of extreme weights need).
  double energy(const IndexPrescription& prescription) const;
  // The Lagrange multipliers of the vertex rows for a connection this solver returned, per vertex:
  // λ = (A W Aᵀ)⁻¹ A x restricted to them, 0 where a vertex has no row (boundary and unreferenced vertices,
  // each closed component's dropped vertex). With the cycle rows' right-hand sides held at those the
  // connection used, E = bᵀ (A W Aᵀ)⁻¹ b, so ∂E/∂b_v = 2 λ_v (b_v = K_v − 2π k_v): moving index n/N from v
  // to u changes E by 2 (2πn/N)(λ_v − λ_u) to first order (trivcon/relax.h). Costs one solve's substitutions.
  Eigen::VectorXd vertex_duals(const Connection& connection) const;

  const Eigen::VectorXd& weights() const;  // per edge, 0 on boundary edges
  const SetupTimings& timings() const;
  // The fill-reducing order of the factorization: "AMD" or "CAMD" (the Cholesky route, docs/solver.md),
  // or "SuiteSparseQR default".
  std::string ordering() const;
  int num_generators() const;
  // Levi-Civita holonomy the constraints use: K_ℓ per loop, z_γ per generator.
  const std::vector<double>& loop_curvatures() const;
  const std::vector<double>& generator_holonomies() const;
  const std::vector<int>& fixed_faces() const;  // sorted, without repeats
  // Zero-weight edges given the small regularizing weight (see above; docs/solver.md "The objective").
  int regularized_edges() const;
  int floored_edges() const;  // interior edges raised to SolverOptions::weight_floor
  const std::vector<FixedPath>& fixed_paths() const;
  // Whether the paths' whole turns are read per path (IndexPrescription::path_guide), not chosen with the
  // cycles: more than SolverOptions::max_dense_paths paths on the Cholesky route.
  bool sparse_paths() const;

 private:
  struct Impl;
  std::unique_ptr<Impl> impl_;
};

// Residuals of `x` against every constraint for the given indices (n/N): fills the verification fields.
// The loops' curvatures and the generators' Levi-Civita holonomies are computed from the geometry unless
// given (a ConnectionSolver gives the ones it computed at set-up, so that an edit does not redo them).
void verify_connection(const Topology& topology, const Geometry& geometry, const Cycles& cycles, const IndexPrescription& prescription,
                       Connection& connection, const std::vector<double>* loop_curvatures = nullptr,
                       const std::vector<double>* generator_holonomies = nullptr);

}  // namespace trivcon
