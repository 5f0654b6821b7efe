// SPDX-License-Identifier: MIT
// trivcon/field.h: direction fields from a connection (paper Section 2.7), and the indices of any field.
//
// A field stores one angle per face, in the face's frame (trivcon/geometry.h): the first of its N
// directions; the others are at +2πk/N.
// - propagate_field walks a breadth-first spanning tree of faces from one root per component and sets
//   β_R = β_L + ρ_e − x_e across each tree edge (paper Eq. 3; β_L = β_R − ρ_e + x_e the other way).
//   Roots: the given (face, angle) pairs; components without one start at their smallest face id, angle 0.
//   Because the connection is trivial, the result does not depend on the tree.
// - field_indices reads indices off a field alone: across interior edge e the field's jump relative to
//   parallel transport, d_e = β_R − β_L − ρ_e, is reduced to (−π/N, π/N] (the closest matching of the
//   N directions); the index of a vertex is (K_v + Σ s_ve d_e) / 2π, of a loop (K_ℓ + Σ c_e d_e) / 2π, of a
//   generator (z_γ + Σ c_e d_e) / 2π, each a multiple of 1/N. It equals the connection's index wherever
//   |x_e| < π/N on the cycle's edges; a larger turn across one edge (very large indices on coarse meshes)
//   is invisible in a field sampled once per face.
#pragma once
#include <Eigen/Core>
#include <utility>
#include <vector>

#include "trivcon/angles.h"  // reduce_angle, declared here before
#include "trivcon/cycles.h"
#include "trivcon/geometry.h"
#include "trivcon/topology.h"

namespace trivcon {

struct Field {
  int N = 1;
  Eigen::VectorXd angle;  // per face, in [0, 2π)
};

Field propagate_field(const Topology& topology, const Geometry& geometry, const Eigen::VectorXd& x, int N,
                      const std::vector<std::pair<int, double>>& roots = {});

// The spanning tree of propagate_field, built once per mesh so that each new connection costs one
// linear pass: faces in breadth-first order from each component's smallest face (components one after
// another), with the edge and direction by which each face is reached. A root elsewhere, or another
// root angle, only rotates its component's field by a constant.
struct PropagationPlan {
  std::vector<int> order;            // faces, component by component
  std::vector<int> component_begin;  // where each component starts in `order` (size components + 1)
  // Per position q in `order` (so that a pass reads them in sequence): the position of the face that
  // order[q] is reached from and the edge it crosses (−1 at roots), and +1 when it crosses from L to R.
  std::vector<int> parent, edge;
  std::vector<signed char> sign;
};
PropagationPlan plan_propagation(const Topology& topology);
Field propagate_field(const Topology& topology, const Geometry& geometry, const PropagationPlan& plan, const Eigen::VectorXd& x, int N,
                      const std::vector<std::pair<int, double>>& roots = {});

// World-space unit vectors (F × 3) of the first direction of each face.
MatrixX3d field_directions(const Geometry& geometry, const Field& field);
// Angles of world-space vectors projected onto each face (a zero or non-finite vector is an error naming the face).
Field field_from_directions(const Geometry& geometry, const MatrixX3d& directions, int N);

struct FieldIndices {
  std::vector<int> vertex;     // n (index n/N) per vertex; 0 for boundary and unreferenced vertices
  std::vector<int> loop;       // per boundary loop
  std::vector<int> generator;  // per generator
  double max_rounding = 0;     // largest distance of a raw index·N from an integer (a consistency check)
};
FieldIndices field_indices(const Topology& topology, const Geometry& geometry, const Cycles& cycles, const Field& field);
// The indices given the field's jump d_e relative to parallel transport on every interior edge (0 on
// boundary edges): what field_indices does after choosing the closest matching, and indices_with_matching
// (trivcon/matching.h) after applying a given one.
FieldIndices indices_from_jumps(const Topology& topology, const Geometry& geometry, const Cycles& cycles, const Eigen::VectorXd& jumps,
                                int N);

// Largest |β_R − β_L − (ρ_e − x_e)| over interior edges, reduced modulo 2π/N: 0 when the field is
// exactly the one the connection x transports.
double max_transport_mismatch(const Topology& topology, const Geometry& geometry, const Eigen::VectorXd& x, const Field& field);


}  // namespace trivcon
