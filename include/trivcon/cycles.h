// SPDX-License-Identifier: MIT
// trivcon/cycles.h: the dual cycles whose holonomy a trivial connection must control (paper 2.1, 2.6).
//
// A dual cycle is a closed walk over faces, stored as signed interior edges: sign +1 where the walk
// crosses edge e from L = edge_faces(e, 0) to R = edge_faces(e, 1), −1 for R to L.
// - Vertex cycle of an interior vertex v: the faces around v counter-clockwise (seen from the
//   normal). It crosses edge (u, v) from L to R when v is the larger id, so its coefficients are
//   s = +1 if v is the edge's larger id, −1 otherwise (this is d0ᵀ; it is not stored here).
// - Boundary-loop cycle of loop ℓ: the sum of the vertex cycles of the loop's vertices, restricted to
//   interior edges; edges joining two vertices of the loop cancel. It goes around the hole the way the
//   vertex cycles go around a vertex, as if the hole were capped by one "virtual" vertex.
// - Generators (handle cycles): per component, exactly 2g cycles from a tree-cotree decomposition of
//   the surface with each boundary loop contracted to a point (Eppstein 2003; paper 2.1 and 2.6):
//   a breadth-first primal tree over interior vertices and loop points using interior edges, a
//   breadth-first dual tree over the faces using the remaining interior edges, and one generator per
//   interior edge in neither tree: cross it from L to R, then return to L through the dual tree.
//   Together, the vertex cycles, b − 1 of the loop cycles and the 2g generators of a component are a
//   basis of its dual cycles (2g + b − 1 non-contractible ones, counted and checked).
// Generators depend on the ids (they follow breadth-first trees from the component's smallest face and
// vertex ids) but the set of fields they allow does not.
#pragma once
#include <vector>

#include "trivcon/geometry.h"
#include "trivcon/topology.h"

namespace trivcon {

struct DualCycle {
  std::vector<int> edges;
  std::vector<int> signs;  // +1 or −1, parallel to edges
  int component = 0;
};

struct Cycles {
  std::vector<DualCycle> generators;  // grouped by component, components in order
  std::vector<DualCycle> loops;       // one per boundary loop, same ids as Topology::boundary_loops
};

Cycles compute_cycles(const Topology& topology);

// Σ sign · value_e along the cycle, for any per-edge quantity (e.g. a connection's x).
double cycle_sum(const DualCycle& cycle, const Eigen::VectorXd& per_edge);

// Σ sign · ρ_e along the cycle: the Levi-Civita holonomy with each ρ_e taken in (−π, π].
double levi_civita_holonomy(const DualCycle& cycle, const Geometry& geometry);
// Σ over the loop's vertices of (π − Σ corner angles): the curvature of the virtual vertex capping loop ℓ
// (Gauss–Bonnet: Σ interior angle defects + Σ loop curvatures = 2π χ per component).
double loop_curvature(const Topology& topology, const Geometry& geometry, int loop);

}  // namespace trivcon
