// SPDX-License-Identifier: MIT
#include "trivcon/field.h"

#include <cmath>

#include "trivcon/error.h"

namespace trivcon {

namespace {
constexpr int kParallelFaces = 100000;  // propagate_field's per-face loops run on all cores (OpenMP) above this
}  // namespace


PropagationPlan plan_propagation(const Topology& t) {
  PropagationPlan plan;
  plan.order.reserve(t.num_faces);
  plan.parent.reserve(t.num_faces);
  plan.edge.reserve(t.num_faces);
  plan.sign.reserve(t.num_faces);
  std::vector<char> seen(t.num_faces, 0);
  for (const ComponentInfo& c : t.components) {
    plan.component_begin.push_back(static_cast<int>(plan.order.size()));
    seen[c.first_face] = 1;
    plan.order.push_back(c.first_face);
    plan.parent.push_back(-1), plan.edge.push_back(-1), plan.sign.push_back(0);
    for (size_t q = plan.component_begin.back(); q < plan.order.size(); ++q) {
      const int f = plan.order[q];
      for (int k = 0; k < 3; ++k) {
        const int e = t.face_edges(f, k);
        if (t.is_boundary_edge(e)) continue;
        const bool from_left = t.edge_faces(e, 0) == f;
        const int h = from_left ? t.edge_faces(e, 1) : t.edge_faces(e, 0);
        if (seen[h]) continue;
        seen[h] = 1;
        plan.order.push_back(h);
        plan.parent.push_back(static_cast<int>(q)), plan.edge.push_back(e), plan.sign.push_back(from_left ? 1 : -1);
      }
    }
  }
  plan.component_begin.push_back(static_cast<int>(plan.order.size()));
  return plan;
}

Field propagate_field(const Topology& t, const Geometry& g, const PropagationPlan& plan, const Eigen::VectorXd& x, int N,
                      const std::vector<std::pair<int, double>>& roots) {
  Field field;
  field.N = N;
  const int nF = t.num_faces;
  if (static_cast<int>(plan.order.size()) != nF || plan.component_begin.size() != t.components.size() + 1)
    throw Error("the propagation plan was made for another mesh");
  // Angles are summed unwrapped along the tree in plan order (exact up to round-off), then each
  // component is shifted to its root angle and every face's angle wrapped once.
  // The turn into each face is read first on all cores (scattered reads), then summed in order.
  std::vector<double> along(nF);
#pragma omp parallel for schedule(static) if (nF > kParallelFaces)
  for (int q = 0; q < nF; ++q) {
    const int e = plan.edge[q];
    along[q] = e < 0 ? 0.0 : plan.sign[q] * (g.rho(e) - x(e));
  }
  for (int q = 0; q < nF; ++q)
    if (plan.edge[q] >= 0) along[q] += along[plan.parent[q]];
  std::vector<double> shift(t.components.size(), 0.0);
  std::vector<char> rooted(t.components.size(), 0);
  std::vector<int> position;
  if (!roots.empty()) {
    position.resize(nF);
    for (int q = 0; q < nF; ++q) position[plan.order[q]] = q;
  }
  for (auto [f, angle] : roots) {
    if (f < 0 || f >= nF) throw Error("root face " + std::to_string(f) + " out of range (mesh has " + std::to_string(nF) + " faces)");
    if (!std::isfinite(angle)) throw Error("root angle of face " + std::to_string(f) + " is not finite");
    const int c = t.face_component[f];
    if (rooted[c]) throw Error("two root faces given for component " + std::to_string(c));
    rooted[c] = 1;
    shift[c] = angle - along[position[f]];
  }
  field.angle.resize(nF);
  const int nC = static_cast<int>(t.components.size());
  for (int c = 0; c < nC; ++c) {
    const int begin = plan.component_begin[c], end = plan.component_begin[c + 1];
#pragma omp parallel for schedule(static) if (end - begin > kParallelFaces)
    for (int q = begin; q < end; ++q) field.angle(plan.order[q]) = wrap_two_pi(along[q] + shift[c]);
  }
  return field;
}

Field propagate_field(const Topology& t, const Geometry& g, const Eigen::VectorXd& x, int N,
                      const std::vector<std::pair<int, double>>& roots) {
  return propagate_field(t, g, plan_propagation(t), x, N, roots);
}

MatrixX3d field_directions(const Geometry& g, const Field& field) {
  MatrixX3d d(field.angle.size(), 3);
  for (int f = 0; f < field.angle.size(); ++f) d.row(f) = g.direction_in_face(f, field.angle(f));
  return d;
}

Field field_from_directions(const Geometry& g, const MatrixX3d& directions, int N) {
  Field field;
  field.N = N;
  field.angle.resize(directions.rows());
  for (int f = 0; f < directions.rows(); ++f) {
    const Eigen::Vector3d d = directions.row(f);
    if (!d.allFinite()) throw Error("the direction of face " + std::to_string(f) + " is not finite");
    const double along = std::hypot(d.dot(g.frame_x.row(f)), d.dot(g.frame_y.row(f)));
    if (!(along > 1e-12 * d.norm())) throw Error("the direction of face " + std::to_string(f) + " has no component in the face's plane");
    field.angle(f) = wrap_two_pi(g.angle_in_face(f, d));
  }
  return field;
}

FieldIndices field_indices(const Topology& t, const Geometry& g, const Cycles& cycles, const Field& field) {
  const int N = field.N;
  Eigen::VectorXd d = Eigen::VectorXd::Zero(t.num_edges);
  for (int e = 0; e < t.num_edges; ++e) {
    if (t.is_boundary_edge(e)) continue;
    d(e) = reduce_angle(field.angle(t.edge_faces(e, 1)) - field.angle(t.edge_faces(e, 0)) - g.rho(e), N);
  }
  return indices_from_jumps(t, g, cycles, d, N);
}

FieldIndices indices_from_jumps(const Topology& t, const Geometry& g, const Cycles& cycles, const Eigen::VectorXd& d, int N) {
  FieldIndices out;
  auto to_n = [&](double raw_turns) {
    const double scaled = raw_turns * N;
    const double rounded = std::round(scaled);
    out.max_rounding = std::max(out.max_rounding, std::abs(scaled - rounded));
    return static_cast<int>(rounded);
  };
  Eigen::VectorXd sum = Eigen::VectorXd::Zero(t.num_vertices);
  for (int e = 0; e < t.num_edges; ++e) {
    sum(t.edge_vertices(e, 1)) += d(e);
    sum(t.edge_vertices(e, 0)) -= d(e);
  }
  out.vertex.assign(t.num_vertices, 0);
  for (int v = 0; v < t.num_vertices; ++v)
    if (t.is_interior_vertex(v)) out.vertex[v] = to_n((g.angle_defect(v) + sum(v)) / (2 * kPi));
  for (size_t l = 0; l < cycles.loops.size(); ++l)
    out.loop.push_back(to_n((loop_curvature(t, g, static_cast<int>(l)) + cycle_sum(cycles.loops[l], d)) / (2 * kPi)));
  for (const DualCycle& c : cycles.generators) out.generator.push_back(to_n((levi_civita_holonomy(c, g) + cycle_sum(c, d)) / (2 * kPi)));
  return out;
}

double max_transport_mismatch(const Topology& t, const Geometry& g, const Eigen::VectorXd& x, const Field& field) {
  double worst = 0;
  for (int e = 0; e < t.num_edges; ++e) {
    if (t.is_boundary_edge(e)) continue;
    const double jump = field.angle(t.edge_faces(e, 1)) - field.angle(t.edge_faces(e, 0)) - (g.rho(e) - x(e));
    worst = std::max(worst, std::abs(reduce_angle(jump, field.N)));
  }
  return worst;
}

}  // namespace trivcon
