// SPDX-License-Identifier: MIT
// trivcon/indices.h: the checks of a prescription against a mesh (the text of indices is read in
// src/io/singularity_files.cpp).
#include "trivcon/indices.h"

#include <cmath>
#include <cstdlib>
#include <string>

#include "trivcon/error.h"

namespace trivcon {

void validate_prescription(const Topology& t, int num_generators, const IndexPrescription& p) {
  if (p.N < 1) throw Error("the symmetry N must be at least 1 (got " + std::to_string(p.N) + ")");
  for (auto [v, n] : p.vertex) {
    if (v < 0 || v >= t.num_vertices)
      throw Error("singular vertex " + std::to_string(v) + " out of range (mesh has " + std::to_string(t.num_vertices) + " vertices)");
    if (t.vertex_component[v] < 0) throw Error("singular vertex " + std::to_string(v) + " is not used by any face");
    if (t.is_boundary_vertex(v))
      throw Error("singular vertex " + std::to_string(v) + " is on boundary loop " + std::to_string(t.vertex_boundary_loop[v]) +
                  ": a boundary vertex has no dual cycle (set the loop's index with --boundary instead)");
  }
  if (!p.path_guide.empty() && static_cast<int>(p.path_guide.size()) != t.num_faces)
    throw Error("the path guide has " + std::to_string(p.path_guide.size()) + " angles, the mesh " + std::to_string(t.num_faces) + " faces");
  for (size_t f = 0; f < p.path_guide.size(); ++f)
    if (!std::isfinite(p.path_guide[f])) throw Error("the path guide's angle at face " + std::to_string(f) + " is not a number");
  for (auto [g, n] : p.generator)
    if (g < 0 || g >= num_generators)
      throw Error("generator " + std::to_string(g) + " out of range (the mesh has " + std::to_string(num_generators) + " generators)");
  for (auto [l, n] : p.loop)
    if (l < 0 || l >= static_cast<int>(t.boundary_loops.size()))
      throw Error("boundary loop " + std::to_string(l) + " out of range (the mesh has " + std::to_string(t.boundary_loops.size()) +
                  " boundary loops)");
  std::vector<long long> sum(t.components.size(), 0), magnitude(t.components.size(), 0);
  std::vector<int> prescribed_loops(t.components.size(), 0);
  for (auto [v, n] : p.vertex) sum[t.vertex_component[v]] += n, magnitude[t.vertex_component[v]] += std::abs(static_cast<long long>(n));
  for (auto [l, n] : p.loop) magnitude[t.vertex_component[t.boundary_loops[l][0]]] += std::abs(static_cast<long long>(n));
  // Indices are whole numbers of 1/N in int: their sums on a component must stay far from its range.
  for (size_t c = 0; c < t.components.size(); ++c)
    if (magnitude[c] > kMaxIndexPart)
      throw Error("the indices on component " + std::to_string(c) + " are too large: their magnitudes add up to more than " +
                  std::to_string(kMaxIndexPart) + "/" + std::to_string(p.N));
  for (auto [l, n] : p.loop) {
    const int c = t.vertex_component[t.boundary_loops[l][0]];
    sum[c] += n;
    ++prescribed_loops[c];
  }
  for (size_t c = 0; c < t.components.size(); ++c) {
    const size_t loops = t.components[c].boundary_loops.size();
    if (loops > 0 && static_cast<size_t>(prescribed_loops[c]) < loops) continue;
    const long long needed = static_cast<long long>(p.N) * t.components[c].euler_characteristic;
    if (sum[c] != needed)
      throw Error("the indices on component " + std::to_string(c) + (loops ? " (vertices and boundary loops)" : "") + " sum to " +
                  format_index(static_cast<int>(sum[c]), p.N) + ", but Gauss-Bonnet needs its Euler characteristic " +
                  std::to_string(t.components[c].euler_characteristic));
  }
}

}  // namespace trivcon
