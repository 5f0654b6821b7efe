// The subcommands of the `trivcon` program. Each registers itself on the CLI11 app; its callback
// throws trivcon::Error for bad input (main prints it and exits with status 1) or returns an exit code
// through `exit_code`.
#pragma once
#include <CLI/CLI.hpp>
#include <string>

#include "trivcon/io.h"

namespace trivcon::cli {

// The program's exit statuses (README.md, "Exit status").
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
void register_edit(CLI::App& app);  // only with TRIVCON_EDITOR (CMake option)

// Reads a mesh file; messages name the file.
MeshData load_mesh(const std::string& path);

}  // namespace trivcon::cli
