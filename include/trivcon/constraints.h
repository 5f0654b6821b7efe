// SPDX-License-Identifier: MIT
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
#include <functional>
#include <map>
#include <string>
#include <vector>

#include "trivcon/cycles.h"
#include "trivcon/field.h"
#include "trivcon/geometry.h"
#include "trivcon/indices.h"
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

// Adds fixed directions from a file: one "FACE x y z" (world direction) or "FACE angle=A" (radians, in the
// face's frame) per line, '#' comments; and from "F:x,y,z" or "F:angle=A" specs (--fix). Face ids are
// checked against the mesh; a face given twice is an error. `face_id`, when given, maps an id as written to the
// mesh's face (e.g. an input's face on its repair, repaired_face in trivcon/repair.h) and checks it instead.
using FaceIdMap = std::function<int(int)>;
void read_fixed_directions(const std::string& path, const Topology& topology, const Geometry& geometry, std::map<int, double>& fixed,
                           const FaceIdMap& face_id = nullptr);
void add_fixed_direction(const std::string& spec, const Topology& topology, const Geometry& geometry, std::map<int, double>& fixed,
                         const FaceIdMap& face_id = nullptr);

// --align-boundary: every face with a boundary edge, fixed to the direction of that edge as the
// boundary loop runs (surface on the left); the longest such edge where a face has several. An edge of length
// 0 (its ends one point) has no direction: a face beside no other boundary edge is not fixed.
std::map<int, double> boundary_alignment(const MatrixX3d& V, const Topology& topology, const Geometry& geometry);

// Pairs of edge-adjacent fixed faces whose directions, after parallel transport across the shared
// edge, differ by more than π/(2N) modulo 2π/N: the field must turn sharply there. (face a, face b, turn).
struct FixedConflict {
  int face_a, face_b;
  double turn;  // radians, in (−π/N, π/N]
};
std::vector<FixedConflict> fixed_conflicts(const Topology& topology, const Geometry& geometry, const std::map<int, double>& fixed, int N);

// Fixed directions along a whole boundary loop decide its index, and with it (Gauss–Bonnet) the sum of the
// component's vertex indices. A loop is decided when every face with an edge on it is fixed (as
// boundary_alignment fixes them). Its index is the one a field holding the fixed directions reads around it
// (field_indices, trivcon/field.h): the fan of faces around each loop vertex is walked from one boundary
// face to the other, the direction carried by parallel transport between fixed faces and, at each fixed
// face, turned onto its direction by the closest of the N choices. A turn of exactly π/N (e.g. a 45° corner
// of the boundary with N = 4) can be read either way: `ambiguous` counts them (each may move the index by
// ±1/N).
struct AlignedLoop {
  int loop = 0;
  int index = 0;      // n (index n/N)
  int ambiguous = 0;  // turns within 1e-6 rad of π/N
};
std::vector<AlignedLoop> aligned_loop_indices(const Topology& topology, const Geometry& geometry, const std::map<int, double>& fixed,
                                              int N);

// A field that holds such fixed directions may still turn by whole 2π/N steps more than that reading around a
// boundary vertex (a singularity on the boundary, which trivcon does not place: boundary vertices carry no
// index). For each boundary vertex whose fan's end faces are fixed (and whose reading is not ambiguous), the
// difference between `field`'s own reading of the fan (each jump by the closest matching, as field_indices)
// and the reading above, in units of 2π/N, is moved to the smallest interior vertex joined to it by an edge (with
// none, the smallest of the nearest interior vertices by edges):
// returns those vertices and the indices (n, index n/N) to add to their singularities so that the vertex
// indices sum to what check_aligned_index_sums asks (auto_singularities does this).
std::map<int, int> boundary_turns_moved_inside(const Topology& topology, const Geometry& geometry, const std::map<int, double>& fixed,
                                               const Field& field);

// Throws trivcon::Error when fixed directions decide every boundary loop of a component (above) and the
// prescription's vertex indices there do not sum to N χ − Σ loop indices (up to the ambiguous turns), or a
// prescribed loop index differs from the one its fixed directions decide. The connection would otherwise
// be exact but turn by 2π/N or more across some edges to reach the fixed directions, and the per-face field
// would read singularities nobody placed (e.g. a boundary-aligned disk with none: four of +1/4). The message
// names the component, the sum needed and the sum given, and suggests placing them (or --auto).
void check_aligned_index_sums(const Topology& topology, const Geometry& geometry, const IndexPrescription& prescription);

}  // namespace trivcon
