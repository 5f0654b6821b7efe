// SPDX-License-Identifier: MIT
// trivcon/split_large_turns.h: refining a mesh where the connection turns by π/N or more, so that every consumer's
// own matching reads exactly the prescribed singularities (solve --split-large-turns).
//
// A tool that pairs each face's directions with its neighbour's by the closest direction (Directional,
// QuadWild, libigl's MIQ) agrees with our connection only across edges with |x_e| < π/N
// (trivcon/matching.h). split_large_turns() solves, splits the two faces beside every edge with
// |x_e| ≥ π/N at their centroids (split_faces_at_centroids, trivcon/generate.h: the surface is kept
// exactly, every corner of a split face gains an edge, so the turning around a vertex spreads over more
// edges), and solves again with the same vertex singularities, until no edge turns that much or
// `max_rounds` rounds are done.
//
// Ids: the input's vertices keep their ids (new vertices, the centroids, are appended); a split face keeps
// its id for its first child, the others are appended (parent_face gives each face's input face).
// Generators and boundary loops of the refined mesh are new cycles: their indices are chosen smoothest
// (a prescription that sets any is refused). The fixed directions of each refined mesh come from
// `constraints` (e.g. boundary or feature alignment found again on it); without it, each fixed face of the
// prescription passes its direction (as a world vector) to all its children.
//
// Splitting does not always finish: a centroid split gives the split face's old edges an obtuse angle
// opposite them, whose clamped cotangent forbids turning there, and the turning moves on. When the
// `max_rounds` rounds of splitting leave large turns, the weights of the edges still turning by π/N or
// more are halved on the final mesh (SolverOptions::edge_weight_scale) and it is solved again, up to
// 3 × `max_rounds` times: a lighter edge turns less, its neighbours take the rest. (Splitting is needed
// first: a vertex whose index needs more turning than its valence allows below π/N per edge, e.g. 3/2 at
// a vertex of valence 5, gets there only by gaining edges.)
// The field is still exact with the prescribed singularities; it is the smoothest one for those weights.
#pragma once
#include <functional>
#include <map>
#include <memory>
#include <vector>

#include "trivcon/design.h"

namespace trivcon {

struct RefineRound {
  int split_edges = 0;  // edges turning by π/N or more, whose two faces were split (or reweighted)
  int vertices = 0, faces = 0;  // of the mesh after the round
  bool reweighted = false;      // the round lowered those edges' weights instead of splitting
};

// The fixed directions (face → angle in its frame, IndexPrescription::fixed) for a refined mesh, given its
// designer and the input face of each of its faces.
using RefinedFixedFaces = std::function<std::map<int, double>(const FieldDesigner& refined, const std::vector<int>& parent_face)>;

struct RefinedDesign {
  MatrixX3d V;                               // the final mesh: the input's if no round was needed
  MatrixX3i F;
  std::vector<int> parent_face;              // input face of each face of F
  std::unique_ptr<FieldDesigner> designer;   // on the final mesh; null if no round was needed (then the input's)
  IndexPrescription prescription;            // what was solved last (its fixed faces are the final mesh's)
  Design design;                             // the field on the final mesh
  std::vector<RefineRound> rounds;
  bool converged = false;                    // no edge of the final mesh turns by π/N or more
};

// See above. `F` is the faces `designer` was built from, as given (the refined mesh keeps their order and
// orientation); `options` are used for every refined mesh's designer; `roots` only on the input mesh (a
// refined mesh starts each component as FieldDesigner::design does). Throws trivcon::Error for a
// prescription with generator or loop indices, and what design() throws.
RefinedDesign split_large_turns(const FieldDesigner& designer, const MatrixX3i& F, const IndexPrescription& prescription,
                                const SolverOptions& options = {},
                                const RefinedFixedFaces& constraints = {}, int max_rounds = 8,
                                const std::vector<std::pair<int, double>>& roots = {});

}  // namespace trivcon
