// SPDX-License-Identifier: MIT
// src/connection/assembly.h (internal): the constraint system of the trivial connection as matrices
// (trivcon/solver.h states the system and its signs; docs/solver.md which rows it has and why).
//
// - row_layout / loop_rows: which interior vertices and boundary loops have a row (one vertex dropped per
//   closed component, one loop per component with boundary: Gauss–Bonnet makes them redundant).
// - system_edges / edge_ends / cycle_columns: the columns of A (edges) and A's rows as per-edge data.
// - normal_matrix: the upper triangle of A W Aᵀ in compressed columns, with the rows of A per edge.
#pragma once
#include <Eigen/Core>
#include <Eigen/SparseCore>
#include <array>
#include <functional>
#include <vector>

#include "trivcon/cycles.h"
#include "trivcon/topology.h"

namespace trivcon::connection {

using SparseMatrix = Eigen::SparseMatrix<double>;
using EdgeEnds = std::vector<std::array<int, 2>>;  // per system edge, the vertex rows of its ends (−1: none)

// Upper triangle of the normal matrix M = A W Aᵀ, compressed columns.
struct Csc {
  std::vector<int> outer, inner;
  std::vector<double> values;
};

// The rows of A touching each system edge a (column a of A): row[start[a] … start[a + 1]) with their
// coefficients.
struct EdgeRows {
  std::vector<int> start, row;
  std::vector<double> coefficient;
};

// Upper triangle of A W Aᵀ as a sparse product over the edges (Gustavson's algorithm): column c
// gathers, for each edge a in row c of A, the rows r ≤ c that edge a touches. The rows of A: nV vertex
// rows given per edge by the rows of its two ends (coefficient −1 for ends[a][0], +1 for ends[a][1]; an
// end without a row is −1), then the extra rows Et (m × (nD − nV)), then the cycle rows Ct (m × nC).
// Every product of two rows sharing an edge is an entry, also where w is 0 or the sum cancels: the
// pattern depends on ends, Et and Ct only (SolverAnalysis relies on it). Fills `edges`.
Csc normal_matrix(const EdgeEnds& ends, int nV, const SparseMatrix& Et, const SparseMatrix& Ct, const Eigen::VectorXd& w, EdgeRows& edges);

// Which rows the reduced system has (docs/solver.md): per component the dropped vertex (closed
// component: its largest interior vertex) or loop (with boundary: the longest loop, ties to the smallest
// id), and the row of each other interior vertex (−1: none).
struct RowLayout {
  std::vector<int> vertex_row, dropped_vertex, dropped_loop;
  int num_vertex_rows = 0;
};
RowLayout row_layout(const Topology& t);
// The boundary loops that have a row, in id order.
std::vector<int> loop_rows(const Topology& t, const std::vector<int>& dropped_loop);
// The edges that are columns of A, and each edge's column (−1: none). The Cholesky route takes every
// interior edge: a zero weight gives an entry of zero, which keeps A W Aᵀ's pattern that of the mesh
// whatever the geometry (SolverAnalysis relies on it); the QR route takes the edges of positive weight.
void system_edges(const Topology& t, const Eigen::VectorXd* positive_only, std::vector<int>& edges, std::vector<int>& column);
EdgeEnds edge_ends(const Topology& t, const std::vector<int>& edges, const std::vector<int>& vertex_row);
// Cycles (or paths) as the sparse columns of Aᵀ (m × count); repeated edges of a cycle are summed.
SparseMatrix cycle_columns(int m, const std::vector<int>& column, int count, const std::function<const DualCycle&(int)>& cycle);

}  // namespace trivcon::connection
