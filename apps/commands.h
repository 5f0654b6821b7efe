// SPDX-License-Identifier: MIT
// The subcommands of the `trivcon` program. Each registers itself on the CLI11 app; its callback
// throws trivcon::Error for bad input (main prints it and exits with status 1) or returns an exit code
// through `exit_code`.
#pragma once
#include <CLI/CLI.hpp>
#include <optional>
#include <string>

#include "trivcon/io.h"
#include "trivcon/repair.h"

namespace trivcon::cli {

// The program's exit statuses (docs/reference/exit-codes.md).
enum ExitStatus : int {
  kSuccess = 0,
  kBadInput = 1,            // a trivcon::Error: bad input, a file that cannot be read or written; out of memory
  kUsageError = 2,          // CLI11 rejected the command line
  kVerificationFailed = 3,  // solve: a design did not pass verification
  kIndicesDiffer = 4,       // check: the field's indices differ from the prescription
  kInternalError = 70,      // any other exception: a bug
};

extern int exit_code;  // set by a subcommand that wants a status other than 0

void register_info(CLI::App& app);
void register_solve(CLI::App& app);
void register_check(CLI::App& app);
void register_render(CLI::App& app);
void register_param(CLI::App& app);
void register_quad(CLI::App& app);
void register_edit(CLI::App& app);  // only with TRIVCON_EDITOR (CMake option)

// Reads a mesh file; messages name the file.
MeshData load_mesh(const std::string& path);

// A mesh file as a command works on it: by default repaired (trivcon/repair.h) when it needs it, so that every
// mesh users have is taken; ids the user gives and every output stay the input file's.
struct LoadedMesh {
  MeshData mesh;                       // what the command works on: the input, or its repair
  MeshData input;                      // the input as read, when repair changed it (else empty: `mesh` is the input)
  std::optional<RepairedMesh> repair;  // when repair changed the mesh
  double read_seconds = 0, repair_seconds = 0;  // repair_seconds: checking and repairing (0 with --no-repair)
  const RepairedMesh* repaired() const { return repair ? &*repair : nullptr; }
  int input_faces() const { return static_cast<int>((repair ? input : mesh).F.rows()); }  // the file's (triangulated)
};

// How a command reads its mesh: --no-repair, --weld TOL (STL).
struct MeshOptions {
  bool no_repair = false;
  double weld = 0;
};
void add_mesh_options(CLI::App* cmd, MeshOptions& options);

// Reads `path` (STL corners welded within options.weld); unless options.no_repair, repairs it when it needs it
// and warns on stderr (unless `quiet`) with repair_summary. With no_repair, a face with a repeated vertex is the
// reader's error (what the topology refuses is refused later, with its message).
LoadedMesh load_mesh(const std::string& path, const MeshOptions& options, bool quiet);

// Per-face rows of the input (a field file) as rows of the mesh worked on.
MatrixX3d rows_on_mesh(const LoadedMesh& mesh, const MatrixX3d& input_rows);

}  // namespace trivcon::cli
