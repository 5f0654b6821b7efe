// SPDX-License-Identifier: MIT
// Matchings of a per-face field across edges (trivcon/matching.h).
#include "trivcon/matching.h"

#include <cmath>

#include "trivcon/error.h"

namespace trivcon {

namespace {
int modulo(long long a, int N) { return static_cast<int>(((a % N) + N) % N); }
// The whole number of 2π/N steps nearest to `angle`, modulo N.
int steps_of(double angle, int N) { return modulo(std::llround(angle * N / (2 * kPi)), N); }
}  // namespace

Eigen::VectorXi principal_matching(const Topology& t, const Geometry& g, const Field& field) {
  Eigen::VectorXi m = Eigen::VectorXi::Zero(t.num_edges);
  for (int e = 0; e < t.num_edges; ++e) {
    if (t.is_boundary_edge(e)) continue;
    // d_e = β_R + 2πm/N − β_L − ρ_e smallest: 2πm/N nearest to β_L + ρ_e − β_R.
    m(e) = steps_of(field.angle(t.edge_faces(e, 0)) + g.rho(e) - field.angle(t.edge_faces(e, 1)), field.N);
  }
  return m;
}

Eigen::VectorXi connection_matching(const Topology& t, const Geometry& g, const Field& field, const Eigen::VectorXd& x) {
  if (x.size() != t.num_edges)
    throw Error("connection_matching: the connection has " + std::to_string(x.size()) + " values, the mesh " + std::to_string(t.num_edges) +
                " edges");
  Eigen::VectorXi m = Eigen::VectorXi::Zero(t.num_edges);
  for (int e = 0; e < t.num_edges; ++e) {
    if (t.is_boundary_edge(e)) continue;
    m(e) = steps_of(field.angle(t.edge_faces(e, 0)) + g.rho(e) - x(e) - field.angle(t.edge_faces(e, 1)), field.N);
  }
  return m;
}

FieldIndices indices_with_matching(const Topology& t, const Geometry& g, const Cycles& cycles, const Field& field,
                                   const Eigen::VectorXi& matching) {
  if (matching.size() != t.num_edges)
    throw Error("the matching has " + std::to_string(matching.size()) + " values, the mesh " + std::to_string(t.num_edges) + " edges");
  const int N = field.N;
  Eigen::VectorXd d = Eigen::VectorXd::Zero(t.num_edges);
  for (int e = 0; e < t.num_edges; ++e) {
    if (t.is_boundary_edge(e)) continue;
    d(e) = wrap_angle(field.angle(t.edge_faces(e, 1)) + 2 * kPi * modulo(matching(e), N) / N - field.angle(t.edge_faces(e, 0)) - g.rho(e));
  }
  return indices_from_jumps(t, g, cycles, d, N);
}

std::vector<int> large_turn_edges(const Topology& t, const Eigen::VectorXd& x, int N) {
  std::vector<int> out;
  const double limit = kPi / N - 1e-9;
  for (int e = 0; e < t.num_edges; ++e)
    if (!t.is_boundary_edge(e) && std::abs(x(e)) >= limit) out.push_back(e);
  return out;
}

}  // namespace trivcon
