// trivcon/constraints.h: fixed directions at faces (paper Section 2.8) and boundary alignment.
//
// A fixed face f holds a direction γ_f (an angle in f's frame, trivcon/geometry.h); the field must equal
// it modulo 2π/N. The fixed faces of a component are joined by a spanning tree of short dual paths:
// faces are grown breadth-first from all fixed faces at once (each face joins the region of its nearest
// fixed face), then regions are linked, shortest link first (Kruskal), through the interior edges between
// them. Each link is a path from fixed face a to fixed face b: up a's region tree, across the linking
// edge, down b's region tree. It adds one constraint row (trivcon/solver.h):
//   Σ_path c_e x_e = Σ_path c_e ρ_e − (γ_b − γ_a) − (2π/N) j,
// i.e. parallel transport adjusted by x carries γ_a onto γ_b up to a whole number j of 1/N turns; j is
// chosen like a free generator index, so that the field is smoothest. These rows are independent of each
// other and of the cycle rows, so every fixed face holds exactly and no singularity is added.
#pragma once
#include <Eigen/Core>
#include <map>
#include <string>
#include <vector>

#include "trivcon/cycles.h"
#include "trivcon/geometry.h"
#include "trivcon/topology.h"

namespace trivcon {

struct FixedPath {
  int from_face = 0, to_face = 0;  // both fixed
  DualCycle path;                  // signed dual edges from `from_face` to `to_face` (DualCycle::component set)
};

// The linking paths for the given fixed faces (sorted, unique); k fixed faces on a component give k − 1 paths.
// Region trees only cross edges marked `usable` (those of positive weight: an edge of zero weight carries no
// adjustment); two regions are linked across an unusable edge only when nothing else joins them, and such
// a path may have no usable edge at all ("rigid": the two directions must then agree after parallel transport).
std::vector<FixedPath> fixed_face_paths(const Topology& topology, const std::vector<int>& fixed_faces, const std::vector<char>& usable);

// Angle in face f's frame of a world direction, after projection onto the face's plane. Errors name the
// face: a zero or non-finite direction, or one perpendicular to the face.
double fixed_angle_from_direction(const Geometry& geometry, int face, const Eigen::Vector3d& direction);

// Adds fixed directions from a file: one "FACE x y z" (world direction) or "FACE angle=A" (radians, in the
// face's frame) per line, '#' comments; and from "F:x,y,z" or "F:angle=A" specs (--fix). Face ids are
// checked against the mesh; a face given twice is an error.
void read_fixed_directions(const std::string& path, const Topology& topology, const Geometry& geometry, std::map<int, double>& fixed);
void add_fixed_direction(const std::string& spec, const Topology& topology, const Geometry& geometry, std::map<int, double>& fixed);

// --align-boundary: every face with a boundary edge, fixed to the direction of that edge as the
// boundary loop runs (surface on the left); the longest such edge where a face has several.
std::map<int, double> boundary_alignment(const MatrixX3d& V, const Topology& topology, const Geometry& geometry);

// Pairs of edge-adjacent fixed faces whose directions, after parallel transport across the shared
// edge, differ by more than π/(2N) modulo 2π/N: the field must turn sharply there. (face a, face b, turn).
struct FixedConflict {
  int face_a, face_b;
  double turn;  // radians, in (−π/N, π/N]
};
std::vector<FixedConflict> fixed_conflicts(const Topology& topology, const Geometry& geometry, const std::map<int, double>& fixed, int N);

}  // namespace trivcon
