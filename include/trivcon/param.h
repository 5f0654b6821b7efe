// SPDX-License-Identifier: MIT
// trivcon/param.h: a seamless integer-grid parametrization from a cross field (N = 4) and its trivial
// connection (Kälberer, Nieser & Polthier 2007; Bommes, Zimmer & Kobbelt 2009), the map a quad mesh is
// extracted from (trivcon/quad.h). The mathematics and its choices: docs/param.md.
//
//   trivcon::Parametrization p = trivcon::parametrize(designer, design, {.edge_length = 0.05});
//   p.uv.row(3 * f + k)   // (u, v) of corner k of face f
//
// Conventions
// - Corners: row 3f + k of `uv` is corner k of face f of Topology::F (the input's faces, with the corners of
//   a re-oriented face in the topology's order; input_corner_uv gives them in the input's order).
// - The cut: interior edges across which the map is discontinuous (a spanning tree of the dual per component,
//   its complement pruned back to the singularities, the handles' loops and the boundary). Off the cut, the two
//   faces of an edge share the (u, v) of its ends. Across a cut edge e, from L = edge_faces(e, 0) to R:
//   φ_R = J^r φ_L + t at both ends of e, J the rotation by +π/2, r = rotation[e] in [0, 4) and t =
//   translation.row(e) two whole numbers. r is the connection's own matching (trivcon/matching.h,
//   connection_matching) composed with the per-face choice of which of the four directions is u: never a
//   matching recomputed from the directions, so large turns of the connection are no problem.
// - Gradients: in every face, ∇u follows the chosen direction of the field and ∇v its quarter turn
//   counter-clockwise, both of length about 1 / edge_length: one unit of (u, v) is one quad edge.
// - Integers: every translation, the (u, v) of every singular vertex and the constant coordinate of every
//   aligned edge are whole numbers (greedy rounding with re-solves); the solve is our sparse Cholesky.
#pragma once
#include <Eigen/Core>
#include <string>
#include <vector>

#include "trivcon/design.h"

