// SPDX-License-Identifier: MIT
// fuzz/fuzz_sings.cpp: a singularity file in Directional's format (-s FILE.sings: "N count", then "vertex n"
// lines), read with N = 4 and checked against the fixed mesh as `solve` does.
#include "io/readers.h"
#include "fuzz_target.h"

TRIVCON_FUZZ_TARGET(sings) {
  const trivcon::fuzz::FixedMesh& m = trivcon::fuzz::fixed_mesh();
  trivcon::IndexPrescription p;
  p.N = 4;
  trivcon::io::read_singularities_from(bytes, "fuzz.sings", p);
  for (const auto& [v, n] : p.vertex) TRIVCON_FUZZ_CHECK(v >= 0);
  trivcon::validate_prescription(m.topology, static_cast<int>(m.cycles.generators.size()), p);
}
