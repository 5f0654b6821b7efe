// SPDX-License-Identifier: MIT
// trivcon/features.h: sharp feature edges, and the fixed directions that make a field follow them.
//
// Conventions
// - A feature (sharp) edge is an interior edge (Topology ids); boundary edges are never features (they
//   are what --align-boundary aligns to; the two can be combined).
// - Dihedral angle of interior edge e = (i, j), L = edge_faces(e, 0) holding i → j, R = edge_faces(e, 1):
//   θ_e = the angle between the unit normals of L and R (Geometry::normal, faces as oriented by
//   trivcon/topology.h), in [0, π]; 0 where the surface is flat across e. `sharp_edges(…, DEG)` takes the
//   edges with θ_e > DEG degrees.
// - Convexity: e is convex (a ridge) when (n_L × n_R) · (p_j − p_i) > 0, i.e. R bends away from L's
//   normal; concave (a valley) otherwise. With outward normals (closed meshes as generated, trivcon/
//   generate.h) the edges of a box are convex; an inside-out mesh swaps the two.
// - Feature alignment: every face beside a feature edge is fixed (trivcon/constraints.h) to that edge's
//   direction p_j − p_i (i < j) in the face's frame (Geometry::half_edge_angle of the half-edge the face
//   holds, + π in R), the same sense on both sides, so that parallel transport across the edge carries
//   one onto the other for every N (for even N the sense does not matter modulo 2π/N). A face beside several feature edges (at a corner)
//   follows the longest one; the others are compatible when their directions agree with it modulo 2π/N within kFeatureAngleTolerance (for N
//   = 4 two perpendicular edges are: a cross along one is along the other), and every face where they do not is reported
//   (FeatureAlignment::conflicts), never resolved silently.
// - Narrow corners (N even, N ≥ 4): where two consecutive feature edges a, b around a vertex enclose a
//   sector of angle θ < π/N (a tapering strip, the tip of a crease), a field following both would give the
//   sector no turn of its own and a map aligned to both would collapse it. The sector's m faces are fixed
//   instead to a's direction turned by δ, 2δ, …, mδ with δ = (θ − 2π/N)/(m + 1), so that the field turns
//   through the sector by one step less than the edges do and the sector's quad corner is 2π/N (one quad
//   corner at the tip). Each is listed (FeatureAlignment::narrow); its faces are not conflicts. Skipped
//   where a sector face has another feature edge, or lies in a second narrow sector.
// - QuadWild's .sharp file (written by write_sharp, read back by read_sharp): line 1 the number of lines
//   that follow, then one line "convexity,face,edge" per side of each feature edge: convexity 1 convex, 0
//   concave; `face` the face id; `edge` ∈ {0, 1, 2} the edge joining the face's vertices edge and edge + 1
//   (mod 3) in the face's order as given (the file's, not the re-oriented Topology::F). Each feature edge
//   gives two lines, one for each of its faces (as QuadWild's own exporter writes), ordered by edge id then
//   L before R.
#pragma once
#include <map>
#include <string>
#include <vector>

#include "trivcon/geometry.h"
#include "trivcon/topology.h"

