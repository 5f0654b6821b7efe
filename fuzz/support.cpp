// SPDX-License-Identifier: MIT
// fuzz/support.cpp: the shared parts of the fuzz targets; see fuzz/fuzz_target.h.
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <stdexcept>

#include "fuzz_target.h"
#include "trivcon/error.h"
#include "trivcon/generate.h"
#include "trivcon/repair.h"
#include "trivcon/topology.h"

namespace trivcon::fuzz {

std::map<std::string, Target>& targets() {
  static std::map<std::string, Target> all;
  return all;
}

bool register_target(const char* name, Target target) {
  targets()[name] = target;
  return true;
}

void invariant_failed(const char* condition, const char* file, int line) {
  const std::string message = std::string(file) + ":" + std::to_string(line) + ": invariant broken: " + condition;
#ifdef TRIVCON_LIBFUZZER
  std::fprintf(stderr, "%s\n", message.c_str());
  std::abort();
#else
  throw std::logic_error(message);
#endif
}

const FixedMesh& fixed_mesh() {
  static const FixedMesh fixed = [] {
    FixedMesh m;
    m.mesh = concatenate({make_torus(4, 3), make_annulus(1, 4)});
    m.topology = build_topology(m.mesh.F, static_cast<int>(m.mesh.V.rows()));
    m.geometry = compute_geometry(m.mesh.V, m.topology, 1);
    m.cycles = compute_cycles(m.topology);
    return m;
  }();
  return fixed;
}

void check_mesh(const MeshData& mesh) {
  TRIVCON_FUZZ_CHECK(mesh.V.cols() == 3 && mesh.F.cols() == 3);
  TRIVCON_FUZZ_CHECK(mesh.F.rows() > 0 && mesh.polygon_count > 0);
  TRIVCON_FUZZ_CHECK(static_cast<Eigen::Index>(mesh.polygon_of_triangle.size()) == mesh.F.rows());
  TRIVCON_FUZZ_CHECK(!mesh.format.empty());
  TRIVCON_FUZZ_CHECK(mesh.V.allFinite());
  int previous = 0;  // polygons are fan-triangulated in order, each into at least one triangle
  for (Eigen::Index t = 0; t < mesh.F.rows(); ++t) {
    const int polygon = mesh.polygon_of_triangle[static_cast<std::size_t>(t)];
    TRIVCON_FUZZ_CHECK(polygon == previous || (t > 0 && polygon == previous + 1));
    previous = polygon;
    for (int k = 0; k < 3; ++k) TRIVCON_FUZZ_CHECK(mesh.F(t, k) >= 0 && mesh.F(t, k) < mesh.V.rows());
    // A face with a repeated vertex is read, and the first is named.
    if (mesh.F(t, 0) == mesh.F(t, 1) || mesh.F(t, 1) == mesh.F(t, 2) || mesh.F(t, 0) == mesh.F(t, 2))
      TRIVCON_FUZZ_CHECK(!mesh.repeated_vertex.empty());
  }
  TRIVCON_FUZZ_CHECK(previous == mesh.polygon_count - 1);
  // Repair takes whatever was read: a manifold mesh with maps back, or a trivcon::Error.
  try {
    const RepairedMesh r = repair_mesh(mesh.V, mesh.F);
    TRIVCON_FUZZ_CHECK(static_cast<Eigen::Index>(r.input_face.size()) == r.F.rows());
    TRIVCON_FUZZ_CHECK(static_cast<Eigen::Index>(r.face_of_input.size()) == mesh.F.rows());
    TRIVCON_FUZZ_CHECK(static_cast<Eigen::Index>(r.vertex_origin.size()) == r.V.rows());
    build_topology(r.F, static_cast<int>(r.V.rows()));  // may refuse only what repair leaves: non-orientable
  } catch (const Error&) {
  }
}

}  // namespace trivcon::fuzz
