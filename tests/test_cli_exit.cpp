// SPDX-License-Identifier: MIT
// The exit statuses of the `trivcon` program, end to end (docs/reference/exit-codes.md): 0 success (also
// --help and --version), 1 bad input, 2 usage error (whatever CLI11's own code for it), 3 `solve`
// verification failed, 4 `check` found indices that differ from the prescription. Meshes are generated
// here and written with trivcon::write_obj.
#include <gtest/gtest.h>

#include <algorithm>
#include <filesystem>
#include <fstream>
#include <iterator>
#include <nlohmann/json.hpp>
#include <string>

#include "support.h"
#include "trivcon/generate.h"
#include "trivcon/io.h"

namespace trivcon {
namespace {

namespace fs = std::filesystem;
using namespace test;  // run_cli, q, save, slurp, … (tests/support.h)

const std::string kError = "trivcon: error: ";
const std::string kRunWithHelp = "Run with --help for more information.\n";

// The UV sphere of test_cli.cpp: vertex 0 is the north pole, 85 the south pole.
std::string save_sphere(const std::string& dir) { return save(dir, "sphere", make_uv_sphere(8, 12)); }

// A usage error: status 2 exactly, CLI11's message and its hint on stderr, nothing on stdout.
void expect_usage_error(const std::string& args, const std::string& message) {
  SCOPED_TRACE("trivcon " + args);
  const CommandResult r = run_cli(args);
  EXPECT_EQ(r.status, 2) << r.err;
  EXPECT_EQ(r.err, message + "\n" + kRunWithHelp);
  EXPECT_EQ(r.out, "");
}

// Bad input: status 1 and exactly this one message on stderr.
void expect_bad_input(const std::string& args, const std::string& message) {
  SCOPED_TRACE("trivcon " + args);
  const CommandResult r = run_cli(args);
  EXPECT_EQ(r.status, 1) << r.err;
  EXPECT_EQ(r.err, kError + message + "\n");
}

// ----------------------------------------------------------------------------------------------
// 0: success, --help, --version

TEST(CliExit, HelpAndVersionExitZero) {
  for (const char* args : {"--help", "-h", "solve --help", "check --help", "info --help", "render --help"}) {
    SCOPED_TRACE(args);
    const CommandResult r = run_cli(args);
    EXPECT_EQ(r.status, 0) << r.err;
    EXPECT_NE(r.out.find("Usage: "), std::string::npos) << r.out;
    EXPECT_EQ(r.err, "");
  }
  const CommandResult r = run_cli("--version");
  EXPECT_EQ(r.status, 0) << r.err;
  EXPECT_EQ(r.out, std::string("trivcon ") + TRIVCON_VERSION + "\n");
}

// ----------------------------------------------------------------------------------------------
// 2: usage errors, one per kind; the mesh exists, so that nothing but the command line is wrong.

TEST(CliExit, UnknownOrMissingSubcommandIsTwo) {
  const std::string dir = test::temp_dir("cli_exit_subcommand");
  const std::string mesh = save_sphere(dir);
  expect_usage_error("", "A subcommand is required");
  expect_usage_error("bogus", "A subcommand is required");
  expect_usage_error("bogus " + q(mesh), "A subcommand is required");
}

TEST(CliExit, UnknownOptionIsTwo) {
  const std::string dir = test::temp_dir("cli_exit_option");
  const std::string mesh = save_sphere(dir);
  expect_usage_error("info --frobnicate " + q(mesh), "The following argument was not expected: --frobnicate");
  expect_usage_error("solve " + q(mesh) + " --frobnicate", "The following argument was not expected: --frobnicate");
  expect_usage_error("--frobnicate", "A subcommand is required");
}

TEST(CliExit, BadOptionValueIsTwo) {
  const std::string dir = test::temp_dir("cli_exit_value");
  const std::string mesh = save_sphere(dir), S = "solve " + q(mesh) + " --sing 0:1 --sing 85:1";
  expect_usage_error(S + " --weights foo", "--weights: foo not in {cotan,unit}");
  expect_usage_error(S + " --solver lu", "--solver: lu not in {cholesky,qr}");
  expect_usage_error(S + " -N 0", "--symmetry: Value 0 not in range 1 to 1000");
  expect_usage_error(S + " -N x", "--symmetry: Value x not in range 1 to 1000");
  expect_usage_error(S + " --root-face x", "Could not convert: --root-face = x");
  expect_usage_error("render " + q(mesh) + " --field f.txt -o p.png --up w", "--up: w not in {x,y,z}");
}

TEST(CliExit, MissingArgumentIsTwo) {
  const std::string dir = test::temp_dir("cli_exit_missing");
  const std::string mesh = save_sphere(dir);
  expect_usage_error("info", "mesh is required");
  expect_usage_error("solve", "mesh is required");
  expect_usage_error("check", "mesh is required");
  expect_usage_error("check " + q(mesh), "field is required");
  expect_usage_error("render " + q(mesh) + " -o p.png", "--field, --uv or --polygon-edges is required");
  // An option without its value.
  expect_usage_error("solve " + q(mesh) + " --field-out", "--field-out: 1 required TEXT missing");
  expect_usage_error("solve " + q(mesh) + " --sing", "--sing: 1 required TEXT missing");
}

TEST(CliExit, ExtraPositionalIsTwo) {
  const std::string dir = test::temp_dir("cli_exit_extra");
  const std::string mesh = save_sphere(dir);
  expect_usage_error("info " + q(mesh) + " " + q(mesh), "The following argument was not expected: " + mesh);
  expect_usage_error("check " + q(mesh) + " f.txt g.txt", "The following argument was not expected: g.txt");
}

// The program has no options that exclude each other; its subcommands do (exactly one is taken).
TEST(CliExit, TwoSubcommandsAreTwo) {
  const std::string dir = test::temp_dir("cli_exit_two_subcommands");
  const std::string mesh = save_sphere(dir);
  expect_usage_error("info " + q(mesh) + " solve " + q(mesh), "The following arguments were not expected: " + mesh + " solve");
}

// ----------------------------------------------------------------------------------------------
// 1: bad input

TEST(CliExit, BadInputIsOne) {
  const std::string dir = test::temp_dir("cli_exit_bad_input");
  const std::string missing = dir + "/nonexistent.obj";
  for (const char* command : {"info ", "solve "})
    expect_bad_input(command + q(missing), "cannot open '" + missing + "': No such file or directory");
  expect_bad_input("check " + q(missing) + " f.txt", "cannot open '" + missing + "': No such file or directory");
  // A face that names a vertex the file does not have (write_obj refuses to write one: appended).
  const Mesh m = make_icosphere(1);
  const std::string range = save(dir, "range", m);
  std::ifstream written(range);
  const std::string line = std::to_string(std::count(std::istreambuf_iterator<char>(written), {}, '\n') + 1);
  std::ofstream(range, std::ios::app) << "f 1 2 " << m.V.rows() + 1 << "\n";
  const std::string message = range + ":" + line + ": face index " + std::to_string(m.V.rows() + 1) + " out of range (file has " +
                              std::to_string(m.V.rows()) + " vertices)";
  for (const char* command : {"info ", "solve "}) expect_bad_input(command + q(range), message);
}

TEST(CliExit, UnreadableBatchIsOne) {
  const std::string dir = test::temp_dir("cli_exit_batch");
  const std::string S = "solve " + q(save_sphere(dir)) + " -q --sing-batch ";
  // A link to itself cannot be examined: a clean error (it was an internal error, status 70).
  const std::string loop = dir + "/loop";
  fs::create_symlink("loop", loop);
  expect_bad_input(S + q(loop), "cannot open '" + loop + "': Too many levels of symbolic links");
  fs::create_directories(dir + "/items");
  std::ofstream(dir + "/items/a.sing") << "0 1\n85 1\n";
  fs::create_symlink("self", dir + "/items/self");
  expect_bad_input(S + q(dir + "/items"), "cannot read '" + dir + "/items/self': Too many levels of symbolic links");
  // A dangling link is not a file of the batch.
  fs::remove(dir + "/items/self");
  fs::create_symlink("nowhere", dir + "/items/dangling");
  const CommandResult r = run_cli(S + q(dir + "/items"));
  EXPECT_EQ(r.status, 0) << r.err;
}

TEST(CliExit, UnwritableOutputIsOne) {
  const std::string dir = test::temp_dir("cli_exit_unwritable");
  const std::string mesh = save_sphere(dir);
  const CommandResult r = run_cli("solve " + q(mesh) + " -q --sing 0:1 --sing 85:1 --field-out " + q(dir + "/no/such/dir/field.txt"));
  EXPECT_EQ(r.status, 1) << r.err;
  EXPECT_TRUE(starts_with(r.err, kError + "cannot write '" + dir + "/no/such/dir/")) << r.err;
  EXPECT_FALSE(fs::exists(dir + "/no"));
}

// ----------------------------------------------------------------------------------------------
// 4: check found indices that differ

TEST(CliExit, CheckWithWrongPrescriptionIsFour) {
  const std::string dir = test::temp_dir("cli_exit_check");
  const std::string mesh = save_sphere(dir), field = dir + "/field.txt";
  const CommandResult solved = run_cli("solve " + q(mesh) + " -q --sing 0:1 --sing 85:1 --field-out " + q(field));
  ASSERT_EQ(solved.status, 0) << solved.err;
  const CommandResult right = run_cli("check " + q(mesh) + " " + q(field) + " --sing 0:1 --sing 85:1");
  EXPECT_EQ(right.status, 0) << right.err;
  const CommandResult r = run_cli("check " + q(mesh) + " " + q(field) + " --sing 0:2");
  EXPECT_EQ(r.status, 4) << r.err;
  EXPECT_EQ(r.err, "");
  EXPECT_EQ(r.out,
            "N 1: 2 singular vertices in the field\n"
            "  vertex 0 index 1\n"
            "  vertex 85 index 1\n"
            "2 vertices differ from the prescription\n"
            "  vertex 0: found 1, prescribed 2\n"
            "  vertex 85: found 1, prescribed 0\n");
  const CommandResult j = run_cli("check " + q(mesh) + " " + q(field) + " --sing 0:2 --json");
  EXPECT_EQ(j.status, 4) << j.err;
  EXPECT_EQ(nlohmann::json::parse(j.out)["differences"].size(), 2u) << j.out;
}

// ----------------------------------------------------------------------------------------------
// 3: solve verification failed

// A sliver (an edge shortened to 1e-12 of its length: angles of about 1e-12, cotangent weights near 1e12
// before mollification) used to fail verification on the default route (issue 12); now the mollified
// weights and iterative refinement make it exact, and the report says what the weight policy did. A
// verification limit no double-precision solve can meet (--tolerance 1e-17) exits 3, and the message says
// which constraint missed, by how much, after how many refinement steps, and what to try.
TEST(CliExit, VerificationFailedIsThree) {
  const std::string dir = test::temp_dir("cli_exit_verification");
  Mesh m = make_icosphere(2);
  const int a = m.F(0, 0), b = m.F(0, 1);
  m.V.row(b) = m.V.row(a) + 1e-12 * (m.V.row(b) - m.V.row(a)).normalized();
  const std::string mesh = save(dir, "sliver", m), report = dir + "/report.json";
  const std::string S = "solve " + q(mesh) + " --sing 3:1 --sing 8:1";
  {
    const CommandResult r = run_cli(S + " -q --report " + q(report));
    EXPECT_EQ(r.status, 0) << r.err;
    EXPECT_EQ(r.err, "");
    const nlohmann::json j = nlohmann::json::parse(std::ifstream(report));
    EXPECT_TRUE(j["verified"].get<bool>());
    EXPECT_GT(j["weight_policy"]["mollified_faces"].get<int>(), 0);
    EXPECT_GT(j["weight_policy"]["mollify_epsilon"].get<double>(), 0.0);
    EXPECT_EQ(j["weight_policy"]["regularized_edges"].get<int>(), 0);
    EXPECT_LE(j["residuals"]["max_vertex"].get<double>(), 1e-9 * std::max(1.0, j["residuals"]["rhs_scale"].get<double>()));
  }
  const CommandResult r = run_cli(S + " --tolerance 1e-17 --report " + q(report));
  EXPECT_EQ(r.status, 3) << r.err;
  EXPECT_TRUE(starts_with(r.err, "trivcon: verification failed: residual ")) << r.err;
  EXPECT_TRUE(contains(r.err, ", fixed faces off by 0, 0 unexplained index mismatches: the holonomy constraints are met only to "))
      << r.err;
  EXPECT_TRUE(
      contains(r.err, " steps of iterative refinement: the normal equations A W A^T are too ill-conditioned on this mesh (weights from "))
      << r.err;
#ifdef TRIVCON_WITH_SUITESPARSE
  EXPECT_TRUE(contains(r.err, "try --solver qr, which solves the constraints without the normal equations, or --weights unit")) << r.err;
#else
  EXPECT_TRUE(contains(r.err, " regularized); try --weights unit")) << r.err;
#endif
  EXPECT_EQ(std::count(r.err.begin(), r.err.end(), '\n'), 1) << r.err;
  EXPECT_NE(r.out.find("max residual "), std::string::npos) << "the summary is still printed: " << r.out;
  // The report is written, and says why.
  const nlohmann::json j = nlohmann::json::parse(std::ifstream(report));
  EXPECT_FALSE(j["verified"].get<bool>());
  EXPECT_TRUE(contains(r.err, "after " + std::to_string(j["weight_policy"]["refinements"].get<int>()) + " steps of iterative refinement"))
      << r.err;
  EXPECT_EQ(run_cli(S + " --tolerance 0").status, 2) << "the limit must be positive";
}

}  // namespace
}  // namespace trivcon
