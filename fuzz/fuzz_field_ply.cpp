// SPDX-License-Identifier: MIT
// fuzz/fuzz_field_ply.cpp: a field file (.ply) against the fixed mesh, then what `check` does with it: the
// field's angles and its indices (trivcon/field_io.h read_field, trivcon/field.h).
#include "io/readers.h"
#include "fuzz_target.h"
#include "trivcon/field.h"

TRIVCON_FUZZ_TARGET(field_ply) {
  const trivcon::fuzz::FixedMesh& m = trivcon::fuzz::fixed_mesh();
  int N = 0;
  const trivcon::MatrixX3d directions = trivcon::io::read_field_from(bytes, "fuzz.ply", m.topology.num_faces, &N);
  TRIVCON_FUZZ_CHECK(directions.rows() == m.topology.num_faces && directions.allFinite());
  TRIVCON_FUZZ_CHECK(N >= 0 && N <= 1000);
  const trivcon::Field field = trivcon::field_from_directions(m.geometry, directions, N > 0 ? N : 4);
  trivcon::field_indices(m.topology, m.geometry, m.cycles, field);
}
