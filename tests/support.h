// Shared helpers for the test programs.
#pragma once
#include <gtest/gtest.h>

#include <map>
#include <string>

#include "trivcon/design.h"

namespace trivcon::test {

// Absolute path of ../shared/data/meshes/NAME, or "" when the shared folder is absent.
std::string shared_mesh(const std::string& name);
// GTEST_SKIP()s the calling test with a message when the shared meshes are absent.
#define TRIVCON_REQUIRE_SHARED()                                                                        \
  if (::trivcon::test::shared_mesh("SOURCES.md").empty())                                               \
  GTEST_SKIP() << "../shared/data/meshes not found next to the repository: skipping real-mesh test"

// A fresh directory for this test's files (under the build tree).
std::string temp_dir(const std::string& name);

struct CommandResult {
  int status = 0;  // exit status
  std::string out, err;
};
// Runs the trivcon program with the arguments (a shell-quoted string), capturing stdout and stderr.
CommandResult run_cli(const std::string& args);

// Optimality of a connection: x is W-orthogonal to every exact dual 1-form (vanishing on the fixed-face
// paths), i.e. at every face whose edges are all interior with w > 0 and that is not in `skip` (the fixed
// faces), Σ σ_fe x_e / w_e = 0 (σ = +1 where f is the edge's L face, −1 where it is R). Returns the
// largest such sum relative to max |x_e / w_e|.
double max_face_optimality(const FieldDesigner& designer, const Connection& connection, const std::map<int, double>& skip = {});

}  // namespace trivcon::test
