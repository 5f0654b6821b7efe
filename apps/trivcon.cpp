// trivcon: command-line front end. Subcommands live in apps/cmd_*.cpp; all the work is in the library.
#include <cstdio>
#include <exception>
#include <iostream>

#include "commands.h"
#include "trivcon/blas.h"
#include "trivcon/tuned_process.h"
#include "trivcon/error.h"

namespace trivcon::cli {
int exit_code = 0;
MeshData load_mesh(const std::string& path) { return read_mesh(path); }
}  // namespace trivcon::cli

int main(int argc, char** argv) {
  trivcon::use_tuned_process(argv);  // BLAS kernels and huge pages: see trivcon/tuned_process.h
  CLI::App app{"trivcon: direction fields with exactly the singularities you ask for (trivial connections, Crane et al. 2010)"};
  app.set_version_flag("--version", std::string("trivcon ") + TRIVCON_VERSION);
  app.require_subcommand(1);
  trivcon::cli::register_info(app);
  trivcon::cli::register_solve(app);
  trivcon::cli::register_param(app);
  trivcon::cli::register_check(app);
  trivcon::cli::register_render(app);
#ifdef TRIVCON_EDITOR
  trivcon::cli::register_edit(app);
#endif
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
