// SPDX-License-Identifier: MIT
// trivcon/topology.h: connectivity, validation and topological invariants of a triangle mesh.
//
// Conventions
// - Vertex and face ids are the caller's (the file's); nothing is renumbered. Edges get ids in order
//   of first appearance when faces are scanned in order, corners 0→1, 1→2, 2→0.
// - Edge e = {i, j} is stored with i < j. Its faces: edge_faces(e, 0) is the face holding the
//   half-edge i→j ("L"), edge_faces(e, 1) the face holding j→i ("R"); −1 where there is none, so
//   boundary edges have exactly one of the two.
// - face_edges(f, k) is the edge from corner k to corner k+1 (mod 3) of face f in the oriented F.
// - Orientation: an orientable component whose faces disagree is re-oriented consistently by
//   flipping the smaller of the two classes of faces (ties: keep the lowest face id's orientation);
//   flipping (a, b, c) gives (a, c, b). `F` below is the oriented copy; `flipped_faces` lists them.
// - Boundary loops are ordered vertex cycles that follow the boundary edges in the direction of the
//   oriented faces (a face's boundary half-edge i→j gives loop order i, j), so the surface lies to
//   the left. Loops are numbered by their smallest vertex id, increasing; each loop starts at its
//   smallest vertex id.
// - Components are connected components of faces (sharing an edge; a shared vertex alone is a
//   non-manifold vertex and an error), numbered by their smallest face id. χ = V − E + F over the
//   component's referenced vertices; genus g = (2 − χ − b)/2.
// Validation errors (trivcon::Error), each naming the element:
//   "face 7 has a repeated vertex (3, 3, 9)", "vertex index 40 out of range in face 7 (mesh has 39
//   vertices)", "non-manifold edge (12, 40) shared by 3 faces (2, 5, 9)", "non-manifold vertex 17: its
//   faces form 2 separate fans", "non-orientable component 0 (containing face 0): faces 3 and 8 cannot
//   be oriented consistently across edge (4, 5); the orientation flips once along the cycle of faces 8 -> 7 ->
//   ... -> 3 -> 8 (12 faces, each sharing an edge with the next)" (up to 24 faces listed), "non-finite coordinate in vertex 12".
#pragma once
#include <Eigen/Core>
#include <string>
#include <vector>

#include "trivcon/common.h"

namespace trivcon {

struct ComponentInfo {
  int faces = 0;
  int vertices = 0;  // referenced vertices
  int edges = 0;
  int euler_characteristic = 0;
  int genus = 0;
  std::vector<int> boundary_loops;  // ids into Topology::boundary_loops
  int first_face = 0;               // smallest face id in the component
};

struct Topology {
  int num_vertices = 0;
  int num_faces = 0;
  int num_edges = 0;
  MatrixX3i F;              // consistently oriented faces (equal to the input where no flip was needed)
  MatrixX2i edge_vertices;  // (i, j), i < j
  MatrixX2i edge_faces;     // (L, R) as above, −1 for none
  MatrixX3i face_edges;     // edge from corner k to k+1
  std::vector<int> face_component;
  std::vector<int> vertex_component;      // −1 for unreferenced vertices
  std::vector<int> vertex_boundary_loop;  // loop id for boundary vertices, −1 otherwise
  std::vector<std::vector<int>> boundary_loops;
  std::vector<ComponentInfo> components;
  std::vector<int> unreferenced_vertices;
  std::vector<int> flipped_faces;  // faces whose orientation was reversed
  // CSR adjacency: the faces around each vertex, and the edges at each vertex (unordered).
  std::vector<int> vertex_face_offsets, vertex_faces;
  std::vector<int> vertex_edge_offsets, vertex_edges;

  bool is_boundary_edge(int e) const { return edge_faces(e, 0) < 0 || edge_faces(e, 1) < 0; }
  bool is_boundary_vertex(int v) const { return vertex_boundary_loop[v] >= 0; }
  bool is_interior_vertex(int v) const { return vertex_component[v] >= 0 && vertex_boundary_loop[v] < 0; }
  // The corner k of face f at vertex v (F(f, k) == v), or −1 when v is not one of f's.
  int corner_of(int f, int v) const {
    for (int k = 0; k < 3; ++k)
      if (F(f, k) == v) return k;
    return -1;
  }
  int euler_characteristic() const;
};

// The edge joining vertices i and j (either order), or −1 (also for ids out of range): one scan of i's edges.
int edge_between(const Topology& topology, int i, int j);

// The faces around vertex v, counter-clockwise (each face's edge from v's previous corner to v leads to the next),
// into `out`. At a boundary vertex the fan starts with the face whose edge from v to its next corner is on the
// boundary and ends with the face whose edge into v is; around an interior vertex it starts anywhere.
void vertex_fan(const Topology& topology, int v, std::vector<int>& out);

// Builds connectivity in O(V + F) (expected) and validates; throws trivcon::Error on the first
// problem found. `num_vertices` is V (vertex ids must be in [0, V)).
Topology build_topology(const MatrixX3i& F, int num_vertices);

// Checks that every coordinate is finite; throws naming the first bad vertex.
void check_finite(const MatrixX3d& V);
// Checks that the mesh's size lets squared lengths, cross products and areas be computed in double
// precision: every coordinate within ±1e150, and the longest edge at least 1e-150 (when there are edges).
// Throws naming the vertex or the edge and what to do (scale the mesh).
void check_coordinate_range(const MatrixX3d& V, const Topology& topology);

}  // namespace trivcon
