// SPDX-License-Identifier: MIT
// trivcon/streamlines.h: integral curves of a per-face direction field (the paper's Figure 16 "ribbons"),
// and deterministic, evenly spread sample points on a surface.
//
// Conventions
// - A field is constant in each face (trivcon/field.h: N directions per face). A streamline is a polyline
//   whose every segment lies in one face and is parallel to one of that face's N directions: within a face
//   it runs straight from where it entered to the face's boundary, then crosses the edge into the
//   neighbour (Topology::edge_faces), where it continues along the neighbour's direction closest to its
//   own direction carried across the edge by Levi-Civita transport (Geometry::rho, i.e. unfolding the two
//   faces into a plane). Points on an edge are computed from the edge's two vertices, so they lie exactly
//   on both faces.
// - Each seed starts one line per family of directions: N/2 lines for even N (direction k and k + N/2 are the
//   same line), N for odd N (1 for vector fields). Every line is traced forwards and backwards from its seed
//   and stored as one polyline oriented along the field direction it follows.
// - A line stops: at a boundary edge; on entering a face that has a singular vertex as a corner (so no line
//   passes through or touches a singular vertex) or a degenerate face; where the next face's direction
//   would lead back out through the edge just crossed (the field converges there); on hitting a vertex
//   (within 1e-6 of an edge's length); when it comes within `separation`/2 of a near-parallel part of another
//   line (or of itself further than 2·separation back along it: closed orbits close); after `max_length`
//   or `max_steps` faces per direction.
// - Seeds are candidate points spread over the surface by area in a fixed pseudo-random order (std::mt19937
//   with a fixed seed); a candidate starts a line of a family only when no near-parallel line passes within
//   `separation` of it. Lines shorter than `separation` are dropped. Output is deterministic for given
//   inputs (no threads, no clocks).
// - Units: world units of V; angles in radians.
#pragma once
#include <Eigen/Core>
#include <string>
#include <utility>
#include <vector>

#include "trivcon/field.h"
#include "trivcon/geometry.h"
#include "trivcon/topology.h"

namespace trivcon {

struct StreamlineOptions {
  double separation = 0;     // distance between neighbouring lines, world units; 0: 1/50 of the bounding-box diagonal
  double max_length = 0;     // per line and direction, world units; 0: 10 × the bounding-box diagonal
  int max_steps = 200000;    // faces crossed per line and direction
  bool all_families = true;  // false: one line per seed (direction 0 of the seed's face) even for N ≥ 2
};

struct Streamline {
  std::vector<Eigen::Vector3d> points;  // at least 2
  std::vector<int> faces;               // faces[i] holds the segment points[i] → points[i + 1]
  double length() const;
};

// Traces evenly spaced streamlines. `singularities` are (vertex, n) pairs (index n/N, as in
// trivcon/indices.h); only the vertices matter here (lines stop next to them).
std::vector<Streamline> trace_streamlines(const MatrixX3d& V, const Topology& topology, const Geometry& geometry, const Field& field,
                                          const std::vector<std::pair<int, int>>& singularities, const StreamlineOptions& options = {});

// Writes the lines as an OBJ: all points as "v x y z" (17 significant digits), then one "l i j k ..."
// (1-based) per line. Atomic (trivcon/io.h); errors name the path.
void write_streamlines_obj(const std::string& path, const std::vector<Streamline>& lines);

struct SurfacePoint {
  int face = 0;
  Eigen::Vector3d position;  // inside the face (a convex combination of its corners)
};
// Points on the surface with pairwise distances ≥ `spacing` (a Poisson-disk-like set, about one per
// spacing² of area), chosen in a fixed pseudo-random order among candidates spread by area;
// `usable[f]` == 0 excludes face f (pass an empty vector to use all faces). Deterministic.
std::vector<SurfacePoint> sample_surface(const MatrixX3d& V, const Topology& topology, const Geometry& geometry, double spacing,
                                         const std::vector<char>& usable = {});

}  // namespace trivcon
