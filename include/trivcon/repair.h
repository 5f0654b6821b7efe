// SPDX-License-Identifier: MIT
// trivcon/repair.h: a mesh as users have it made manifold, with maps back to the input.
//
// What repair_mesh does, in this order:
// - faces with a repeated vertex (a, a, b) are dropped: they have no direction; each maps to a face sharing its
//   edge (a, b), else one sharing a vertex (for the field a per-face output gives it), else to −1;
// - exact duplicate faces (the same three vertices in any order) are dropped; each maps to the face it
//   duplicates (the first one in file order);
// - an edge with more than two faces is cut: its faces are paired into manifold sheets, consistently oriented
//   pairs first (one face holds i → j, the other j → i), in file order; a face left without a partner keeps
//   the edge as a boundary edge;
// - then every vertex whose faces form several fans (connected across the paired edges) is split: the fan
//   holding the vertex's first corner in file order keeps the vertex's id, each other fan gets a new vertex,
//   appended after the input's vertices in order of first appearance;
// - where the sheets of a cut edge meet again around both its ends (so that splitting its vertices cannot
//   separate them, e.g. two pages joined along two edges), the faces beyond the first two on the edge (in file
//   order) are dropped and the repair runs again; each maps like a degenerate face, to a face sharing an edge.
// Faces stay in file order (duplicates left out) with their corners in the input's order; the re-orientation of
// orientable components is build_topology's (trivcon/topology.h). Indices out of range and non-orientable
// components are not repaired: build_topology's errors name them.
#pragma once
#include <map>
#include <string>
#include <utility>
#include <vector>

#include "trivcon/common.h"

namespace trivcon {

struct RepairedMesh {
  MatrixX3d V;                    // the input's vertices (same ids), then the split vertices' copies
  MatrixX3i F;                    // the input's faces in order, duplicates left out
  std::vector<int> face_of_input;  // per input face: its face in F (for a duplicate, the face it duplicates; for a
                                   // dropped face, one sharing an edge or a vertex, or −1)
  std::vector<int> input_face;     // per face of F: its input face
  std::vector<int> vertex_origin;  // per vertex of V: the input vertex it copies (itself for ids < input count)
  int input_vertices = 0, input_faces = 0;  // the input's counts
  // What was done (ids of the input).
  std::vector<int> degenerate_faces;                   // dropped faces with a repeated vertex, increasing
  std::vector<std::pair<int, int>> duplicates;         // (dropped face, the face it duplicates), increasing
  std::vector<std::pair<int, int>> cut_edges;          // (i, j), i < j: edges that had more than two faces
  std::vector<std::pair<int, int>> split_vertices;     // (vertex, fans): vertices split into that many
  std::vector<int> unpaired_faces;                     // faces left as boundary beside a cut edge
  std::vector<int> unseparated_faces;                  // dropped where sheets of a cut edge meet again, increasing
  bool changed() const {
    return !degenerate_faces.empty() || !duplicates.empty() || !cut_edges.empty() || !split_vertices.empty() || !unseparated_faces.empty();
  }
};

// Throws trivcon::Error for an index out of range (as build_topology does) and when no face is left.
RepairedMesh repair_mesh(const MatrixX3d& V, const MatrixX3i& F);

// One sentence with the counts and the first ids ("" when nothing was done), e.g. "repaired: 2 duplicate faces
// dropped (first: face 9, a copy of face 3); 1 edge with more than two faces cut (first: (6, 7), 4 faces);
// 3 vertices split into separate fans (first: vertex 22, 2 fans)".
std::string repair_summary(const RepairedMesh& repaired);

// For a vertex of the input that was split: the first face (input id) of each of its fans, in fan order; empty
// when it was not split. For the message of a singularity prescribed there.
std::vector<int> fan_faces(const RepairedMesh& repaired, int input_vertex);

// Ids a user states in the input's numbering, on the repaired mesh. Each throws trivcon::Error for an id out of the
// input's range; `what` starts the message ("singular vertex", "fixed face", ...).
// - A vertex keeps its id; one that repair split into several fans is an error naming the first face of each fan:
//   which sheet is meant cannot be told from the input's id (place it on the repaired mesh instead, written by
//   --mesh-out, where each fan has its own id).
// - A face goes to face_of_input (a duplicate to the face it duplicates); a dropped degenerate face is an error.
int repaired_vertex(const RepairedMesh& repaired, int input_vertex, const std::string& what);
int repaired_face(const RepairedMesh& repaired, int input_face, const std::string& what);
// Per-face rows of the input (a field file) as rows of the repaired mesh.
MatrixX3d rows_on_repaired(const RepairedMesh& repaired, const MatrixX3d& input_rows);
// Per-corner rows of the repaired mesh (F × 3w: w numbers per corner, corners in F's order, e.g. a map's (u, v))
// for the input's faces `input_F`: each input face takes the row of face_of_input, its corners matched by vertex
// (a duplicate may list them in another order); a degenerate face's corners take those of the face it maps to at
// the same vertex, else its first corner's; a face mapped to −1 gets zeros.
Eigen::MatrixXd corner_rows_on_input(const RepairedMesh& repaired, const MatrixX3i& input_F, const Eigen::MatrixXd& rows);
// The inverse: per-corner rows of the input's faces as rows of the repaired mesh's (a kept face keeps its corners
// in the input's order).
Eigen::MatrixXd corner_rows_on_repaired(const RepairedMesh& repaired, const Eigen::MatrixXd& input_rows);
// Singular vertices (vertex → n) given by the input's ids, on the repaired mesh (repaired_vertex for each).
std::map<int, int> singularities_on_repaired(const RepairedMesh& repaired, const std::map<int, int>& input_vertex);
// Per-vertex values (e.g. singularities: vertex → n) of the repaired mesh by the input's ids: a copy's goes to the
// vertex it copies (summed with the others there; zeros left out).
std::map<int, int> values_on_input(const RepairedMesh& repaired, const std::map<int, int>& per_vertex);
// The vertices of the repaired mesh that copy input vertex v (v itself first), for edges named by input vertices.
std::vector<int> vertex_copies(const RepairedMesh& repaired, int input_vertex);

}  // namespace trivcon
