// SPDX-License-Identifier: MIT
// trivcon/quad.h: the quad mesh of a seamless integer-grid map (trivcon/param.h): the integer points of the map
// are its vertices, the integer iso-lines between them its edges (in the manner of QEx: Ebke, Bommes, Campen &
// Kobbelt 2013). The steps and what happens on folded maps: docs/quad.md.
//
//   trivcon::QuadMesh q = trivcon::extract_quads(designer, param);
//   q.V, q.Q                    // vertices on the input surface, quads counter-clockwise
//   q.quality.problems          // every guarantee that failed, one sentence each ("" = none)
//
// Conventions
// - Charts: the map's (u, v) is read as whole multiples of 2⁻²⁰, one value per vertex carried around its fan
//   through the exact transitions of the cut, so the two sides of every edge agree exactly and every predicate
//   (point in triangle, on an edge, at a vertex) is decided in exact integer arithmetic. Hence coordinates
//   within about 5·10⁻⁷ of a whole number count as that whole number (cones and aligned edges are).
// - Vertices: one per integer point of the map: at an input vertex, inside an input edge, or inside an input
//   face whose (u, v) triangle is positively oriented (points inside folded or degenerate triangles are dropped
//   and counted). vertex_face / vertex_barycentric say where each lies: a face of Topology::F and barycentric
//   coordinates in the corner order of that (oriented) face; V is their interpolation of the input positions.
// - Edges: the traces that come back (from p to q, and from q to p); a trace that fails or ends elsewhere is no
//   edge. Quads: Q's rows are counter-clockwise seen from the side Topology::F's faces are oriented to (the
//   input's orientation where the topology did not re-orient it). Faces of that graph that are not quads are
//   filled with quads around a new vertex where they have an even number of sides (QuadOptions::fill_faces;
//   such a vertex has vertex_cone −1); the others are not in Q: they are listed in other_faces. Both reported.
// - Boundary: quad edges along the input's boundary exist only where the boundary lies on integer iso-lines
//   (ParamOptions::aligned_edges holding the boundary edges); elsewhere traces leave the surface and are
//   reported.
#pragma once
#include <Eigen/Core>
#include <string>
#include <vector>

#include "trivcon/design.h"
#include "trivcon/param.h"

