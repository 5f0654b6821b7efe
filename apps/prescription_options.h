// SPDX-License-Identifier: MIT
// The options that describe a prescription (-N, -s, --sing, --generator, --boundary), shared by `solve`, `edit`
// and `check`.
#pragma once
#include <CLI/CLI.hpp>
#include <map>
#include <string>
#include <vector>

#include "trivcon/constraints.h"
#include "trivcon/common.h"
#include "trivcon/geometry.h"
#include "trivcon/indices.h"
#include "trivcon/topology.h"

namespace trivcon::cli {

struct PrescriptionOptions {
  int N = 1;
  std::vector<std::string> sing_files, sings, generators, loops;
  CLI::Option* N_option = nullptr;
  CLI::Option* files_option = nullptr;  // -s
  CLI::Option* sing_option = nullptr;   // --sing
  bool N_given() const { return N_option && N_option->count() > 0; }
  bool empty() const { return sing_files.empty() && sings.empty() && generators.empty() && loops.empty(); }
  // Adds the options to `cmd`; --generator and --boundary only `with_cycles`.
  void add_to(CLI::App* cmd, bool with_cycles);
  // The prescription the options give (files read, specs parsed; throws trivcon::Error).
  IndexPrescription build() const;
  // A per-face field file (trivcon/field_io.h read_field): its directions; `N` becomes the file's N when
  // the file states one, which must agree with -N when that was given (trivcon::Error otherwise).
  MatrixX3d read_field_file(const std::string& path, int num_faces, int& N) const;
};

// The --fix arguments of `solve` and `edit`: "F:x,y,z" / "F:angle=A" specs and files of such lines, added to
// `fixed` (face → angle in its frame; trivcon/constraints.h; throws trivcon::Error naming the argument).
// Face ids are the input's: `face_id` maps them onto a repaired mesh (trivcon/constraints.h).
void add_fix_options(const std::vector<std::string>& fixes, const Topology& topology, const Geometry& geometry,
                     std::map<int, double>& fixed, const FaceIdMap& face_id = nullptr);

}  // namespace trivcon::cli
