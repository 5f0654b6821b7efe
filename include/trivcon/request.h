// SPDX-License-Identifier: MIT
// trivcon/request.h: one field request, as every front end states it (the CLI's options, the editor's JSON,
// Python's keywords), turned into a design. The front ends parse and print; what a request means is here.
//
//   trivcon::FieldDesigner designer(V, F);
//   trivcon::FieldRequest r;  r.prescription.N = 4;  r.auto_place = true;  r.align_boundary = true;
//   trivcon::FieldOutcome out = trivcon::solve_request(designer, F, r);
//   out.design.field, out.prescription.vertex (the singularities used), out.constraints.fixed ...
//
// Fixed faces, in the order in which later ones win on the same face: the boundary's edge directions
// (align_boundary), the sharp edges' directions (feature_degrees / feature_edges, trivcon/features.h), then
// the explicit directions of prescription.fixed.
// Orientation: with auto_place, each component without a root or fixed face takes its rotation from the
// smoothest field the singularities came from (turn_toward, trivcon/auto.h); otherwise the field starts at
// angle 0 at the component's first face (FieldDesigner::design).
#pragma once
#include <functional>
#include <map>
#include <memory>
#include <optional>
#include <string>
#include <utility>
#include <vector>

#include "trivcon/auto.h"
#include "trivcon/constraints.h"
#include "trivcon/design.h"
#include "trivcon/features.h"
#include "trivcon/param.h"
#include "trivcon/quad.h"
#include "trivcon/relax.h"
#include "trivcon/repair.h"
#include "trivcon/split_large_turns.h"

