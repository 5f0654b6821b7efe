// The subcommands of the `trivcon` program. Each registers itself on the CLI11 app; its callback
// throws trivcon::Error for bad input (main prints it and exits with status 1) or returns an exit code
// through `exit_code`.
#pragma once
#include <CLI/CLI.hpp>
#include <string>

#include "trivcon/io.h"

namespace trivcon::cli {

extern int exit_code;  // set by a subcommand that wants a status other than 0

void register_info(CLI::App& app);
void register_solve(CLI::App& app);  // also `check`
void register_render(CLI::App& app);

// Reads a mesh file; messages name the file.
MeshData load_mesh(const std::string& path);

}  // namespace trivcon::cli
