// SPDX-License-Identifier: MIT
// fuzz/fuzz_sing.cpp: a plain singularity file (-s FILE: "VERTEX INDEX" lines), read with N = 4 and checked
// against the fixed mesh as `solve` does (trivcon/indices.h read_singularities, validate_prescription).
#include "io/readers.h"
#include "fuzz_target.h"

TRIVCON_FUZZ_TARGET(sing) {
  const trivcon::fuzz::FixedMesh& m = trivcon::fuzz::fixed_mesh();
  trivcon::IndexPrescription p;
  p.N = 4;
  trivcon::io::read_singularities_from(bytes, "fuzz.sing", p);
  for (const auto& [v, n] : p.vertex) TRIVCON_FUZZ_CHECK(v >= 0);
  trivcon::validate_prescription(m.topology, static_cast<int>(m.cycles.generators.size()), p);
}
