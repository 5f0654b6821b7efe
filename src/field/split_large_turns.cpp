// SPDX-License-Identifier: MIT
#include "trivcon/split_large_turns.h"

#include <numeric>

#include "trivcon/cancel.h"
#include "trivcon/error.h"
#include "trivcon/generate.h"
#include "trivcon/matching.h"

namespace trivcon {

RefinedDesign split_large_turns(const FieldDesigner& designer, const MatrixX3i& F, const IndexPrescription& prescription,
                                const SolverOptions& options,
                                const RefinedFixedFaces& constraints, int max_rounds, const std::vector<std::pair<int, double>>& roots) {
  if (!prescription.generator.empty() || !prescription.loop.empty())
    throw Error("splitting large turns makes new generators and boundary loops: leave their indices to be chosen");
  if (max_rounds < 0) throw Error("splitting large turns: max_rounds must be at least 0, not " + std::to_string(max_rounds));
  // The prescription's fixed directions as world vectors, per input face (the default constraints).
  std::map<int, Eigen::Vector3d> fixed_world;
  for (auto [f, angle] : prescription.fixed) fixed_world[f] = designer.geometry().direction_in_face(f, angle);
  RefinedDesign out;
  out.V = designer.V();
  if (F.rows() != designer.topology().num_faces)
    throw Error("splitting large turns: " + std::to_string(F.rows()) + " faces given for a designer of " +
                std::to_string(designer.topology().num_faces));
  out.F = F;
  out.parent_face.resize(designer.topology().num_faces);
  std::iota(out.parent_face.begin(), out.parent_face.end(), 0);
  out.prescription = prescription;
  const FieldDesigner* current = &designer;
  int splits = 0, reweights = 0;
  bool reweighting = false;  // once splitting stalls, only the weights change
  for (int round = 0;; ++round) {
    check_cancelled();  // trivcon/cancel.h
    out.design = current->design(out.prescription, round == 0 ? roots : std::vector<std::pair<int, double>>{});
    const std::vector<int> large = large_turn_edges(current->topology(), out.design.connection.x, out.prescription.N);
    if (large.empty()) {
      out.converged = true;
      break;
    }
    reweighting = reweighting || splits >= max_rounds;
    if (reweighting) {
      if (reweights == 3 * max_rounds) break;
      ++reweights;
      // Lower the weights of the edges still turning too much (see trivcon/split_large_turns.h), on a designer of our own.
      if (!out.designer) {
        out.designer = std::make_unique<FieldDesigner>(out.V, out.F, options);
        std::vector<int> faces;
        for (auto [f, angle] : out.prescription.fixed) faces.push_back(f);
        out.designer->set_fixed_faces(faces);
        current = out.designer.get();
      }
      SolverOptions lighter = out.designer->solver_options();
      if (lighter.edge_weight_scale.empty()) lighter.edge_weight_scale.assign(out.designer->topology().num_edges, 1.0);
      for (int e : large) lighter.edge_weight_scale[e] *= 0.5;
      out.designer->set_solver_options(lighter);
      out.rounds.push_back({static_cast<int>(large.size()), static_cast<int>(out.V.rows()), static_cast<int>(out.F.rows()), true});
      continue;
    }
    ++splits;
    std::vector<int> beside;
    for (int e : large) beside.push_back(current->topology().edge_faces(e, 0)), beside.push_back(current->topology().edge_faces(e, 1));
    std::vector<int> step_parent;
    const Mesh next = split_faces_at_centroids(Mesh{out.V, out.F}, beside, &step_parent);
    std::vector<int> composed(step_parent.size());
    for (size_t f = 0; f < step_parent.size(); ++f) composed[f] = out.parent_face[step_parent[f]];
    out.parent_face.swap(composed);
    out.V = next.V, out.F = next.F;
    out.designer = std::make_unique<FieldDesigner>(out.V, out.F, options);
    current = out.designer.get();
    out.prescription.fixed.clear();
    if (constraints) {
      out.prescription.fixed = constraints(*current, out.parent_face);
    } else {
      for (int f = 0; f < static_cast<int>(out.parent_face.size()); ++f) {
        const auto it = fixed_world.find(out.parent_face[f]);
        if (it != fixed_world.end()) out.prescription.fixed[f] = current->geometry().angle_in_face(f, it->second);
      }
    }
    std::vector<int> faces;
    for (auto [f, angle] : out.prescription.fixed) faces.push_back(f);
    out.designer->set_fixed_faces(faces);
    out.rounds.push_back({static_cast<int>(large.size()), static_cast<int>(out.V.rows()), static_cast<int>(out.F.rows())});
  }
  return out;
}

}  // namespace trivcon
