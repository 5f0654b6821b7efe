// SPDX-License-Identifier: MIT
// fuzz/fuzz_batch.cpp: the JSON-lines file of `solve --sing-batch` (apps/batch.h read_batch_lines), each
// item's prescription then checked against the fixed mesh as `solve` does.
#include <set>

#include "batch.h"
#include "fuzz_target.h"

TRIVCON_FUZZ_TARGET(batch) {
  const trivcon::fuzz::FixedMesh& m = trivcon::fuzz::fixed_mesh();
  trivcon::IndexPrescription base;
  base.N = 4;
  const std::vector<trivcon::cli::BatchItem> items = trivcon::cli::read_batch_lines(bytes, "fuzz.jsonl", base);
  std::set<std::string> names;
  for (const trivcon::cli::BatchItem& item : items) {
    TRIVCON_FUZZ_CHECK(!item.name.empty() && names.insert(item.name).second);
    trivcon::validate_prescription(m.topology, static_cast<int>(m.cycles.generators.size()), item.prescription);
  }
}
