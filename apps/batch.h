// SPDX-License-Identifier: MIT
// The items of `solve --sing-batch`: many singularity sets solved with one factorization.
#pragma once
#include <string>
#include <vector>

#include "trivcon/indices.h"

namespace trivcon::cli {

struct BatchItem {
  std::string name;
  IndexPrescription prescription;
  std::string source;  // where it was read: the file's name in the directory, or "line N" of the JSON-lines file
};

// --sing-batch: a directory of singularity files (sorted by name; each named by its file name without
// extension), or a JSON-lines file: one object per line, {"name": "a", "sing": {"12": "1/4", ...},
// "generator": {"0": "1"}, "boundary": {"1": "0"}} ("generator"/"boundary" optional). Each item's
// prescription starts from the command line's (-N, --generator, --boundary); its singularities replace
// those of -s/--sing. Throws trivcon::Error naming the file (and line) for anything it cannot read, and
// for two items of the same name (their outputs would overwrite each other).
std::vector<BatchItem> read_batch(const std::string& path, const IndexPrescription& base);
// The JSON-lines form on the file's text in memory; `path` names it in messages (used by read_batch and the fuzz target).
std::vector<BatchItem> read_batch_lines(const std::string& text, const std::string& path, const IndexPrescription& base);

}  // namespace trivcon::cli
