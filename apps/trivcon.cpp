// SPDX-License-Identifier: MIT
// trivcon: command-line front end. Subcommands live in apps/cmd_*.cpp; all the work is in the library.
#include <chrono>
#include <cstdio>
#include <exception>
#include <iomanip>
#include <iostream>
#include <sstream>
#include <utility>

#include "commands.h"
#include "trivcon/blas.h"
#include "trivcon/tuned_process.h"
#include "trivcon/error.h"

namespace trivcon::cli {
int exit_code = 0;
MeshData load_mesh(const std::string& path) { return read_mesh(path); }

LoadedMesh load_mesh(const std::string& path, const MeshOptions& options, bool quiet) {
  LoadedMesh out;
  const auto t0 = std::chrono::steady_clock::now();
  out.mesh = read_mesh(path, options.weld);
  const auto t1 = std::chrono::steady_clock::now();
  out.read_seconds = std::chrono::duration<double>(t1 - t0).count();
  if (options.no_repair) {
    if (!out.mesh.repeated_vertex.empty()) throw Error(out.mesh.repeated_vertex);
    return out;
  }
  RepairedMesh r = repair_mesh(out.mesh.V, out.mesh.F);
  out.repair_seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - t1).count();
  if (!r.changed()) return out;
  out.input = std::move(out.mesh);
  out.mesh.V = r.V, out.mesh.F = r.F;
  out.mesh.format = out.input.format;
  out.mesh.polygon_count = out.input.polygon_count;
  out.mesh.polygon_of_triangle.resize(r.input_face.size());
  for (size_t q = 0; q < r.input_face.size(); ++q)
    out.mesh.polygon_of_triangle[q] = out.input.polygon_of_triangle.empty() ? r.input_face[q] : out.input.polygon_of_triangle[r.input_face[q]];
  if (!quiet) std::cerr << "trivcon: warning: " << path << " " << repair_summary(r) << " (--no-repair refuses it instead)\n";
  out.repair = std::move(r);
  return out;
}

void add_mesh_options(CLI::App* cmd, MeshOptions& options) {
  cmd->add_option("--weld", options.weld,
                  "STL: join corners closer than this distance (in the mesh's units) into one vertex; default 0, exact position")
      ->check(CLI::NonNegativeNumber);
  cmd->add_flag("--no-repair", options.no_repair,
                "Refuse a mesh that is not manifold (faces with a repeated vertex, duplicate faces, edges with more than two faces, "
                "vertices where sheets touch) instead of repairing it");
}

MatrixX3d rows_on_mesh(const LoadedMesh& m, const MatrixX3d& input_rows) {
  return m.repair ? rows_on_repaired(*m.repair, input_rows) : input_rows;
}
// The end of `trivcon --help`: the exit statuses (ExitStatus in commands.h), laid out as CLI11 lays out options
// (descriptions from column 30), so that scripts/cli_help.py reads them into the man page's EXIT STATUS.
std::string exit_status_help() {
  const std::pair<int, const char*> statuses[] = {
      {kSuccess, "Success (also --help and --version)"},
      {kBadInput, "Bad input (the message on stderr names the problem and where: file and line, vertex, edge or face), "
                  "a file that cannot be read or written, or out of memory"},
      {kUsageError, "Usage error: an unknown subcommand or option, a bad or missing value, a missing or extra argument"},
      {kVerificationFailed, "solve, param, quad: the result failed verification (the message says which check missed "
                            "and by how much; the outputs are still written, but no quad mesh without quads)"},
      {kIndicesDiffer, "check: the field's indices differ from the prescription"},
      {kInternalError, "Internal error (a bug: the message starts with 'trivcon: internal error:')"},
  };
  std::ostringstream out;
  out << "Exit status:\n";
  for (const auto& [code, text] : statuses) out << "  " << std::left << std::setw(28) << code << text << "\n";
  return out.str();
}
}  // namespace trivcon::cli

int main(int argc, char** argv) {
  trivcon::use_tuned_process(argv);  // BLAS kernels and huge pages: see trivcon/tuned_process.h
  CLI::App app{"trivcon: direction fields with exactly the singularities you ask for (trivial connections, Crane et al. 2010)"};
  app.set_version_flag("--version", std::string("trivcon ") + TRIVCON_VERSION);
  app.require_subcommand(1);
  trivcon::cli::register_info(app);
  trivcon::cli::register_solve(app);
  trivcon::cli::register_param(app);
  trivcon::cli::register_quad(app);
  trivcon::cli::register_check(app);
  trivcon::cli::register_render(app);
#ifdef TRIVCON_EDITOR
  trivcon::cli::register_edit(app);
#endif
  app.footer(trivcon::cli::exit_status_help());  // after the subcommands, which would otherwise inherit it
  try {
    app.parse(argc, argv);
  } catch (const CLI::ParseError& e) {
    // --help and --version come as ParseErrors too (status 0, text on stdout); for every usage error CLI11
    // prints its message, and the status is 2 whatever CLI11's own code for that error.
    return app.exit(e) == 0 ? trivcon::cli::kSuccess : trivcon::cli::kUsageError;
  } catch (const trivcon::Error& e) {
    std::cerr << "trivcon: error: " << e.what() << "\n";
    return trivcon::cli::kBadInput;
  } catch (const std::bad_alloc&) {
    std::cerr << "trivcon: error: out of memory\n";
    return trivcon::cli::kBadInput;
  } catch (const std::exception& e) {
    std::cerr << "trivcon: internal error: " << e.what() << "\n";
    return trivcon::cli::kInternalError;
  }
  return trivcon::cli::exit_code;
}
