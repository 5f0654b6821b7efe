// SPDX-License-Identifier: MIT
// trivcon/geometry.h: the intrinsic and extrinsic geometry the trivial-connection solver needs.
//
// Conventions (all angles in radians)
// - Faces are those of Topology::F (consistently oriented). Face f's frame: the x axis runs along its
//   first half-edge, corner 0 → corner 1; angles increase counter-clockwise seen with the face's
//   normal n = (p1 − p0) × (p2 − p0) pointing at the viewer. A direction at angle β in face f is the
//   world vector cos β · frame_x(f) + sin β · frame_y(f), with frame_y = n̂ × frame_x.
// - Corner angles are intrinsic (from the three edge vectors via atan2(|a × b|, a · b)) and sum to π in
//   every face. Three distinct points get their true angles, so collinear ones give (0, 0, π) and a
//   face that is degenerate (area ≤ 1e-14 × its longest edge², or a zero-length edge) but not exactly flat gets angles within about
//   1e-14 of that; a zero-length edge gives 0 opposite it and π/2 at its endpoints; a face whose
//   corners coincide gives π/3 each.
// - half_edge_angle(f, k): the angle, in f's frame, of the half-edge from corner k to corner k+1:
//   0, π − α1, π + α0 for k = 0, 1, 2 (αk is the corner angle at corner k).
// - rho(e), for an interior edge e = (i, j), i < j, L = edge_faces(e, 0) and R = edge_faces(e, 1):
//   the Levi-Civita rotation from L to R, i.e. the angle of p_j − p_i in R's frame minus its angle in
//   L's frame, taken in (−π, π]. A direction at angle β_L in L is parallel-transported to β_L + ρ in R.
//   Boundary edges have ρ = 0 (unused).
// - angle_defect(v): 2π − Σ corner angles at an interior vertex (Gaussian curvature); π − Σ corner
//   angles at a boundary vertex (geodesic curvature of the boundary); 0 at an unreferenced vertex.
//   Gauss–Bonnet holds exactly per component: Σ angle_defect = 2π χ (up to round-off).
// - cotan_weight(e) = ½ (max(cot α, 0) + max(cot β, 0)) over the angles α, β opposite interior edge e
//   (the paper's Sections 2.5 and 4.2: negative cotangents are clamped). Boundary edges: 0. The
//   cotangents are those of the faces' intrinsic triangles, mollified (Sharp & Crane 2020, Sec. 4.5)
//   when the mesh has slivers, needles, zero-area faces or zero-length edges, per connected component:
//   if some face's edge lengths miss the triangle inequality by less than δ = 10⁻⁵ × the component's
//   mean edge length, the smallest ε that gives every face of the component that margin is added to
//   every edge length of the component, and its cotangents come from those lengths. Then every face has a well-defined shape and bounded
//   cotangents (at most about longest edge / δ), so no weight is ever NaN, infinite or 0 because of a
//   degenerate face, and a mesh that is a clean mesh with edges split at or next to an endpoint gets
//   (to within δ) the weights that give the clean mesh's field: a zero-length edge gets a very large
//   weight, which joins its two coincident ends. Only the weights are mollified: corner angles, ρ,
//   angle defects and frames are those of the mesh as given. A mesh whose faces all have the margin
//   keeps its exact cotangents (mollify_epsilon = 0, mollified_faces = 0).
#pragma once
#include <Eigen/Core>
#include <vector>

#include "trivcon/angles.h"  // wrap_angle, declared here before
#include "trivcon/topology.h"

namespace trivcon {

struct Geometry {
  MatrixX3d corner_angles;             // F × 3
  MatrixX3d half_edge_angle;           // F × 3
  Eigen::VectorXd face_area;           // extrinsic area, 0 for degenerate faces
  std::vector<char> degenerate_face;   // area ≤ 1e-14 × longest edge², or a zero-length edge
  MatrixX3d frame_x, frame_y, normal;  // unit vectors; for a degenerate face the normal is borrowed from its neighbours
  Eigen::VectorXd angle_defect;        // per vertex
  Eigen::VectorXd rho;                 // per edge
  Eigen::VectorXd cotan_weight;        // per edge
  int negative_cotan_edges = 0;        // interior edges with ½(cot α + cot β) < 0 before clamping
  int clamped_cotangents = 0;          // negative cotangents opposite interior edges, clamped to 0
  int zero_weight_edges = 0;           // interior edges of cotan weight 0 (both opposite angles ≥ π/2)
  int degenerate_faces = 0;            // faces treated as degenerate (see above)
  int zero_area_faces = 0;             // faces whose extrinsic area is exactly 0
  int mollified_faces = 0;             // faces whose lengths missed the triangle inequality by less than δ
  double mollify_epsilon = 0;          // the largest length ε added to a component's edges for the cotangents (0: none)
  std::vector<double> component_epsilon;  // per component (Topology::components): its ε (0: not mollified)
  // Per face: the area of its intrinsic triangle with the component's ε added to its edge lengths (Kahan's
  // Heron), for the faces whose cotangents were mollified; face_area for every other face (whose margin is at
  // least 1000 δ, so adding ε would change its area by less than about 1e-3 relative). Positive on every face
  // of a mollified component, including zero-area faces (trivcon/auto.h measures its field with it).
  Eigen::VectorXd mollified_area;

  // Angle of the world vector `d` in face f's frame (its projection onto the face's plane).
  double angle_in_face(int f, const Eigen::Vector3d& d) const;
  // World unit vector at angle `beta` in face f's frame.
  Eigen::Vector3d direction_in_face(int f, double beta) const;
};

// The per-face and per-edge loops run on `threads` OpenMP threads (0: OpenMP's default) on meshes of
// more than 50k faces.
Geometry compute_geometry(const MatrixX3d& V, const Topology& topology, int threads = 0);

// Mean Euclidean length of the mesh's edges (0 without edges): the unit of --auto-cancel, of the renderer's
// glyph size, and of anything else measured "in mean edge lengths".
double mean_edge_length(const MatrixX3d& V, const Topology& topology);

// Whether edge e's two ends are at exactly one position (an edge of length 0: a pole row or seam of a mesh exported
// unwelded, a collapsed edge).
inline bool zero_length_edge(const MatrixX3d& V, const Topology& topology, int e) {
  return V.row(topology.edge_vertices(e, 0)) == V.row(topology.edge_vertices(e, 1));
}

// Angle in face f's frame of a world direction, after projection onto the face's plane. Errors name the
// face: a zero or non-finite direction, or one perpendicular to the face.
double fixed_angle_from_direction(const Geometry& geometry, int face, const Eigen::Vector3d& direction);


}  // namespace trivcon
