// SPDX-License-Identifier: MIT
// src/connection/qr_engine.h (internal): the paper-literal route of ConnectionSolver (SolverKind::QR): the
// minimum-norm solution of the full weighted constraint system by SuiteSparseQR, from one QR
// factorization of (A W^½)ᵀ reused for every right-hand side (x = W^½ Q R⁻ᵀ Eᵀ b, as SPQR's min2norm).
#pragma once
#include <memory>

#include "connection/assembly.h"
#include "connection/solver_engine.h"
#include "trivcon/solver.h"

namespace trivcon::connection {

// Dt (m × nD) and Ct (m × nC): the transposed vertex and cycle rows over the system edges, w their weights.
// Throws trivcon::Error when the system is rank deficient.
std::unique_ptr<SolverEngine> make_qr_engine(const SparseMatrix& Dt, const SparseMatrix& Ct, const Eigen::VectorXd& w,
                                             SetupTimings& timings);

}  // namespace trivcon::connection