namespace trivcon {

struct FieldRequest {
  // N, the vertex / generator / loop indices (vertex ones ignored with auto_place), and the explicit fixed
  // directions (face -> angle in its frame), which win over both alignments.
  IndexPrescription prescription;
  bool align_boundary = false;           // fix every face with a boundary edge to that edge's direction
  std::optional<double> feature_degrees; // fix the faces beside every interior edge sharper than this (degrees)
  std::vector<int> feature_edges;        // ... and beside these edges (ids of the designer's topology)
  // Of the edges sharper than feature_degrees, those in chains with a loose end shorter than this (in the mesh's
  // units) are not followed (without_short_feature_ends, trivcon/features.h; listed edges always are). Unset:
  // none dropped, except that map_request drops those shorter than one unit of the map.
  std::optional<double> feature_min_length;
  bool auto_place = false;               // the singularities of the smoothest field (auto_singularities)
  AutoOptions auto_options;              // its cancel distance, iterations, curvature guidance (N and fixed: the request's)
  std::vector<std::pair<int, double>> roots;  // (face, angle): where a component's field starts
  bool relax = false;                    // move the vertex singularities downhill in the energy first (trivcon/relax.h)
  RelaxOptions relax_options;            // its pins, moves at most, cancellations
  bool split_large_turns = false;        // refine where the connection turns by π/N or more (split_large_turns.h)
  int max_split_rounds = 8;
  Sizing sizing = Sizing::map;           // for a map (request_param_options): ParamOptions::sizing
  // For a map (map_request sets it): singularities given (not auto_place) on feature vertices get the sectors
  // that make their index (turn_sectors_for_singularities), as the moves onto feature lines of `quad --auto` do,
  // so that its --sing-out given back makes the same field; a map's quad corners then follow the index. Not for
  // `solve`: there the field with the faces along the lines alone is the smoothest (often with the quarter turn
  // spread over a sector's free faces), and -s gives back --auto's field.
  bool sectors_for_singularities = false;
  bool features_given() const { return feature_degrees.has_value() || !feature_edges.empty(); }
};

// What a request fixes on a mesh.
struct RequestConstraints {
  std::map<int, double> fixed;    // every fixed face: face -> angle in its frame
  std::vector<int> fixed_faces;   // its faces, increasing (FieldDesigner::set_fixed_faces)
  std::vector<int> sharp_edges;   // the feature edges, increasing
  std::vector<int> loose_edges;   // sharp edges left out as short loose ends (feature_min_length), increasing
  FeatureAlignment features;      // the faces fixed beside them, corners, conflicts
  int convex_edges = 0;           // sharp edges that are ridges (is_convex_edge)
  int boundary_overridden = 0;    // faces align_boundary fixed that a sharp edge turned (modulo 2π/N)
};

// The fixed faces of `request` on `designer`'s mesh. Throws trivcon::Error for a fixed face or feature edge
// out of range, or a feature angle outside [0, 180].
RequestConstraints request_constraints(const FieldDesigner& designer, const FieldRequest& request);

// The design of `prescription` (its fixed map complete: RequestConstraints::fixed) on a designer already set
// up for its fixed faces; with `guide` (the smoothest field, AutoResult::field), components without a root or
// fixed face are turned toward it, and it is the fixed-face paths' guide (guide_paths).
Design request_design(const FieldDesigner& designer, const IndexPrescription& prescription,
                      const std::vector<std::pair<int, double>>& roots = {}, const Field* guide = nullptr);

// Sets `prescription.path_guide` to `guide`'s angles where the designer's solver reads the fixed-face paths'
// whole turns path by path (ConnectionSolver::sparse_paths) and none is set: the turns the smoothest field makes
// along them, close to what the dense route would choose with the cycles. No-op without a guide of the same N and
// mesh.
void guide_paths(const FieldDesigner& designer, IndexPrescription& prescription, const Field* guide);

// The request's smoothest field and singularities (auto_place), with the constraints' fixed faces held.
AutoResult request_auto(const FieldDesigner& designer, const FieldRequest& request, const RequestConstraints& constraints);

struct FieldOutcome {
  IndexPrescription prescription;         // what was designed: the singularities used, every fixed face (on the final mesh)
  RequestConstraints constraints;         // on the input mesh
  std::vector<int> sharp_edges;           // the feature edges of the final mesh
  Design design;                          // on the final mesh
  bool verified = false;                  // design_verified(design)
  // With auto_place. Its `vertex` is the placement before the moves onto feature lines (AutoOptions::onto_features)
  // and, where those are made, before the split that follows them; `prescription` holds what was designed.
  std::optional<AutoResult> auto_result;
  std::optional<RelaxResult> relax_result;  // with relax: its prescription is the one designed (on the input mesh)
  // With split_large_turns: the refined mesh (refined == nullptr when no round was needed: the input's).
  std::unique_ptr<FieldDesigner> refined;
  MatrixX3d V;                            // the refined mesh (empty without one)
  MatrixX3i F;
  std::vector<int> parent_face;           // input face of each face of the final mesh (empty without splitting)
  std::vector<RefineRound> rounds;
  bool split_converged = true;
  // The designer the design belongs to.
  const FieldDesigner& designer(const FieldDesigner& input) const { return refined ? *refined : input; }
};

// A request stated in the input file's ids (vertices, faces, edges between input vertices), moved onto its repair
// (trivcon/repair.h) whose topology is `topology`: singular vertices keep their ids (a split one is an error,
// repaired_vertex), relaxation pins hold every copy of their vertex, roots go to face_of_input, and a listed feature edge between two input vertices marks every
// copy of it (the sheets of a cut edge each get theirs). Fixed directions are not here: their angles are in a
// face's frame, so they are read onto the repaired mesh's faces directly (read_fixed_directions's face map).
// Throws trivcon::Error for an id out of the input's range.
void move_request_to_repaired(FieldRequest& request, const Topology& topology, const RepairedMesh& repaired);

// The whole request: constraints, set-up (set_fixed_faces, only when they changed), auto placement, relaxation,
// validation (check_aligned_index_sums, validate_prescription: the CLI's messages), design, splitting.
// `F` is the faces `designer` was built from, as given (for split_large_turns). Throws trivcon::Error.
FieldOutcome solve_request(FieldDesigner& designer, const MatrixX3i& F, const FieldRequest& request);

// The map of a request's field (trivcon/param.h, N = 4) as `param`, `quad`, Python and the editor make it: the scale
// (edge_length > 0, else about target_faces unit squares) and, on integer iso-lines, every boundary edge when
// the request aligns the boundary and the sharp edges the field followed (outcome.sharp_edges).
ParamOptions request_param_options(const FieldDesigner& designer, const FieldRequest& request, const FieldOutcome& outcome,
                                   double edge_length, double target_faces);
// The same with the sharp edges given (the designer's edge ids: RequestConstraints::sharp_edges).
ParamOptions request_param_options(const FieldDesigner& designer, const FieldRequest& request, const std::vector<int>& sharp_edges,
                                   double edge_length, double target_faces);

// One unit of (u, v) in the mesh's units: edge_length when > 0, else √(area / target_faces). With automatic
// placement a ± pair closer than that cannot sit on two integer points without folding the map, so the map's
// front ends cancel pairs within it unless the request says otherwise (cancel_for_map).
double map_unit(const FieldDesigner& designer, double edge_length, double target_faces);
// With auto_place: sets request.auto_options to cancel pairs within one unit of the map (absolute) when no cancel
// distance was given, and to split every singularity of |index| ≥ 1 into ones of ±1/4 about one unit around it
// (AutoOptions::split_above = 3) when no split was asked for: a quad vertex has valence 4 − 4k, so k ≥ 1
// cannot be made (the smoothest field of a round disk with its boundary aligned puts +1 at the centre); and to
// move ±1/4 singularities closer than kMapOntoFeatures units to a feature line onto it (AutoOptions::onto_features),
// but not within one unit of another singularity (AutoOptions::onto_separation).
void cancel_for_map(FieldRequest& request, const FieldDesigner& designer, double edge_length, double target_faces);

// A field and its map, as `param`, `quad` and Python's solve with a map scale make them.
struct MapOutcome {
  FieldOutcome field;
  Parametrization param;   // not made (empty) when the field did not pass verification
  int placements = 1;      // automatic placements tried (map_request)
  double cancel_units = 0; // with automatic placement: the cancel distance used, in units of the map (0: the request's own)
  int first_problems = 0;  // the first attempt's problems (below; its map made without retries), when it was placed again
  double first_distortion = 0;  // the first attempt's mean singular-value ratio, when it was placed again
  int retried_maps = 0;    // screened maps whose near-miss retries were made (kMapRetryCandidates at most)
  bool relaxed = false;    // the kept placement was relaxed by map_request (not by the request's own relax)
  bool periods = false;    // and with the periods in the objective (kMapPeriodWeight)
  double onto_units = 0;   // with automatic placement and sharp edges: the distance singularities were moved onto them from, in units
  bool onto_flat = false;  // and onto sectors where a quad gets a flat corner (AutoOptions::onto_flat_sectors)
  bool onto_boundary = false;  // and onto the aligned boundary as corners (AutoOptions::onto_boundary)
  double scale = 1;        // the kept map's edge length over the one asked for (kMapScales; 1: the one asked for)
  std::optional<QuadMesh> quads;  // with quads = true: the kept map's quad mesh (extract_quads)
  // Edges split at their midpoints (map_request): then field.refined, V, F and parent_face hold the refined mesh.
  int refined_edges = 0;
  int maps = 0;            // maps the search made in all (placements, near-miss retries, other scales; MapSearch)
  bool stopped = false;    // the search stopped at MapSearch::max_maps with steps left that could have mended the map
};

// How map_request's search is bounded and what it says while it runs. A search that keeps problems can make many
// maps (each placement's, the near-miss retries', the other scales', the corners', again on a refined mesh), each
// costing about as much as the first; a user who would rather have the best of fewer sooner bounds them.
struct MapSearch {
  // No step starts once this many maps are made (0: no bound). Counted: every map parametrize makes
  // (ParamQuality::attempts: a placement's or another scale's with the other sizings' where its own keeps
  // problems, the near-miss retries' up to 2 + 2 · ParamOptions::retries). A step under way
  // finishes, so the search can end a few maps past the bound; what it keeps is what the search without a bound
  // had kept at that point. The first step (the first placement's map) is always made.
  int max_maps = 0;
  // Called with one line after each step past a first map that has problems (the maps made so far, what the step
  // tried, its problems and mean singular-value ratio, the best so far), and when the bound stops the search.
  std::function<void(const std::string&)> progress;
};
// Words for a placement of the search (the line of `quad`, the search's progress): "the first", "pairs cancelled
// within 2 units", "the singularities found, relaxed", ...
std::string describe_placement(double cancel_units, bool relaxed, bool periods, double onto_units, bool onto_flat, bool onto_boundary);
// The distance, in units of the map, within which cancel_for_map moves ±1/4 singularities onto a feature line, and
// the farther one of map_request's attempt after the relaxed ones (a singularity in a strip or wedge between
// two feature lines, where the map has one unit across it, has no integer point off both lines).
inline constexpr double kMapOntoFeatures = 1.5;
inline constexpr double kMapOntoFeaturesFar = 2;
// When every placement's map keeps problems, map_request makes the kept field's map again at these edge lengths,
// relative to the one asked for (the rounding's outcome is sensitive to the scale, also where a map has too many
// problems for the near-miss retries, ParamOptions::retries); the quad count moves by about 1/scale².
inline constexpr double kMapScales[] = {0.95, 1.05, 0.9, 1.1};
// A field's map at one edge length, with its quad mesh when asked for.
struct ScaledMap {
  Parametrization param;
  std::optional<QuadMesh> quads;
  double scale = 1;  // the map's edge length over the one asked for (kMapScales; 1: the one asked for)
};
// The map of a field as every front end keeps it (param, quad, Python's Result.parametrize/quad, the editor's quads):
// parametrize with `options` (and with `quads` its quad mesh, extract_quads); when that map keeps problems (folded
// or degenerate faces, wrong windings, and with `quads` the quad mesh's failed checks) and no singularity of
// index ≥ 1 makes its folds necessary (folds_necessary), made again at kMapScales times the options' edge length
// (their target's squares over scale²), each without near-miss retries of its own (ParamOptions::retries: those
// are at lengths between these) and, but the last, with the untangling's share of a map that others follow
// (kUntangleShareFollowed); a map is kept when it has fewer problems, or as few and less stretch beyond
// kMapDistortionGoal, and the first without problems ends the loop. Throws what parametrize throws.
ScaledMap map_field(const FieldDesigner& designer, const Design& design, const ParamOptions& options, bool quads = false);
// The loop over kMapScales alone, from `map` made with `options` at their own scale (map.scale = 1).
void map_at_other_scales(const FieldDesigner& designer, const Design& design, const ParamOptions& options, ScaledMap& map);
// A map's problems as map_field counts them.
int map_problems(const Parametrization& param, const std::optional<QuadMesh>& quads);

// The weight of the periods (RelaxOptions::period_weight) in map_request's second relaxed attempt.
inline constexpr double kMapPeriodWeight = 3;
// The reach (RelaxOptions::reach) of map_request's relaxed attempts.
inline constexpr int kMapRelaxReach = 3;
// The candidate solves (RelaxOptions::max_solves) of each of map_request's own relaxations: kMapRelaxSolves per
// singularity of its start (each moves a few edges, a move costs some tens of solves), but at most kMapRelaxWork
// / the mesh's vertices (a solve costs about one back-substitution), and at least kMapRelaxMinSolves.
inline constexpr int kMapRelaxSolves = 50;
inline constexpr double kMapRelaxWork = 3e8;
inline constexpr int kMapRelaxMinSolves = 500;
// When the kept map's near-miss retries (ParamOptions::retries) leave problems, map_request retries the next
// screened maps too, in rank, up to this many maps in all: ranked before their retries, the one they mend may
// not be first.
inline constexpr int kMapRetryCandidates = 3;
// map_request does not relax a placement whose first attempt has more singularities than this (each move ranks
// every singularity's candidates again).
inline constexpr size_t kMapRelaxMaxSingularities = 600;
// cancel_for_map, solve_request, and the map with request_param_options (and its quad mesh with `quads`); a request
// that detects sharp edges (feature_degrees) without a feature_min_length gets one unit of the map. With
// automatic placement and no cancel distance in the request, a map left with folded or degenerate faces or wrong
// windings (or, with `quads`, whose quad mesh fails a check of check_quads), or stretched beyond
// kMapDistortionGoal, is made again: from the same singularities relaxed (trivcon/relax.h; kept a unit from the
// aligned edges and from each other, with a reach of kMapRelaxReach edges), then relaxed with the periods (RelaxOptions::period_weight =
// kMapPeriodWeight), then (with sharp edges) with singularities moved onto the feature lines from
// kMapOntoFeaturesFar units, then from singularities whose ± pairs were cancelled within 2, then 4
// units (at a scale too coarse for the singularities found, a detailed scan at a thousand quads, fewer of them
// give a map without folds), then those relaxed, and last (with sharp edges) moved onto the lines from
// kMapOntoFeatures and kMapOntoFeaturesFar units also onto sectors where a quad gets a flat corner
// (AutoOptions::onto_flat_sectors); with the request's own relax, every placement is relaxed. A
// placement equal to an earlier one is not mapped again, one equal before relaxation is not relaxed again, the
// periods' relaxation is skipped where they are not used (periods_usable), none is relaxed when the first has
// more than kMapRelaxMaxSingularities singularities, and each relaxation stops at its budget (kMapRelaxSolves, kMapRelaxWork).
// While other attempts may follow, the maps are made without ParamOptions::retries; when the kept map has
// problems its retries follow, resumed from it (parametrize_retries). The search ends at the first map without problems
// within the goal; past it every attempt is made; the kept map is the one with the fewest problems, then the least
// stretch beyond the goal (the earliest of equals). `request` is left as the kept one
// was made.
// Still with problems, the kept field's map at other edge lengths (map_at_other_scales), then the screened
// runners-up's in rank, until a map has none; the better one is kept. Still with problems and the boundary
// aligned, the placements with the singularities beside the boundary moved onto it as corners
// (AutoOptions::onto_boundary), unrelaxed and relaxed, with their retries and scales the same way; the better
// map is kept.
// Last, when the kept map has problems and folds beside an edge that is not aligned but whose two ends lie on
// aligned edges, every such edge is split at its midpoint (split_edges_at_midpoints) and the whole search runs
// again on the refined mesh (the request moved onto it: fixed directions and roots to every child, listed feature
// edges by their ends); its map is kept when it has fewer problems, with field.refined, V, F, parent_face and
// refined_edges set. Not with generator or loop indices, nor after split_large_turns.
// Throws what solve_request and parametrize throw.
// `search` bounds the maps made and reports each step (MapSearch); MapOutcome::maps and stopped say how it went.
MapOutcome map_request(FieldDesigner& designer, const MatrixX3i& F, FieldRequest& request, double edge_length, double target_faces,
                       bool quads = false, const MapSearch& search = {});

}  // namespace trivcon
