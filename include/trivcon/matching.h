// SPDX-License-Identifier: MIT
// trivcon/matching.h: how the N directions of neighbouring faces are paired, which a per-face field
// does not store, and what a tool that computes its own pairing will read from our field.
//
// Conventions (trivcon/geometry.h, field.h): across interior edge e, L = edge_faces(e, 0) and
// R = edge_faces(e, 1); a face's N directions are at β + 2πk/N, k = 0 … N − 1, counter-clockwise.
// - A matching gives each interior edge a whole number m_e in [0, N): direction 0 of L, carried into R by
//   parallel transport (angle β_L + ρ_e), is paired with direction m_e of R (angle β_R + 2π m_e / N), and
//   direction k of L with direction k + m_e (mod N) of R. Boundary edges have m_e = 0 (unused).
// - Indices with a matching: d_e = β_R + 2π m_e / N − β_L − ρ_e taken in (−π, π]; a vertex's index is
//   (K_v + Σ s_ve d_e) / 2π, a loop's and a generator's as in trivcon/field.h.
// - principal_matching: the m_e that makes |d_e| smallest (|d_e| ≤ π/N), what Directional's
//   principal_matching, QuadWild and libigl's MIQ compute; field_indices (trivcon/field.h) reads indices
//   with it.
// - connection_matching: the m_e our connection x uses (β_R = β_L + ρ_e − x_e modulo 2π/N): m_e is the
//   whole number of 2π/N steps in β_L + ρ_e − x_e − β_R. With it, d_e = −x_e wherever |x_e| < π, so the
//   indices read with it are exactly the connection's (the prescription) on every cycle whose edges turn
//   by less than π; the principal matching agrees with it only where |x_e| < π/N.
#pragma once
#include <Eigen/Core>
#include <vector>

#include "trivcon/cycles.h"
#include "trivcon/field.h"
#include "trivcon/geometry.h"
#include "trivcon/topology.h"

namespace trivcon {

Eigen::VectorXi principal_matching(const Topology& topology, const Geometry& geometry, const Field& field);
// `x`: the connection the field was propagated with (per edge, trivcon/solver.h).
Eigen::VectorXi connection_matching(const Topology& topology, const Geometry& geometry, const Field& field, const Eigen::VectorXd& x);
// Indices of the field read with the given matching (values taken modulo N).
FieldIndices indices_with_matching(const Topology& topology, const Geometry& geometry, const Cycles& cycles, const Field& field,
                                   const Eigen::VectorXi& matching);
// Interior edges whose connection turns by π/N or more (|x_e| ≥ π/N − 1e-9), in increasing edge id: where
// a principal matching differs from the connection's.
std::vector<int> large_turn_edges(const Topology& topology, const Eigen::VectorXd& x, int N);

}  // namespace trivcon
