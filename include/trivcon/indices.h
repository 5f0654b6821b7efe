// SPDX-License-Identifier: MIT
// trivcon/indices.h: what the user prescribes — singular vertices, and the turning of the field around
// generators and boundary loops — and how it is read and checked.
//
// Indices are exact multiples of 1/N and are stored as integers n meaning n/N (N = 1 vectors, 2 lines,
// 4 crosses, any N ≥ 1). The index of a vertex is the number of turns the field makes, relative to
// parallel transport, along the vertex's counter-clockwise dual cycle (paper Section 2.3): +1 a source
// or a sink on a sphere, −1 a saddle; a cross field on a cube has +1/4 at the 8 corners.
// Generator and boundary-loop indices are measured the same way along their dual cycles (trivcon/cycles.h):
// the connection's holonomy there is 2π · index; a generator's index counts the field's turns relative to
// Levi-Civita transport with each edge's rotation ρ_e taken in (−π, π] (so it depends on the cycle,
// which `trivcon info --cycles` lists). A boundary loop's index is that of the virtual vertex capping
// the hole: a flat disk with a constant field has loop index +1; a flat annulus with a constant field has +1 on
// its outer loop and −1 on its inner loop.
// Gauss–Bonnet: on every component the vertex indices plus the loop indices sum to χ.
#pragma once
#include <map>
#include <ostream>
#include <string>
#include <vector>

#include "trivcon/topology.h"

namespace trivcon {

// |p| and q of an index p/q, |n| = |index · N| of any index and the sum of the magnitudes on a component,
// and N of a .sings file, are at most this: sums of indices stay far from int's range.
constexpr long long kMaxIndexPart = 1000000000;

struct IndexPrescription {
  int N = 1;
  std::map<int, int> vertex;     // vertex id → n (index n/N); absent: 0
  std::map<int, int> generator;  // generator id → n; absent: chosen to make the field smoothest
  std::map<int, int> loop;       // boundary loop id → n; absent: chosen to make the field smoothest
  std::map<int, double> fixed;   // face → direction (angle in the face's frame) the field must have there,
                                 // modulo 2π/N (trivcon/constraints.h)
  // Optional: an N-field's angle per face (e.g. the smoothest field --auto reads its singularities from,
  // AutoResult::field) whose turn along each fixed-face path chooses the path's whole number of turns where
  // the solver does not choose them with the cycles (SolverOptions::max_dense_paths); empty: each path's
  // smallest turn. It changes which exact field is made, never its singularities.
  std::vector<double> path_guide;
};

// Parses an index "3", "-1", "1/4", "-3/2" into units of 1/N; throws naming `where` when it is not
// a multiple of 1/N or not a number.
int parse_index(const std::string& text, int N, const std::string& where);

// Adds the singularities of a file: one "VERTEX INDEX" per line, '#' comments, blank lines; or, for a
// file ending in .sings, Directional's format (first line "N count", then "vertex n" lines meaning n/N;
// its N must divide into ours: an index n/N_file must be a multiple of 1/N). A vertex listed twice is an error.
void read_singularities(const std::string& path, IndexPrescription& prescription);
// Adds "V:INDEX" (from --sing), "G:INDEX" (--generator) or "L:INDEX" (--boundary).
void add_vertex_index(const std::string& spec, IndexPrescription& prescription);
void add_generator_index(const std::string& spec, IndexPrescription& prescription);
void add_loop_index(const std::string& spec, IndexPrescription& prescription);

// An index n/N as a reduced fraction ("1/4", "-1/2") or an integer ("1", "0").
std::string format_index(int n, int N);
// Writes singularities (vertex → n) in the plain format above, atomically (trivcon/io.h): a '#' header
// comment ("# trivcon singularities", "# N <N>", "# <count> singular vertices"), then one
// "VERTEX INDEX" line per vertex in increasing id, INDEX from format_index. read_singularities reads it back.
void write_singularities(const std::string& path, const std::map<int, int>& vertex, int N);
// The same text written to a stream (the editor's download).
void write_singularities_to(std::ostream& out, const std::map<int, int>& vertex, int N);

// Checks the prescription against the mesh: vertex out of range, unreferenced or on the boundary;
// generator or loop id out of range; on each closed component, vertex indices summing to χ; on a
// component whose loops all have prescribed indices, vertex and loop indices summing to χ.
void validate_prescription(const Topology& topology, int num_generators, const IndexPrescription& prescription);

}  // namespace trivcon
