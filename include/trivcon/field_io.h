// SPDX-License-Identifier: MIT
// trivcon/field_io.h: the files `trivcon solve` writes, and the readers that take them back.
//
// Formats (all ids 0-based and the input file's own; faces in file order after fan triangulation):
// - Field text (.txt or any other extension): lines starting with '#' are comments; trivcon writes
//   "# trivcon field", "# N <N>", "# faces <F>" first. Then one line "x y z" per face: the first of the
//   face's N unit directions, in world coordinates, in the face's plane. The others are that vector
//   rotated by 2πk/N about the face normal (right-hand rule, normal of the face as oriented).
// - .rawfield (Directional's raw field): first line "N F", then one line per face with 3N numbers,
//   the N vectors x y z one after the other, counter-clockwise.
// - .rosy (QuadWild's 4-RoSy field, vcglib Load4ROSY): line 1 the face count, line 2 N (always 4: the
//   writer refuses another N), then one line "x y z" per face, the first direction as in the text format.
// - .ply: binary little-endian PLY of the mesh (vertex: double x y z; face: list uchar int
//   vertex_indices, then double fx fy fz = the first direction).
// - Connection: "# trivcon connection", "# N <N>", then one line "i j x" per interior edge, i < j,
//   sorted by (i, j); x is the adjustment angle in radians with the sign of trivcon/solver.h.
// - Matching (.matching, Directional's format): first line "N E" (E interior edges), then one line
//   "L R i j m" per interior edge in increasing (i, j): its faces L = edge_faces(e, 0) and R, its vertices
//   i < j, and m in [0, N): direction 0 of L, carried into R, is direction m of R (trivcon/matching.h).
// - Lines (.obj): for each face and each of its N directions, a segment from the face centroid of length
//   0.4 × the face's mean edge length: "v" lines, then "l a b" lines (1-based, OBJ).
// Readers accept what the writers write (and .rawfield from Directional) and report the file and line of
// any problem. All writers are atomic (trivcon/io.h).
#pragma once
#include <ostream>
#include <string>
#include <vector>

#include "trivcon/field.h"
#include "trivcon/geometry.h"
#include "trivcon/io.h"

namespace trivcon {

// Writes by extension: .rawfield, .rosy, .ply, anything else the text format. With `face_of_row` (one entry per
// row of F), row i is the field of face face_of_row[i] of the geometry: a field solved on a repaired mesh written
// for the input's faces (RepairedMesh::face_of_input, trivcon/repair.h); a row of −1 (a degenerate input face
// with no neighbour) is the zero vector.
void write_field(const std::string& path, const MatrixX3d& V, const MatrixX3i& F, const Geometry& geometry, const Field& field,
                 const std::vector<int>& face_of_row = {});
// The same bytes written to a stream (the editor's downloads); `path` only picks the format, by its extension.
void write_field_to(std::ostream& out, const std::string& path, const MatrixX3d& V, const MatrixX3i& F, const Geometry& geometry,
                    const Field& field, const std::vector<int>& face_of_row = {});
// Reads a field written by write_field, a Directional .rawfield or a QuadWild .rosy: world directions (F × 3, the first
// direction per face) and N (0 when the file does not say). `num_faces` must match.
MatrixX3d read_field(const std::string& path, int num_faces, int* N_in_file = nullptr);

void write_connection(const std::string& path, const Topology& topology, const Eigen::VectorXd& x, int N);
// Reads (i, j) → x back; returns per-edge x (0 on boundary edges); every interior edge must be listed once.
Eigen::VectorXd read_connection(const std::string& path, const Topology& topology);

void write_matching(const std::string& path, const Topology& topology, const Eigen::VectorXi& matching, int N);
// Reads a .matching back: per-edge m in [0, N) (0 on boundary edges); every interior edge listed once, as
// "L R i j m" or with its faces swapped ("R L i j m", read as −m); the file's N must be `N`.
Eigen::VectorXi read_matching(const std::string& path, const Topology& topology, int N);

void write_field_lines(const std::string& path, const MatrixX3d& V, const MatrixX3i& F, const Geometry& geometry, const Field& field);

}  // namespace trivcon