namespace trivcon {

// An aligned edge is put on an iso-line in each face beside it whose field runs along it or across it within
// this angle (radians, π/6): where one triangle holds two boundary or sharp edges meeting between 60° and 120°
// (or 150° and 210°), its field follows one and the other is aligned too, the corner a quad corner; further off
// the edge is left unaligned and counted (ParamQuality::unaligned_edges): the choice between along and across
// would be arbitrary there.
constexpr double kAlignedEdgeTolerance = 0.5235987755982988;
// Where one triangle holds two aligned edges at an acute corner between this angle (radians, π/4) and 60°, the
// edge its field does not follow is aligned across the other all the same: an acute corner cannot be flat, so it
// is a quad corner (below π/4, sharp edges meet at a narrow corner whose sector turns, trivcon/features.h).
constexpr double kAcuteCorner = 0.7853981633974483;

// The goal for a map's mean singular-value ratio (ParamQuality::mean_distortion): above it the map's integers
// are descended (docs/param.md, "Rounding") and map_request places the singularities again.
inline constexpr double kMapDistortionGoal = 1.5;
// The share of the untangling's bounds that a map gets when another map follows it where it keeps problems
// (ParamOptions::untangle_share): a long untangling mostly fights regions it cannot open, and the next map is the
// cheaper remedy.
inline constexpr double kUntangleShareFollowed = 0.25;

// How the map's target size per face is set (ParamOptions::sizing).
enum class Sizing { uniform, map, connection };
// Its name in reports and options ("uniform", "map", "connection"), and the sizing of a name: throws
// trivcon::Error "sizing: expected 'map', 'connection' or 'uniform', not '<name>'" for any other.
const char* sizing_name(Sizing sizing);
Sizing sizing_from_name(const std::string& name);

struct ParamOptions {
  double edge_length = 0;   // the quad edge length in the mesh's units (> 0 wins over target_faces)
  double target_faces = 0;  // otherwise: about this many unit squares (edge_length = √(area / target_faces))
  // Edges to put on integer iso-lines (topology edge ids): boundary edges (align_boundary) and sharp edges.
  // An edge is aligned in each face beside it whose field runs along it or across it (within
  // kAlignedEdgeTolerance); the others are counted in ParamQuality::unaligned_edges, as is a spur that meets a
  // line inside one triangle with the same coordinate constant (that triangle would be a segment; docs/param.md).
  std::vector<int> aligned_edges;
  // Greedy rounding: each round fixes the integers nearest to whole numbers, this fraction of those left (at
  // least one), then re-solves.
  double rounding_fraction = 0.5;
  int round_all_below = 16;  // when at most this many integers are left, one round fixes them all (a factorization each)
  int max_stiffening_rounds = 20;  // re-solves with the flipped faces stiffened (MIQ's §5), integers kept
  // A map left with a few flipped or degenerate faces or wrong windings is made again at up to this many other
  // edge lengths (3 % and 6 % shorter and longer), the best kept (docs/param.md, "Near misses"), while the
  // retries' factorizations stay below twice the first attempt's (not wall time: the same map on any machine);
  // 0: never.
  int retries = 4;
  // The target size per face before the rounding (docs/param.md, "Sizing"): sizing_rounds rounds that each let
  // it follow the real-valued map's own scale, smoothed (Sizing::map); or the conformal factor of the field's
  // connection, e^φ (Sizing::connection); or the field's unit length everywhere (Sizing::uniform). Where the map
  // keeps problems, or is past kMapDistortionGoal, the other sizing is made too (parametrize).
  Sizing sizing = Sizing::map;
  int sizing_rounds = 2;
  // After the rounding, where the map misses a goal (folds, or a mean singular-value ratio above
  // kMapDistortionGoal): coordinate descent of the energy on the integers (docs/param.md, "Rounding"); false: the
  // greedy rounding's integers as they are.
  bool descend_integers = true;
  // The share of the local untangling's bounds (regions, L-BFGS work; docs/param.md, "Folds") for the map of the
  // last sizing variant, in (0, 1]; the variants that another follows get kUntangleShareFollowed. A search that
  // makes other maps after this one (trivcon's map requests while they screen placements) sets that share too.
  double untangle_share = 1.0;
  // Last, on a map whose mean σ_max/σ_min is past kMapDistortionGoal: the faces stretched past it and their
  // neighbours lower their ratio with the integers held, leaving the field's directions a little where that helps
  // (docs/param.md, "Folds": Shape); false: the least squares' map, which follows the field as closely as the
  // integers allow.
  bool shape = true;
};

struct ParamQuality {
  int faces = 0, cones = 0, cut_edges = 0;
  int integer_unknowns = 0;   // free whole numbers the rounding fixed
  int rounding_rounds = 0;    // solves of the rounding
  int factorizations = 0;     // numeric factorizations of the map's system in all
  int stiffening_rounds = 0;  // re-solves against flips
  Sizing sizing = Sizing::uniform;  // the kept map's sizing (ParamOptions::sizing)
  int sizing_rounds = 0;      // re-solves with the target's size per face following the map (Sizing::map)
  int folds_real_valued = 0;  // folded faces of the first, real-valued map (before stiffening)
  int folds_rounded = 0;      // folded faces right after the rounding (before stiffening again)
  int small_components = 0;  // components of too few unit squares given squares of their own size (docs/param.md)
  int cones_moved = 0;        // singularities moved to a neighbouring integer point against a fold or a shared point
  int integers_moved = 0;     // other integers (iso-lines, translations) moved by ±1 against a fold
  int integers_descended = 0; // integers moved by whole units to lower energy after the rounding (docs/param.md)
  int segments_opened = 0;    // lengths between integer points (aligned edges and chains of them, loop and face
                              // extents) the rounding would have collapsed, kept a unit (docs/param.md)
  int strip_widths = 0;       // widths of strips between parallel aligned lines the second rounding kept open (0:
                              // the first rounding's map, docs/param.md "Rounding")
  int untangled_faces = 0;    // folded or degenerate faces opened by the local untangling (docs/param.md)
  int untangling_regions = 0; // regions untangled (each kept only when the map had fewer folds after it)
  int rewound_regions = 0;    // of those, regions untangled again from their least squares against a wrong winding
  int relieved_regions = 0;   // regions around a nearly flat face opened after the untangling (docs/param.md)
  int shaped_faces = 0;       // faces the shape pass moved to lower their stretch (0: none kept; docs/param.md)
  int flipped_faces = 0;      // faces whose (u, v) triangle is inverted
  int degenerate_faces = 0;   // faces whose (u, v) triangle has (nearly) zero area
  int collapsed_faces = 0;    // faces with an edge of length 0 on the surface, not turned over (not counted above)
  // Interior vertices whose (u, v) corner angles do not sum to 2π(1 − k) (k the index, 0 off the cones): where
  // the quad mesh gets a vertex of another valence than the singularities say; and boundary vertices between two
  // aligned boundary edges whose angles do not sum to the turn between the edges (0 expected; docs/param.md).
  int winding_errors = 0;
  int attempts = 1;           // maps made (ParamOptions::retries); the one kept is described here
  int first_factorizations = 0;  // the first map's factorizations (the retries' budget counts against them)
  std::vector<int> first_flipped;  // up to 10 ids of flipped or degenerate faces
  // Components smaller than one unit square at the map's scale (their own, for small components): no quad fits
  // there whatever the singularities (debris of a scan, a stray triangle); the first one's first face and its
  // unit squares; and how many of the flipped or degenerate faces are theirs.
  int tiny_components = 0, first_tiny_face = -1, tiny_component_folds = 0;
  double first_tiny_squares = 0;
  // Interior edges across which the connection turns by π or more: the per-face field, which the map follows, turns
  // by 2π less there, so the cones at the edge's ends read ±1 more than prescribed (docs/param.md, "The cut and
  // the combing").
  int half_turn_edges = 0;
  double max_transition_residual = 0;  // over cut edges: how far φ_R − J^r φ_L is from one whole vector at both ends
  double max_cone_offset = 0;          // distance of a singular vertex's (u, v) from the nearest integer point
  double max_cone_angle_error = 0;     // |Σ (u, v) corner angles − 2π(1 − k)| at singular vertices, radians
  int aligned_edges = 0, unaligned_edges = 0;
  int turned_boundary_points = 0;      // slit tips: boundary vertices where the aligned boundary turns back, made whole
  double max_alignment_error = 0;      // distance of an aligned edge's constant coordinate from a whole number
  double mean_distortion = 0;          // area-weighted mean of σ_max / σ_min of the map's Jacobian over the faces
                                       // neither flipped nor degenerate (those, counted above, would swamp it)
  double max_distortion = 0;           // its largest (infinite on a degenerate (u, v) triangle)
  double unit_squares = 0;             // total (u, v) area
  double target_squares = 0;           // mesh area / edge_length²
  int non_unimodular = 0;              // integer relations the elimination could not keep whole (0 expected)
  double seconds_cut = 0, seconds_setup = 0, seconds_rounding = 0, seconds_stiffening = 0, seconds_untangling = 0, seconds_check = 0;
  // (seconds_untangling: the untangling, the relief and the shape pass)
  double seconds_retries = 0;  // the attempts not kept
  double seconds_total() const {  // every stage and the retries
    return seconds_cut + seconds_setup + seconds_rounding + seconds_stiffening + seconds_untangling + seconds_check + seconds_retries;
  }
  // True when the map is seamless (transitions whole to 1e-6), every cone on an integer point, every aligned edge
  // on an iso-line: what the linear constraints promise. Folds (and a cone angle off by whole turns, which a
  // fold around the cone makes) are counted above.
  bool seamless = false;
};

struct Parametrization {
  Eigen::MatrixXd uv;               // 3F × 2, see the conventions
  std::vector<int> cut_edges;       // increasing edge ids
  Eigen::VectorXi rotation;         // per edge, r in [0, 4) on cut edges, 0 elsewhere
  Eigen::MatrixXi translation;      // per edge × 2, t on cut edges, 0 elsewhere
  std::vector<int> cones;           // singular interior vertices, increasing
  std::vector<int> cone_index;      // n per cone (index n / 4)
  std::vector<int> aligned_edges;   // increasing edge ids on integer iso-lines (of ParamOptions::aligned_edges)
  double edge_length = 0;
  ParamQuality quality;
};

// The map of `design`'s field (N = 4) on `designer`'s mesh. Throws trivcon::Error for another N, a missing
// or non-positive scale, an untangle_share outside (0, 1], an aligned edge id out of range, or a system our
// factorization finds not positive definite.
Parametrization parametrize(const FieldDesigner& designer, const Design& design, const ParamOptions& options);

// The near-miss retries alone, resumed from `screened`: a map parametrize made with the same designer, design and
// options but retries = 0 (a screening search also gives it untangle_share = kUntangleShareFollowed; the retries
// untangle with the whole bounds). The result equals parametrize(designer, design, options); the maps `screened` made
// are not made again (a search that screens many fields' maps retries only the one it keeps). Throws
// trivcon::Error when `screened` does not come from parametrize.
Parametrization parametrize_retries(const FieldDesigner& designer, const Design& design, const ParamOptions& options,
                                    const Parametrization& screened);

// Whether a cone of index ≥ 1 makes the map's folds necessary (a quad corner cannot open to 2π or more): no
// retry at another scale removes them, so the retries (ParamOptions::retries, map_request's other scales) skip it.
bool folds_necessary(const Parametrization& param);

// The (u, v) of the corners of the input's faces `F` (the faces the designer was built from), F × 6: (u, v)
// of corner 0, 1, 2 in the input's corner order.
Eigen::MatrixXd input_corner_uv(const Parametrization& param, const Topology& topology, const MatrixX3i& F);

// One sentence on what is wrong with the map ("" when seamless without flips): for a report or a warning.
std::string param_warning(const Parametrization& param);

}  // namespace trivcon
