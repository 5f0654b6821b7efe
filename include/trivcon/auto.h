// SPDX-License-Identifier: MIT
// trivcon/auto.h: singularities found automatically, from the globally smoothest N-direction field
// (Knöppel, Crane, Pinkall & Schröder 2013, face-based). The method, its weights, the eigen-solve and the
// reasons for each choice: docs/auto.md.
//
// Conventions
// - The field: one complex u_f per face in its frame (trivcon/geometry.h); the field's first direction is
//   at angle arg(u_f)/N. Per component it minimises E(u) / ‖u‖²_M, E(u) = Σ_e w_e |u_R − e^{iNρ_e} u_L|²
//   over interior edges (the weights w_e and the face masses M: docs/auto.md): the smallest eigenvector,
//   by AutoOptions::iterations inverse-power iterations from a fixed start (deterministic). Fixed faces
//   (AutoOptions::fixed) hold u_f = e^{iNγ_f} as Dirichlet values. A face where the field vanishes
//   (|u_f| ≤ 1e-9 × its component's largest |u|) takes its neighbours' values transported into it, summed
//   (angle 0 if that vanishes too).
// - Singularities: the field's indices at interior vertices (field_indices, trivcon/field.h), so they
//   satisfy Gauss–Bonnet per closed component. Boundary vertices carry none: turning there beside fixed
//   boundary faces moves to an interior neighbour (boundary_turns_moved_inside, trivcon/constraints.h).
// - Coincident vertices (joined by edges of length exactly 0): each cluster's indices are summed onto its
//   smallest vertex id (0: removed); a cluster touching the boundary keeps its vertices' own.
// - Cancellation (cancel_distance > 0): ± pairs (+n, −n) at most that geodesic distance apart (Dijkstra
//   along mesh edges, Euclidean lengths) are removed, closest first (ties: smaller vertex ids), each vertex
//   in one pair at most; every sum per component is kept. Distances in mean edge lengths, or in the
//   mesh's units with cancel_absolute.
// - Curvature alignment (align_curvature, N even): the field solves (A − t·λ̂ M) u = M q toward the
//   principal curvature directions q (trivcon/curvature.h); t = 0 reuses the factor, t ≠ 0 refactors.
// Errors: trivcon::Error (invalid options, fixed faces out of range or not finite, every face of zero area,
// a matrix that is not positive definite, a field that is not finite); trivcon::Cancelled (trivcon/cancel.h).
#pragma once
#include <map>
#include <string>
#include <utility>
#include <vector>

#include "trivcon/common.h"
#include "trivcon/cycles.h"
#include "trivcon/field.h"
#include "trivcon/geometry.h"
#include "trivcon/topology.h"

