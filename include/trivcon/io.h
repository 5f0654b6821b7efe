// SPDX-License-Identifier: MIT
// trivcon/io.h: reading and writing triangle meshes (OBJ, OFF, PLY, and the same gzipped).
//
// Conventions
// - Vertex ids are the file's own, 0-based, in file order; no vertex is dropped, merged or renumbered
//   (unreferenced vertices are kept).
// - Faces are in file order; a polygon with k > 3 corners (a, b, c, d, ...) is fan-triangulated in
//   order into (a,b,c), (a,c,d), ...; `polygon_of_triangle` maps each triangle back to the file's
//   polygon. Polygons are counted 0-based in file order.
// - Readers only parse: they check syntax, counts, index ranges (an index outside [0, V) is an
//   error) and that every coordinate is finite. A polygon with a repeated corner is read (its
//   triangles with a repeated vertex are what repair drops, trivcon/repair.h) and the first one is
//   named in MeshData::repeated_vertex. Topology (manifoldness, orientation) is checked by
//   trivcon/topology.h.
// - Errors are trivcon::Error with the file name and the 1-based line (text formats) or byte
//   offset (binary PLY), e.g. "mesh.obj:12: face index 40 out of range (file has 39 vertices)".
// - Writers write to a temporary file beside the target and rename it into place, so a failed write
//   never leaves a half-written file. Everything written can be read back identically (binary PLY
//   stores doubles; OBJ stores coordinates with 17 significant digits).
#pragma once
#include <functional>
#include <iosfwd>
#include <string>
#include <vector>

#include "trivcon/common.h"

namespace trivcon {

// A mesh as read from a file: V (vertex positions, file order) and F (triangles, file order after fan
// triangulation) of trivcon::Mesh, plus where each triangle came from.
struct MeshData : Mesh {
  std::vector<int> polygon_of_triangle;  // file polygon of each triangle
  int polygon_count = 0;                 // polygons in the file
  std::string format;                    // "obj", "off", "ply-ascii", "ply-binary-le", "ply-binary-be", "stl-ascii",
                                         // "stl-binary", "gltf", "glb"
  // The first polygon with a repeated corner, as the error a front end that does not repair gives, with the file
  // and line (or byte): e.g. "m.obj:5: face 1 has a repeated vertex (0, 0, 1)"; "" when there is none.
  std::string repeated_vertex;
};

// Reads by extension: .obj .off .ply .stl .gltf .glb, each optionally followed by .gz (case-insensitive).
// weld_tolerance: for STL, see read_stl; another format with a tolerance other than 0 is an error.
MeshData read_mesh(const std::string& path, double weld_tolerance = 0);

// Format-specific readers on an in-memory buffer (already decompressed); `name` is used in messages.
MeshData read_obj(const std::string& buffer, const std::string& name);
MeshData read_off(const std::string& buffer, const std::string& name);
MeshData read_ply(const std::string& buffer, const std::string& name);
// STL, ASCII or binary (binary when the size matches its header's triangle count): corners welded into vertices
// by exact position, numbered in order of first appearance; format "stl-ascii" or "stl-binary". With
// weld_tolerance > 0, a corner within that distance of a vertex made before joins it (the earliest such vertex;
// a vertex keeps the position of its first corner): for exports that store shared corners slightly apart.
MeshData read_stl(const std::string& buffer, const std::string& name, double weld_tolerance = 0);
// glTF 2.0, .gltf (`name`'s folder resolves external buffers) or .glb (by its magic): every triangle primitive of
// the default scene's nodes, transforms applied, each its own block of vertices; format "gltf" or "glb".
MeshData read_gltf(const std::string& buffer, const std::string& name);

// Whole file into memory, gunzipping when the path ends in .gz. Errors name the file.
std::string read_file_bytes(const std::string& path);

void write_obj(const std::string& path, const MatrixX3d& V, const MatrixX3i& F);
void write_ply(const std::string& path, const MatrixX3d& V, const MatrixX3i& F);  // binary little-endian, double x y z, int list
// A quad mesh (a quad per row of Q, counter-clockwise): binary PLY when the path ends in .ply, else OBJ.
void write_quad_mesh(const std::string& path, const MatrixX3d& V, const Eigen::MatrixX4i& Q);
// OBJ with one texture coordinate per corner: the vertices and faces as given, then `vt u v` for corner k of
// face f at line 3f + k + 1 of the vt lines, and `f a/ta b/tb c/tc`. corner_uv: F × 6 ((u, v) of corners 0, 1, 2).
void write_uv_obj(const std::string& path, const MatrixX3d& V, const MatrixX3i& F, const Eigen::MatrixXd& corner_uv);
// The (u, v) of every corner (F × 6) from an OBJ whose faces are F's triangles, in order, with 'v/vt' corners
// (what write_uv_obj writes). Throws trivcon::Error naming the file and line of anything else.
Eigen::MatrixXd read_corner_uv(const std::string& path, const MatrixX3i& F);

// Writes via `fill` into a temporary file beside `path`, then renames it into place. If `fill`
// throws or the stream fails, the temporary is removed and `path` is untouched. All of trivcon's
// outputs go through this.
void write_file_atomically(const std::string& path, const std::function<void(std::ostream&)>& fill);

}  // namespace trivcon