namespace trivcon {

// Two edge directions closer than this (radians, modulo 2π/N) count as compatible at a corner.
constexpr double kFeatureAngleTolerance = 1e-9;

// θ_e above (radians); 0 for boundary edges.
double dihedral_angle(const Topology& topology, const Geometry& geometry, int edge);
// Whether interior edge `edge` is convex (see above).
bool is_convex_edge(const MatrixX3d& V, const Topology& topology, const Geometry& geometry, int edge);

// The interior edges whose dihedral angle exceeds `degrees` (in [0, 180]; anything else, NaN included,
// throws trivcon::Error), in increasing id.
std::vector<int> sharp_edges(const MatrixX3d& V, const Topology& topology, const Geometry& geometry, double degrees);

// The sharp edges without short loose ends, for a map: `edges` (interior edge ids, increasing) taken as a graph on
// their vertices is cut into chains at every vertex where other than two of them meet; a chain with a free end
// (a vertex with one sharp edge) shorter than `min_length` (in the mesh's units, along the chain) is dropped, and
// again until none is left (dropping a spur can leave a junction with a free chain); then every connected piece
// less than `min_length` across (the largest distance between two of its vertices) is dropped. Other chains
// between junctions, and closed loops, stay whatever their length. A scan's creases come out of a dihedral
// threshold as hundreds of dashes and tiny rings a fraction of a quad long; each asks the map for integer
// iso-lines of its own, and lines that close together fold it. A clean CAD part's lines are long or end at
// junctions: nothing is dropped there.
// Returns the edges kept, increasing; `dropped` (optional) gets the others, increasing.
std::vector<int> without_short_feature_ends(const MatrixX3d& V, const Topology& topology, const std::vector<int>& edges, double min_length,
                                            std::vector<int>* dropped = nullptr);

// The sharp edges without a face whose three edges are all among them: such a face cannot have all three on
// integer iso-lines (a map makes it flat), so its least sharp edge (smallest dihedral angle; the larger id of
// equals) is left out, face after face in increasing id until none is left. A clean CAD part has no such face;
// a coarse or noisy one has knots of them. Returns the edges kept, increasing; `dropped` (optional) gets the
// others, increasing.
std::vector<int> without_closed_faces(const Topology& topology, const Geometry& geometry, const std::vector<int>& edges,
                                      std::vector<int>* dropped = nullptr);

// Reads feature edges: one "i j" (vertex ids, either order) per line, '#' comments and blank lines skipped.
// Errors name file:line: a malformed line, a vertex id out of range, a pair that is not an edge of the mesh,
// a boundary edge, an edge listed twice. Returns edge ids in increasing order.
std::vector<int> read_feature_edges(const std::string& path, const Topology& topology);

// A face beside feature edges that do not agree modulo 2π/N: it follows `followed`, not `other`.
struct FeatureConflict {
  int face;
  int followed, other;  // edge ids
  double difference;    // |angle of other − angle of followed| modulo 2π/N, radians in (tolerance, π/N]
};

// Consecutive feature edges around `vertex` enclosing a sector narrower than π/N (see above).
struct NarrowCorner {
  int vertex;
  int first, second;  // edge ids, in the counter-clockwise sense around the vertex
  double angle;             // θ, radians
  std::vector<int> faces;   // the sector's faces W_1..W_m, from `first` to `second`
};

// A singularity moved onto a feature line (move_singularities_onto_features).
struct FeatureSnap {
  int from, to;            // vertex ids
  double distance;         // along edges
  std::vector<int> faces;  // the sector of `to` turned anew (their directions in FeatureAlignment::fixed)
};

struct FeatureAlignment {
  std::map<int, double> fixed;             // face → angle in the face's frame (IndexPrescription::fixed)
  std::vector<FeatureConflict> conflicts;  // one per (face, disagreeing edge), by face
  std::vector<NarrowCorner> narrow;        // by vertex
  std::vector<FeatureSnap> snapped;        // by `from`
  std::vector<FeatureSnap> given_sectors;  // turned for singularities given (turn_sectors_for_singularities), by vertex
  // Boundary vertices made corners of the aligned boundary (vertex → n): the fan turned through with n steps fewer
  // than the nearest to its angle, as a singularity of index n/N would make it; no singularity there (a boundary
  // vertex carries no index). By move_singularities_onto_features or turn_sectors_for_singularities.
  std::map<int, int> corners;
  int corner_faces = 0;                    // faces beside two or more feature edges (compatible or not)
};
// The fixed directions for `edges` (interior edge ids) and symmetry N ≥ 1.
FeatureAlignment feature_alignment(const MatrixX3d& V, const Topology& topology, const Geometry& geometry, const std::vector<int>& edges,
                                   int N);

// For a map (N even, N ≥ 4): each singularity of index ±1/N in `vertex` (vertex → n) closer than `distance`
// along edges to a feature line is moved onto the nearest vertex w of the line, if w has two or more sharp
// edges (a line vertex or a junction) and no singularity: the sector of w facing it (its faces beside no other
// sharp edge) is turned through with one step more (−1/N) or fewer (+1/N) than the nearest to its angle, as a
// narrow corner's, so that w gets the index. A singularity a unit or so from a feature line would otherwise often be rounded onto the line's
// iso-line beside it (or one unit from it, where a strip between lines is squeezed to one unit), flattening the
// faces between them. The map requests use 1.5 units (trivcon/request.h, cancel_for_map). Without `flat_sectors`,
// not onto a sector whose quad corners at w would open wider than 1.5 steps (3π/4 for N = 4) each: a +1/N on a
// straight line or on a T-junction's straight side gives a quad one corner of about π (scaled Jacobian about 0).
// With `separation` > 0, not onto a vertex closer than that (along edges) to another singularity (one there
// already, or moved before it): two singularities less than a unit apart on one line can be rounded onto one
// integer point, folding the map between them (a row of round holes' rims); the next nearest line vertex is
// tried instead, else the singularity stays.
// With `boundary`, the boundary is such a line too (faces beside its edges fixed to them, as align_boundary
// does): a singularity moved onto a boundary vertex w turns w's fan (its faces from one boundary edge to the
// other, the faces beside those two following them exactly) and leaves no singularity: w becomes a corner of
// the boundary (a −1/N beside a round hole: a concave corner of the quads there, where a cone a fraction of a unit
// inside would be rounded onto the rim's iso-line or a unit from it). A fan of three faces cannot take the turn in
// steps the field reads unambiguously (two of π/4): on the boundary the next nearest vertices are tried too.
// Updates `vertex` and `alignment.fixed` (new faces among them: the sector's middle ones), lists the moves in
// `alignment.snapped` and the corners made in `alignment.corners`; the sectors of moves listed there already (an
// earlier call's) are not turned again.
void move_singularities_onto_features(const MatrixX3d& V, const Topology& topology, const Geometry& geometry, const std::vector<int>& edges,
                                      int N, double distance, bool flat_sectors, std::map<int, int>& vertex, FeatureAlignment& alignment,
                                      double separation = 0, bool boundary = false);

// For singularities given (vertex → n, index n/N; N even, N ≥ 4) on feature vertices (two or more sharp edges,
// interior): a sector at w whose faces follow its two edges turns through by the nearest whole number of steps
// k = round(θ/(2π/N)) (a narrow corner's by one), so w reads N − Σk without a turn of its own; where the index
// given differs from that by a step or more, as many plain sectors as the difference (beside no other sharp edge,
// not turned already) are turned through with one step fewer (+1/N) or more (−1/N), the sectors whose angle
// fits the new count best first (and not ones whose quad corners would open wider than 1.5 steps, while others
// fit). Otherwise the field makes up the difference with a turn of π/N or more across one edge of the sector,
// a large turn the map folds around: a placement of `quad --auto` written with --sing-out (a singularity moved
// onto a line, whose sector that move turned) and given back with -s. Updates `alignment.fixed` (the sectors'
// faces) and lists the sectors in `alignment.given_sectors` (from = to = the vertex, distance 0).
// With `boundary` (the boundary aligned), a boundary vertex w given index n/N is a corner of the boundary, as
// move_singularities_onto_features makes one: the plain sectors of its fan (from boundary edge to boundary edge,
// cut at sharp edges) are turned through with n steps fewer in all, and w is listed in `alignment.corners` when
// all n could be taken (not when a sector is turned already: a corner there, or a fan of three faces asked for a
// quarter turn). Boundary vertices are left alone without it.
void turn_sectors_for_singularities(const Topology& topology, const Geometry& geometry, const std::vector<int>& edges, int N,
                                    const std::map<int, int>& vertex, FeatureAlignment& alignment, bool boundary = false);
// The singular vertices with the corners of the boundary among them, as a singularity file lists them (the
// boundary vertices read back as corners with the boundary aligned).
std::map<int, int> with_corners(std::map<int, int> vertex, const std::map<int, int>& corners);

// One line of a .sharp file.
struct SharpFaceEdge {
  int convex;  // 1 convex, 0 concave
  int face;    // face id
  int edge;    // 0, 1, 2: from the face's vertex `edge` to vertex `edge` + 1 in the given F
};
// Writes QuadWild's .sharp for `edges` (interior edge ids) atomically; `F` is the mesh's faces as given (the
// file's order; the Topology was built from it), `convex` one flag per listed edge. With `input_face` (a repaired
// mesh's RepairedMesh::input_face), the faces written are the input's.
void write_sharp(const std::string& path, const MatrixX3i& F, const Topology& topology, const std::vector<int>& edges,
                 const std::vector<char>& convex, const std::vector<int>& input_face = {});
// Reads a .sharp file: checks the count, the faces (in [0, F)) and edges (0..2); errors name file:line.
std::vector<SharpFaceEdge> read_sharp(const std::string& path, int num_faces);

}  // namespace trivcon
