// SPDX-License-Identifier: MIT
// A user's program on the installed library's public API (trivcon/design.h on plain (V, F) arrays):
// a cross field on a cube-like sphere with +1/4 at the eight cube corners (its only vertices of valence
// 3), then an edit that moves two of them. Exits 0 only if both solves are exact and the indices read back
// from the fields are the prescribed ones.
#include <trivcon/design.h>
#include <trivcon/generate.h>

#include <algorithm>
#include <cstdio>
#include <vector>

namespace {

bool exact(const trivcon::Design& d, const trivcon::IndexPrescription& p) {
  const double residual = std::max(d.connection.max_vertex_residual, d.connection.max_cycle_residual);
  if (!(residual <= 1e-9 * std::max(1.0, d.connection.rhs_scale))) return false;
  for (int v = 0; v < static_cast<int>(d.indices.vertex.size()); ++v) {
    const auto it = p.vertex.find(v);
    if (d.indices.vertex[v] != (it == p.vertex.end() ? 0 : it->second)) return false;
  }
  return true;
}

}  // namespace

int main() {
  const trivcon::Mesh mesh = trivcon::make_cube_sphere(8, true);
  std::vector<int> valence(mesh.V.rows(), 0);
  for (int f = 0; f < mesh.F.rows(); ++f)
    for (int k = 0; k < 3; ++k) ++valence[mesh.F(f, k)];
  std::vector<int> corners;
  for (int v = 0; v < static_cast<int>(valence.size()); ++v)
    if (valence[v] == 3) corners.push_back(v);
  if (corners.size() != 8) return 1;

  trivcon::FieldDesigner designer(mesh.V, mesh.F);
  trivcon::IndexPrescription cube;
  cube.N = 4;
  for (int v : corners) cube.vertex[v] = 1;
  const trivcon::Design first = designer.design(cube);
  trivcon::IndexPrescription moved = cube;
  moved.vertex.erase(corners[0]), moved.vertex.erase(corners[1]);
  moved.vertex[corners[0] + 1] = 1, moved.vertex[corners[1] + 1] = 1;
  const trivcon::Design second = designer.design(moved);
  std::printf("energy %.6f then %.6f, residuals %.3g and %.3g\n", first.connection.energy, second.connection.energy,
              first.connection.max_vertex_residual, second.connection.max_vertex_residual);
  return exact(first, cube) && exact(second, moved) && second.connection.energy > first.connection.energy ? 0 : 1;
}
