// SPDX-License-Identifier: MIT
// Shared helpers for the test programs.
#pragma once
#include <gtest/gtest.h>

#include <array>
#include <functional>
#include <map>
#include <string>
#include <vector>

#include "trivcon/design.h"
#include "trivcon/generate.h"

namespace trivcon::test {

// Absolute path of ../shared/data/meshes/NAME, or "" when the shared folder is absent.
std::string shared_mesh(const std::string& name);
// GTEST_SKIP()s the calling test with a message when the shared meshes are absent.
#define TRIVCON_REQUIRE_SHARED()                          \
  if (::trivcon::test::shared_mesh("SOURCES.md").empty()) \
  GTEST_SKIP() << "../shared/data/meshes not found next to the repository: skipping real-mesh test"

// A fresh directory for this test's files (under the build tree).
std::string temp_dir(const std::string& name);
// A path ending in `name` in a fresh directory of its own, named after the running test (ctest runs the
// tests of one program in parallel processes, so fixed directory names would collide).
std::string temp_file(const std::string& name);
// A Möbius strip of `n` quads (2n triangles, 2n vertices): rails top_i = 2i, bottom_i = 2i + 1; the
// last quad joins (top, bottom) of step n − 1 to (bottom, top) of step 0.
Mesh mobius_strip(int n);

// For the command-line tests: a shell-quoted argument ('…'), string tests, the lines of a text, and a
// mesh written into `dir` as OBJ (or binary PLY when `ply`), returning its path.
std::string q(const std::string& s);
// A GoogleTest parameter name for a file name: letters and digits kept, everything else '_'.
std::string test_name_of(const std::string& file);
bool starts_with(const std::string& s, const std::string& prefix);
bool contains(const std::string& s, const std::string& part);
std::vector<std::string> lines_of(const std::string& text);
std::string save(const std::string& dir, const std::string& name, const Mesh& m, bool ply = false);
// A singularity file (`--sing-out`'s) as vertex -> index text ("1/4"), comments left out.
std::map<int, std::string> read_singularity_texts(const std::string& path);
// The bytes of a file ("" when it cannot be read), and a file written with exactly `text`.
std::string slurp(const std::string& path);
void write_text(const std::string& path, const std::string& text);

// The message of the trivcon::Error thrown by `f`, or a marker when it throws nothing / something else.
std::string error_of(const std::function<void()>& f);

// Topology of a mesh (all its vertices counted).
Topology topo(const Mesh& m);
// Faces from a list of corner triples.
MatrixX3i faces(const std::vector<std::array<int, 3>>& list);
// The vertices at exactly `distance` edges from v, increasing.
std::vector<int> vertex_ring(const Topology& t, int v, int distance);
// Vertices of a given valence (e.g. the 8 corners of a cube sphere, the 12 of an icosphere).
std::vector<int> vertices_of_valence(const Mesh& m, int valence);
// make_disk(rings, segments) with every interior vertex moved in the plane by up to `amount` × the ring
// spacing in a pseudo-random direction (deterministic): no symmetry left, so a zero of order k of a field
// splits into k simple ones as on a generic mesh (on the symmetric disk, zeros sit on the symmetry).
Mesh jittered_disk(int rings, int segments, double amount);
// The cube [-1, 1]³ (each side n × n squares, each square 4 triangles around its centre) sheared along x by
// 2.5 y: its sides z = ±1 are parallelograms with corners of atan(1 / 2.5) ≈ 21.8° and 158.2° where the
// sharp edges meet (narrow corners, trivcon/features.h), each corner of a side shared by two triangles.
Mesh sheared_box(int n);
// A flat plate of nx × ny unit cells, each with a round hole of radius r at its centre: per cell, `layers` rings of
// quads (each cut into two triangles) from the hole's circle, sampled at the angles of 4m points evenly spaced
// along the cell's square, out to that square; the cells share their squares' points.
Mesh perforated_plate(int nx, int ny, int m, int layers, double r);
// The same plate meshed as a general-purpose mesher would: a triangle lattice of spacing about h (rows of
// equilateral triangles, so no edge follows the holes' rings), the triangles with a corner closer than r + 0.3 h to a
// hole's centre removed, the hole's rim vertices then put on its circle and the vertices within 3 h of the rim
// smoothed (15 rounds of neighbour means, in vertex order).
Mesh lattice_plate(int nx, int ny, double r, double h);
// The first boundary vertex whose fan has `faces` faces (−1 if none): on a lattice plate's straight side, 3.
int boundary_vertex_with_fan(const Topology& topology, size_t faces);
// A flat mesh in the plane z = 0 (faces counter-clockwise seen from +z) made a closed solid of thickness `height`:
// its faces, their copy at z = −height turned over, and two triangles per boundary edge for the wall between.
Mesh extruded(const Mesh& flat, double height);
// The unit sphere as modelling tools export it: a grid of (rings + 1) × (segments + 1) points by latitude and
// longitude, unwelded, two triangles per cell. Each pole is a row of `segments` + 1 points at one place (exactly),
// joined by edges of length 0, and the seam two coincident columns: a disk whose one boundary loop runs along both
// sides of the seam and through both poles; the triangle of each cell beside a pole has an edge of length 0.
Mesh unwelded_sphere(int rings, int segments);
// Solver options that send more than 256 fixed-face paths down the sparse route (SolverOptions::max_dense_paths),
// for the tests of that route on meshes of a few hundred paths.
SolverOptions sparse_path_options();
// A cross field with the boundary aligned (every face with a boundary edge fixed to it), its fixed faces set on
// the designer; no singularities yet.
IndexPrescription aligned_cross_field(FieldDesigner& designer, const Mesh& m);

// Checks every structural invariant of a Topology against F (the input) alone. Cheap: O(F log F).
void expect_consistent(const Topology& t, const MatrixX3i& F_in, int nv, const std::string& what);
// Geometry checks: no NaN/inf anywhere, corner angles sum to π per face, Gauss–Bonnet per component.
void expect_geometry_sane(const MatrixX3d& V, const Topology& t, const std::string& what, double gb_tol = 1e-9);

struct CommandResult {
  int status = 0;  // exit status
  std::string out, err;
};
// Runs the trivcon program with the arguments (a shell-quoted string), capturing stdout and stderr.
CommandResult run_cli(const std::string& args);

// Optimality of a connection: x is W-orthogonal to every exact dual 1-form (vanishing on the fixed-face
// paths), i.e. at every face whose edges are all interior with w > 0 and that is not in `skip` (the fixed
// faces), Σ σ_fe x_e / w_e = 0 (σ = +1 where f is the edge's L face, −1 where it is R). Returns the
// largest such sum relative to max |x_e / w_e|.
double max_face_optimality(const FieldDesigner& designer, const Connection& connection, const std::map<int, double>& skip = {});

// Renumbering (generate.h permute(): vertex_perm[old] = new, face_perm[old] = new):
// - per-edge values x of the renumbered mesh, on the original's edges: edges matched by their vertex pair,
//   the sign flipped where the renumbering reverses the edge's i < j order (x is oriented from L, the face
//   holding i → j, to R; trivcon/geometry.h, solver.h);
Eigen::VectorXd edge_values_on_original(const Topology& original, const Topology& renumbered, const Eigen::VectorXd& x,
                                        const std::vector<int>& vertex_perm);
// - the largest angle, modulo 2π/N, between the world directions of a field on the original mesh and one on
//   the renumbered mesh (the faces' frames differ: permute rotates corners).
double max_field_difference(const Geometry& original, const Field& a, const Geometry& renumbered, const Field& b,
                            const std::vector<int>& face_perm);

}  // namespace trivcon::test
