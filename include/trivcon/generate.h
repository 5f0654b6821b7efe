// SPDX-License-Identifier: MIT
// trivcon/generate.h: meshes built in code, for tests that must run anywhere and for benchmarks.
//
// Every generator returns a consistently oriented manifold triangle mesh (outward normals for
// closed surfaces, counter-clockwise seen from +z for flat ones) without unreferenced vertices,
// coincident vertices or zero-area faces, deterministic for given parameters. All run in time linear
// in the output size.
//
// Invalid parameters throw trivcon::Error naming the function, the parameter and its value, e.g.
// "make_uv_sphere: invalid rings = 1 (need rings >= 2)"; parameters that would give more than
// about 5·10^8 vertices or faces throw as well.
#pragma once
#include <utility>
#include <vector>

#include "trivcon/common.h"

namespace trivcon {

// Mesh (V, F) is declared in trivcon/common.h.

// Unit sphere: icosahedron subdivided `level` ≥ 0 times (1→4), projected; 10·4^level + 2 vertices,
// 20·4^level faces. The vertices of level l are the first vertices of level l + 1, unchanged.
Mesh make_icosphere(int level);
// Unit sphere as a latitude/longitude grid with poles: `rings` ≥ 2 rings, `segments` ≥ 3;
// vertex 0 is the north pole (0, 0, 1), then rings − 1 latitude rows of `segments` vertices from
// north to south, then the south pole; 2 + segments·(rings−1) vertices, 2·segments·(rings−1) faces.
Mesh make_uv_sphere(int rings, int segments);
// Cube [-1,1]^3 with each face an n×n grid (n ≥ 1), projected to the unit sphere when `spherical`
// (a "cube-like" sphere); 6n² + 2 vertices, 12n² faces. Each grid cell is split along the diagonal
// perpendicular to the direction from its face's centre, so for n ≥ 2 the 8 cube corners are the
// only vertices of valence 3 (and for even n the mesh has the cube's full symmetry).
Mesh make_cube_sphere(int n, bool spherical);
// Torus around the z axis with major radius R, minor radius r (0 < r < R), nu ≥ 3 steps around
// the axis and nv ≥ 3 around the tube, nu × nv quads split into triangles (genus 1, χ = 0);
// nu·nv vertices, 2·nu·nv faces.
Mesh make_torus(int nu, int nv, double R = 1.0, double r = 0.4);
// Closed surface of genus g ≥ 0 (χ = 2 − 2g): the boundary of a plate of (4g+2) × 6 × 2 cubic voxels
// of edge 1/3, centred at the origin, with g holes of 2 × 2 voxels through it in a row along x (holes
// and the bars between and around them are 2 voxels wide, so it is manifold). Every voxel face is
// a `resolution`×`resolution` (≥ 1) grid of quads split into triangles: 2·resolution²·(72g + 56)
// faces, 2 − 2g + resolution²·(72g + 56) vertices; encloses 2·(20g + 12) voxels, volume
// 2·(20g + 12)/27. Not smoothed: faces are flat, edges and corners sharp (all triangles are right
// isosceles).
Mesh make_genus_surface(int g, int resolution);
// Flat unit disk in the z = 0 plane: a centre vertex and `rings` ≥ 1 rings, ring k (1..rings) with
// k·segments vertices on radius k/rings (`segments` ≥ 3), so triangles keep their shape;
// 1 + segments·rings·(rings+1)/2 vertices, segments·rings² faces; χ = 1, one boundary loop.
Mesh make_disk(int rings, int segments);
// Closed cylinder around the z axis, radius 1, z in [−height/2, height/2] (height > 0): two flat caps, each
// make_disk(rings, segments) (the bottom one turned to face −z), and a side of `stacks` ≥ 1 rows of
// quads split into triangles between the two rims of rings·segments vertices each. Vertex ids: the bottom
// cap's (as make_disk's, at z = −height/2), the top cap's, then stacks − 1 side rows bottom to top; faces:
// bottom cap, top cap, side. The two rims are sharp edges of dihedral angle 90° (a CAD-like test shape,
// trivcon/features.h); χ = 2.
Mesh make_capped_cylinder(int rings, int segments, int stacks, double height = 2.0);
// Flat annulus with radii 0 < r_in < r_out: rings + 1 circles of `segments` ≥ 3 vertices
// (`rings` ≥ 1), (rings+1)·segments vertices, 2·rings·segments faces; χ = 0, two boundary loops.
Mesh make_annulus(int rings, int segments, double r_in = 0.5, double r_out = 1.0);
// Flat n×n square grid of the unit square [0,1]² with `holes` ≥ 0 square holes cut out, laid out in a
// row along x: each hole is w×w cells, w = ⌊n/(2·holes+1)⌋, and holes are at least one cell apart
// from each other and from the outer boundary, which needs n ≥ 2·holes + 1. Vertices inside holes
// are dropped and the rest renumbered compactly: (n+1)² − holes·(w−1)² vertices,
// 2·(n² − holes·w²) faces; χ = 1 − holes, one outer boundary loop plus one loop per hole.
Mesh make_holed_grid(int n, int holes);
// Disjoint union, vertices and faces in argument order (ids of later meshes shifted).
Mesh concatenate(const std::vector<Mesh>& parts);
// Midpoint subdivision (every triangle into four), shared edge midpoints created once; vertex ids of the
// input kept as the first V ids, then one new vertex per undirected edge {i, j} (i < j), in
// increasing order of (i, j). Face f = (a, b, c) becomes faces 4f..4f+3 =
// (a, ab, ca), (ab, b, bc), (ca, bc, c), (ab, bc, ca), so orientation is kept. Positions are not
// smoothed. Works for any triangle mesh (face indices must be in [0, V)); O(V + F).
Mesh subdivide_midpoint(const Mesh& mesh);
// Sliver, needle and coincident-vertex variants of a clean mesh (the surface kept, more triangles): the
// edges of a greedy set in which no two share a face (taken in increasing order of (i, j), i < j, which
// picks about 30 % of a closed mesh's edges) are each split at m = p_i + t·(p_j − p_i), 0 ≤ t < 1, moved by
// lift·|p_j − p_i| along the mean unit normal of the edge's faces (lift = 0 keeps the surface exactly).
// t = 0 and lift = 0 makes m coincide with p_i (zero-area faces); a small t makes triangles with an angle
// of about t (slivers), and lift ≈ t makes needles. Input vertex ids are kept; the new vertex of the k-th
// split edge is V + k. A face (a, b, c) whose half-edge a → b is split becomes (a, m, c), keeping its
// index, and (m, b, c), appended; `parent_face[f]` (when not null) is the input face each output face
// lies in. Throws like the generators above for t outside [0, 1) or invalid faces.
Mesh split_edges_near_end(const Mesh& mesh, double t, double lift = 0, std::vector<int>* parent_face = nullptr);
// Splits each given face (a, b, c) at its centroid g into (a, b, g), keeping its index, and (b, c, g),
// (c, a, g), appended in that order, face after face in increasing id (duplicates ignored); the centroid
// of the k-th face is vertex V + k. The surface is kept exactly, orientation too, and every corner of a
// split face gains an edge (solve --split-large-turns: the turning around a vertex is spread over more
// edges). `parent_face` as above. Throws naming a face id out of range.
Mesh split_faces_at_centroids(const Mesh& mesh, const std::vector<int>& faces, std::vector<int>* parent_face = nullptr);
// Splits each listed edge (a vertex pair, either order; duplicates ignored) at its midpoint: the midpoint of the
// k-th edge in increasing (min, max) order is vertex V + k. A face with s ≥ 1 split edges becomes 1 + s faces,
// the first keeping its index, the others appended face after face in increasing id: one split edge a → b
// (rotated so) gives (a, m, c), (m, b, c); two, on a → b and b → c, give (m_ab, b, m_bc) and the rest cut
// along its shorter diagonal; three give the corners' triangles and the middle one. The surface and orientation
// are kept exactly; faces without a listed edge are unchanged. `parent_face` as above. Throws for a pair that is
// not an edge of a face, or a vertex id out of range. (trivcon param and quad, where a map folds beside an edge
// whose two ends lie on aligned lines, as across a flat CAD face triangulated without inner vertices.)
Mesh split_edges_at_midpoints(const Mesh& mesh, const std::vector<std::pair<int, int>>& edges, std::vector<int>* parent_face = nullptr);
// Random permutation of vertex ids and of face order (faces keep their orientation, corners
// rotate cyclically by a random amount); deterministic for a seed on every platform (draws come
// straight from std::mt19937). `vertex_perm[old] = new`, `face_perm[old] = new` when not null.
Mesh permute(const Mesh& mesh, unsigned seed, std::vector<int>* vertex_perm = nullptr, std::vector<int>* face_perm = nullptr);

}  // namespace trivcon
