// SPDX-License-Identifier: MIT
// fuzz/fuzz_fixed.cpp: a fixed-direction file (--fix FILE: "FACE x y z" or "FACE angle=A" lines) against the
// fixed mesh (trivcon/constraints.h read_fixed_directions), then the conflicts `solve` reports for it.
#include <cmath>

#include "io/readers.h"
#include "fuzz_target.h"
#include "trivcon/constraints.h"

TRIVCON_FUZZ_TARGET(fixed) {
  const trivcon::fuzz::FixedMesh& m = trivcon::fuzz::fixed_mesh();
  std::map<int, double> fixed;
  trivcon::io::read_fixed_directions_from(bytes, "fuzz.txt", m.topology, m.geometry, fixed);
  for (const auto& [face, angle] : fixed) TRIVCON_FUZZ_CHECK(face >= 0 && face < m.topology.num_faces && std::isfinite(angle));
  trivcon::fixed_conflicts(m.topology, m.geometry, fixed, 4);
}