namespace trivcon {

struct QuadOptions {
  int max_trace_faces = 0;  // input faces one iso-line trace may cross (0: the number of faces of the mesh)
  bool check = true;        // run check_quads on the result (fills the measures below the extraction's own)
  // Move the vertices of inverted or nearly inverted quads on the surface (docs/quad.md, "Relaxation"): quads
  // whose worst corner's sine about the surface's normal is below this; 0 or less: no relaxation.
  double relax_below = 0.2;
  // Fill the faces of the traced graph that are not quads and have an even number of sides (around the map's
  // folds) with quads around one new vertex each, or a hexagon with a diagonal (docs/quad.md, "Faces",
  // Filling): the mesh is then all quads where it can be, and the valences there, which are not the map's, are
  // reported by the check.
  bool fill_faces = true;
};

struct QuadQuality {
  // The extraction itself.
  int integer_points = 0;          // integer points found (at vertices, inside edges, inside positive faces)
  int dropped_points = 0;          // integer points inside folded or degenerate (u, v) triangles, not used
  int traces = 0;                  // iso-line segments traced (one per direction at each vertex)
  int failed_traces = 0;           // traces that left the surface, ran out of faces or ended on no integer point
  int abandoned_traces = 0;        // of the failed ones: given up because all traces together crossed too many faces
  int unmatched_traces = 0;        // traces whose end does not trace back to their start
  int non_quad_faces = 0;          // faces of the traced graph with other than 4 sides (other_faces)
  int open_faces = 0;              // walks around a face that did not close (0 expected: see docs/quad.md)
  int unused_vertices = 0;         // integer points in no face (dropped from V)
  int unclosed_vertices = 0;       // input vertices whose (u, v) does not come back to itself around its fan
  int map_folds = 0;               // the map's flipped and degenerate faces (ParamQuality), for the warning
  int map_tiny_components = 0;     // the map's components smaller than one unit square (ParamQuality), for the warning
  int relaxed_vertices = 0;        // vertices moved on the surface to undo inverted or nearly inverted quads
  int filled_faces = 0;            // of the non-quad faces: filled with quads around a new vertex (QuadOptions::fill_faces)
  std::vector<int> problem_faces;  // up to 10 input faces where points were dropped or traces failed
  // Of the quad mesh (check_quads).
  int quads = 0, vertices = 0, edges = 0, boundary_loops = 0, components = 0, euler_characteristic = 0;
  int input_euler_characteristic = 0, input_boundary_loops = 0, input_components = 0;
  int irregular_vertices = 0;  // interior vertices of valence != 4
  // Irregular interior vertices not at a cone, plus cones (index n/4, n != 0) whose quad vertex does not have
  // valence 4 − n or that have no quad vertex.
  int singular_mismatches = 0;
  int non_manifold_edges = 0;     // edges in more than two quads
  int non_manifold_vertices = 0;  // vertices whose quads form more than one fan
  bool manifold = false, oriented = false;
  // Quads whose normal (p2 − p0) × (p3 − p1) points against the surface's: the normal of the input face nearest
  // to the quad's centre (among the faces of the component of its first corner's vertex_face, when given).
  int inverted_quads = 0;
  double min_scaled_jacobian = 0, mean_scaled_jacobian = 0;  // per corner: sine of its angle about the quad's normal
  // Quads with a corner of scaled Jacobian ≤ 0 (flat or reflex; not inverted): where a cone sits on a straight
  // feature line or in a strip between two, or the map turns at a concave boundary, at a vertex the relaxation
  // of src/quad/relax.h keeps in place (a cone, a vertex on an aligned edge or on the boundary).
  int nonconvex_quads = 0;
  // Largest distance from a quad's centre or edge midpoint to the input surface (its component, when vertex_face
  // is given), over the input's bounding box diagonal (the vertices lie on the surface by construction).
  double hausdorff_relative = 0;
  double target_quads = 0;  // the map's target_squares
  double seconds_extract = 0, seconds_check = 0;
  std::vector<std::string> problems;  // each failed guarantee in one sentence; empty when all hold
};

struct QuadMesh {
  Eigen::MatrixXd V;                   // quad vertices, on the input surface
  Eigen::MatrixX4i Q;                  // quads, counter-clockwise (see the conventions)
  Eigen::VectorXi vertex_face;         // face of Topology::F each vertex lies in
  Eigen::MatrixXd vertex_barycentric;  // V × 3: its barycentric coordinates there (Topology::F's corner order)
  Eigen::VectorXi vertex_cone;         // the input vertex it sits on (a cone, or any vertex on an integer point), else −1
  // Faces of the traced graph that are not quads and were not filled (vertex ids, counter-clockwise). On a closed
  // surface Q and these run each side of every edge once, also where the map folds (where faces are often not quads).
  std::vector<std::vector<int>> other_faces;
  QuadQuality quality;
};

// The quad mesh of `param` (made by parametrize on `designer` for one design). Throws trivcon::Error when the
// map does not belong to the designer's mesh (sizes, a cut edge on the boundary), a transition is not a quarter
// turn, a (u, v) or translation is not finite or too large (≥ 2³⁰), or the faces' (u, v) bounding boxes cover more
// than 2²⁷ unit squares (a broken map); every other failure (folds, traces that do not meet, faces that are not
// quads) is reported in quality.problems.
QuadMesh extract_quads(const FieldDesigner& designer, const Parametrization& param, const QuadOptions& options = {});

// Measures the quad mesh (V, Q, vertex_cone) against the input surface and the map's cones, from the quads
// alone: fills the second part of QuadQuality (from `quads` on) and appends to `quality.problems` what fails:
// quads with a repeated vertex, non-manifold, not oriented, χ, boundary loops or components differing from the
// input's, valences against the cones, inverted quads (the distance to the surface is measured, not judged).
// Throws trivcon::Error when Q refers to a vertex out of range or vertex_cone's size is not V's.
void check_quads(const FieldDesigner& designer, const Parametrization& param, QuadMesh& quads);

// One sentence on what is wrong with the quad mesh ("" when every guarantee holds): for a report or a warning.
std::string quad_warning(const QuadMesh& quads);

}  // namespace trivcon
