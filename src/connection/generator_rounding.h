// SPDX-License-Identifier: MIT
// src/connection/generator_rounding.h (internal): choosing the free whole numbers of a solve (generator and loop
// indices, fixed-face path turns) so that the field is smoothest.
//
// The energy is a quadratic function of the cycle rows' indices n: E = E₀ + (2π/N)² (u − n)ᵀ P (u − n),
// P = S⁻¹ (the engine's, src/connection/solver_engine.h). With the free ones parametrised as n = n₀ + M t,
// nearest_lattice_point minimises it over integer t: Babai's nearest-plane rounding of the real minimiser
// (one coordinate at a time, each given the ones already rounded and the rest still real), then single
// ±1 steps while they lower the energy.
#pragma once
#include <Eigen/Core>

#include "connection/solver_engine.h"

namespace trivcon::connection {

// Rounds the real minimiser u of ‖T (u − n)‖² to integers one coordinate at a time (see above): with T
// lower triangular from the first coordinate on, with T upper triangular from the last one back. Exact
// halves round up, with a margin of 1e-7, so that routes whose round-off differs choose alike on ties.
Eigen::VectorXi babai_round(const Eigen::MatrixXd& T, bool lower, const Eigen::VectorXd& u);

// Minimises (u − n₀ − M t)ᵀ P (u − n₀ − M t) over integer t. `identity`: M = I (every cycle row free,
// the usual case of editing singularities), which costs O(|C|²) per step through the engine's P products;
// otherwise P is formed.
Eigen::VectorXi nearest_lattice_point(const SolverEngine& engine, const Eigen::VectorXd& u, const Eigen::VectorXd& n0,
                                      const Eigen::MatrixXd& M, bool identity);

}  // namespace trivcon::connection
