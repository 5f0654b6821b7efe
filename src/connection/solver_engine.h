// SPDX-License-Identifier: MIT
// src/connection/solver_engine.h (internal): what ConnectionSolver asks of a factorization of its constraint
// system (trivcon/solver.h): the Cholesky route (cholesky_engine.h) or the QR route (qr_engine.h).
//
// The constraint system lives in the space of the system edges (assembly.h system_edges: every interior
// edge on the Cholesky route, those with w_e > 0 on the QR route): Dt (m × nD) and Ct (m × nC) are the
// transposed constraint rows (vertex rows, then cycle rows), so x_active = W (Dt λ + Ct μ).
#pragma once
#include <Eigen/Core>
#include <functional>
#include <string>

namespace trivcon::connection {

class SolverEngine {
 public:
  virtual ~SolverEngine() = default;
  // Returns x on the system edges for vertex right-hand sides b_D; the cycle right-hand sides b_C are
  // asked from `choose`, given r₀: the real b_C that minimises the energy for this b_D.
  using CycleRhsChooser = std::function<Eigen::VectorXd(const Eigen::VectorXd& r0)>;
  virtual Eigen::VectorXd solve(const Eigen::VectorXd& b_D, const CycleRhsChooser& choose) const = 0;
  // The energy Σ x²/w of that solution without x: ‖L⁻¹ Π b‖² after the forward substitution (the backward half
  // and x are not needed). A negative value on a route that cannot (QR): the caller solves instead.
  virtual double energy(const Eigen::VectorXd& /*b_D*/, const CycleRhsChooser& /*choose*/) const { return -1; }

  // P = S⁻¹ = ((A W Aᵀ)⁻¹) restricted to the cycle rows: the energy's quadratic form in their right-hand sides.
  virtual Eigen::VectorXd apply_P(const Eigen::VectorXd& v) const = 0;
  virtual Eigen::VectorXd P_column(int i) const = 0;
  virtual Eigen::MatrixXd dense_P() const = 0;
  // A triangular T with P = Tᵀ T (for rounding one index at a time, Babai's nearest plane).
  virtual const Eigen::MatrixXd& P_factor(bool& lower) const = 0;
  // The vertex right-hand side most solves differ from in only a few rows (the angle defects: no
  // singularity), so that a solve can update a stored forward substitution instead of redoing it.
  virtual void set_base_rhs(const Eigen::VectorXd& /*b_D*/) {}
  // One step of iterative refinement with the factor at hand: x += W Aᵀ (A W Aᵀ)⁻¹ (b − A x), for the
  // full right-hand side b = [b_D; b_C] (vertex rows, then cycle rows, as solve() used them). Returns
  // false, leaving x, on a route that has nothing to refine (QR solves the constraints directly).
  virtual bool refine(const Eigen::VectorXd& /*b*/, Eigen::VectorXd& /*x*/) const { return false; }
  // y = (A W Aᵀ)⁻¹ A x in row order (vertex rows, then the extra rows, then the cycle rows, as solve()
  // used them), for x on the system edges. For an x that solve() returned, A x is the right-hand side it
  // met, so y are the constraints' Lagrange multipliers (the energy bᵀ (A W Aᵀ)⁻¹ b has gradient 2y in b).
  virtual Eigen::VectorXd multipliers(const Eigen::VectorXd& x) const = 0;
  // The fill-reducing order the factorization used.
  virtual std::string ordering() const = 0;
  // diag(P)
  const Eigen::VectorXd& P_diagonal() const { return P_diagonal_; }

 protected:
  Eigen::VectorXd P_diagonal_;
};

}  // namespace trivcon::connection
