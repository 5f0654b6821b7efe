// trivcon/repair.h: a mesh as users have it made manifold, with maps back to the input.
//
// What repair_mesh does, in this order:
// - exact duplicate faces (the same three vertices in any order) are dropped; each maps to the face it
//   duplicates (the first one in file order);
// - an edge with more than two faces is cut: its faces are paired into manifold sheets, consistently oriented
//   pairs first (one face holds i → j, the other j → i), in file order; a face left without a partner keeps
//   the edge as a boundary edge;
// - then every vertex whose faces form several fans (connected across the paired edges) is split: the fan
//   holding the vertex's first corner in file order keeps the vertex's id, each other fan gets a new vertex,
//   appended after the input's vertices in order of first appearance.
// Faces stay in file order (duplicates left out) with their corners in the input's order; the re-orientation of
// orientable components is build_topology's (trivcon/topology.h). Faces with a repeated vertex, indices out of
// range and non-orientable components are not repaired: build_topology's errors name them.
#pragma once
#include <string>
#include <utility>
#include <vector>

#include "trivcon/common.h"

namespace trivcon {

struct RepairedMesh {
  MatrixX3d V;                    // the input's vertices (same ids), then the split vertices' copies
  MatrixX3i F;                    // the input's faces in order, duplicates left out
  std::vector<int> face_of_input;  // per input face: its face in F (for a duplicate, the face it duplicates)
  std::vector<int> input_face;     // per face of F: its input face
  std::vector<int> vertex_origin;  // per vertex of V: the input vertex it copies (itself for ids < input count)
  // What was done (ids of the input).
  std::vector<std::pair<int, int>> duplicates;         // (dropped face, the face it duplicates), increasing
  std::vector<std::pair<int, int>> cut_edges;          // (i, j), i < j: edges that had more than two faces
  std::vector<std::pair<int, int>> split_vertices;     // (vertex, fans): vertices split into that many
  std::vector<int> unpaired_faces;                     // faces left as boundary beside a cut edge
  bool changed() const { return !duplicates.empty() || !cut_edges.empty() || !split_vertices.empty(); }
};

// Throws trivcon::Error for an index out of range or a face with a repeated vertex (as build_topology does).
RepairedMesh repair_mesh(const MatrixX3d& V, const MatrixX3i& F);

// One sentence with the counts and the first ids ("" when nothing was done), e.g. "repaired: 2 duplicate faces
// dropped (first: face 9, a copy of face 3); 1 edge with more than two faces cut (first: (6, 7), 4 faces);
// 3 vertices split into separate fans (first: vertex 22, 2 fans)".
std::string repair_summary(const RepairedMesh& repaired);

// For a vertex of the input that was split: the first face (input id) of each of its fans, in fan order; empty
// when it was not split. For the message of a singularity prescribed there.
std::vector<int> fan_faces(const RepairedMesh& repaired, int input_vertex);

}  // namespace trivcon