namespace trivcon {

class FieldDesigner;

struct AutoOptions {
  int N = 4;                     // symmetry, ≥ 1
  int iterations = 8;            // inverse-power iterations, ≥ 1
  double cancel_distance = 0;    // cancel ± pairs at most this far apart; 0: none
  bool cancel_absolute = false;  // cancel_distance in mesh units instead of mean edge lengths
  // Split (after cancellation; split_above 0: never): singularities of one sign closer than split_distance (mesh
  // units, along edges) are gathered at the member nearest their centroid; a sum |n| > split_above, any gathered
  // positive sum and any n > 1 become |n| singularities of ±1 on interior vertices about split_distance from it
  // that hold none yet, far from each other (negative sums up to split_above stay: one −2 is a quad vertex of
  // valence 6, two −1 a fraction of a unit apart fold the map). A cluster joins closest pair first while every member
  // stays within split_distance of every other. Then opposite singularities at most cancel_distance apart meet
  // as far as their indices allow (cancel_singularity_pairs with `partial`): a −2 beside a +1 becomes one −1, a
  // −2 between two +1 vanishes. `trivcon param` and `quad` with --auto use split_above = N − 1 = 3 and one quad
  // edge: a quad vertex has valence 4 − n, none for n ≥ 4.
  int split_above = 0;
  double split_distance = 0;
  std::map<int, double> fixed;   // face → angle in its frame (radians), held as Dirichlet values
  // Vertices whose singularities are prescribed as found, never cancelled, gathered or split: the ends of
  // sharp edges, where the fixed faces' turns make them (trivcon/features.h); moved, the turn would stay and
  // the exact field would make it up with a large turn beside them.
  std::vector<int> held;
  // For a map (set by the map requests, trivcon/request.h; 0: never): singularities closer than this (mesh units,
  // along edges) to a feature line are then moved onto it (move_singularities_onto_features, trivcon/features.h).
  double onto_features = 0;
  double onto_separation = 0;      // not onto a vertex closer than this to another singularity (mesh units; 0: anywhere)
  bool onto_flat_sectors = false;  // and onto sectors whose quad corners would be flat (move_singularities_onto_features)
  bool onto_boundary = false;      // and, with the boundary aligned, onto it as a corner (move_singularities_onto_features)
  bool align_curvature = false;  // follow the principal curvature directions (see above); N even
  double curvature_t = 0;        // its strength t < 1: 0 as geometry-central, → 1 smoother, < 0 closer to the curvature
};

struct AutoTimings {
  double assemble = 0, factor = 0, iterate = 0, align = 0, indices = 0, cancel = 0;  // seconds
};

struct AutoResult {
  Field field;                             // the smoothest field, angle = arg(u_f)/N in [0, 2π/N)
  std::map<int, int> found;                // its singularities: vertex → n (index n/N)
  int coincident_removed = 0;              // singularities of `found` that summing over coincident vertices removed
  int boundary_moved = 0;                  // 1/N steps of turning at boundary vertices beside fixed faces, moved into `found` at
                                           // an interior neighbour (boundary_turns_moved_inside, trivcon/constraints.h)
  std::map<int, int> vertex;               // after that and cancellation: the singularities to prescribe
  std::vector<std::pair<int, int>> pairs;  // cancelled pairs (vertex of index +n, vertex of −n), in order
  int split = 0;                           // singularities split into ±1 ones (split_above)
  int met = 0;                             // meetings of opposite singularities of different sizes after the split
  double energy = 0;                       // E(u) / ‖u‖²_M over the whole mesh (the Rayleigh quotient without fixed faces)
  int vanishing_faces = 0;                 // faces where |u_f| vanished (see above)
  std::string ordering;                    // the smoothest field's factor order: "AMD" or "coordinate dissection"
  AutoTimings seconds;
};

// On a prepared mesh (V gives the edge lengths for the weights and distances).
AutoResult auto_singularities(const MatrixX3d& V, const Topology& topology, const Geometry& geometry, const Cycles& cycles,
                              const AutoOptions& options);
// On a FieldDesigner's topology and geometry (fixed faces are those of options.fixed, not the designer's).
AutoResult auto_singularities(const FieldDesigner& designer, const AutoOptions& options);
// On plain (V, F): validates and prepares the mesh first (trivcon::Error as build_topology).
AutoResult auto_singularities(const MatrixX3d& V, const MatrixX3i& F, const AutoOptions& options);

// The cancellation above on its own, `distance` in the mesh's units: the singularities left, and the
// cancelled pairs (positive vertex, negative vertex) appended to `pairs` when not null. With `partial`,
// opposite singularities of different sizes meet too: +a and −b at most `distance` apart (closest first) each
// lose min(a, b), the larger keeping the rest at its vertex, and a vertex may meet several; `met` (when not null)
// counts those meetings (whole pairs still go to `pairs`).
std::map<int, int> cancel_singularity_pairs(const MatrixX3d& V, const Topology& topology, const std::map<int, int>& vertex, double distance,
                                            std::vector<std::pair<int, int>>* pairs = nullptr, bool partial = false, int* met = nullptr);

// The split of AutoOptions::split_above on its own, as auto_singularities ends (after the cancellation): the
// singularities of `vertex` but those at options.held vertices (kept as they are) gathered, split and met with
// opposite ones within options.cancel_distance; `result`'s split, met and pairs count them. The map requests run
// it after moving singularities onto feature lines (trivcon/request.h). `vertex` itself when split_above is 0.
std::map<int, int> split_auto_singularities(const MatrixX3d& V, const Topology& topology, const std::map<int, int>& vertex,
                                            const AutoOptions& options, AutoResult& result);

// The summing over coincident vertices above on its own.
std::map<int, int> merge_coincident_singularities(const MatrixX3d& V, const Topology& topology, const std::map<int, int>& vertex);


// The roots (face, angle) that turn each component's field to agree best with `guide`, an N-field (e.g. the
// smoothest field AutoResult::field that --auto read its singularities from: the trivial connection then
// keeps its orientation, instead of starting each component at angle 0). `field` is the field
// FieldDesigner::design made with `roots`; for each component with neither a root in `roots` nor a fixed face
// (whose directions decide its rotation), the rotation θ maximizing Σ_f A_f cos(N(α_f − β_f − θ)), i.e.
// θ = arg(Σ_f A_f e^{iN(α_f − β_f)}) / N (A_f the face areas), is returned as a root at the component's
// first face with angle β + θ (nothing where that sum vanishes). `roots` are returned first, unchanged.
std::vector<std::pair<int, double>> roots_toward(const FieldDesigner& designer, const Field& field, const Field& guide,
                                                 const std::vector<std::pair<int, double>>& roots = {},
                                                 const std::map<int, double>& fixed = {});
// The same rotation applied to `field` in place (each component's angles + θ, wrapped to [0, 2π)), without
// designing again: what an interactive front end does after every edit (a rotation by a constant per
// component changes none of the design's checks). Components with a fixed face keep their rotation.
// Components with a root in `roots` keep theirs too.
void turn_toward(const FieldDesigner& designer, Field& field, const Field& guide, const std::map<int, double>& fixed = {},
                 const std::vector<std::pair<int, double>>& roots = {});

}  // namespace trivcon
