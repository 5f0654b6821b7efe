// SPDX-License-Identifier: MIT
// `trivcon solve --auto`, `--auto-cancel`, `--sing-out` and `--sing-from-field`, run as a separate process.
#include <cmath>
#include <fstream>
#include <Eigen/Geometry>
#include <nlohmann/json.hpp>

#include "support.h"
#include "trivcon/io.h"

namespace trivcon {
namespace {

using test::run_cli;
using test::slurp;
using test::temp_file;

nlohmann::json read_json(const std::string& path) { return nlohmann::json::parse(slurp(path)); }

// The report's singularities as vertex → index text.
std::map<int, std::string> report_singularities(const nlohmann::json& report) {
  std::map<int, std::string> s;
  for (const auto& item : report["singularities"]) s[item["vertex"].get<int>()] = item["index"].get<std::string>();
  return s;
}

std::string mesh_file(const Mesh& m, const std::string& name) {
  const std::string path = temp_file(name);
  write_obj(path, m.V, m.F);
  return path;
}

// `solve MESH -N 4 --auto OPTIONS` and then `solve MESH -N 4 -s (its singularities) OPTIONS`: the two reports.
struct AutoThenGiven {
  nlohmann::json automatic, given;
};
AutoThenGiven solve_auto_then_given(const std::string& mesh, const std::string& options) {
  const std::string auto_report = temp_file("auto.json"), given_report = temp_file("given.json"), sing = temp_file("auto.sing");
  auto r = run_cli("solve " + mesh + " -N 4 --auto " + options + " --sing-out " + sing + " --report " + auto_report);
  EXPECT_EQ(r.status, 0) << r.err;
  r = run_cli("solve " + mesh + " -N 4 -s " + sing + " " + options + " --report " + given_report);
  EXPECT_EQ(r.status, 0) << r.err;
  return {read_json(auto_report), read_json(given_report)};
}

// The two reports name the same singularities, both are verified, and their energies agree to 1e-9: the same field.
void expect_same_field(const nlohmann::json& a, const nlohmann::json& g) {
  EXPECT_EQ(report_singularities(a), report_singularities(g));
  EXPECT_TRUE(a["verified"].get<bool>() && g["verified"].get<bool>());
  EXPECT_NEAR(g["energy"].get<double>(), a["energy"].get<double>(), 1e-9 * a["energy"].get<double>());
}

TEST(CliAuto, CubeGetsEightCornersAndSolvesExactly) {
  const std::string mesh = mesh_file(make_cube_sphere(8, false), "cube.obj");
  const std::string report = temp_file("report.json"), sings = temp_file("auto.sing"), field = temp_file("field.txt");
  const auto r = run_cli("solve " + mesh + " -N 4 --auto --report " + report + " --sing-out " + sings + " --field-out " + field);
  ASSERT_EQ(r.status, 0) << r.err;
  EXPECT_NE(r.out.find("auto: smoothest field found 8 singularities, 0 removed by summing over coincident vertices, cancelled 0 pairs, using 8"), std::string::npos) << r.out;
  const nlohmann::json j = read_json(report);
  EXPECT_EQ(j["auto"]["found"], 8);
  EXPECT_EQ(j["auto"]["cancelled_pairs"], 0);
  EXPECT_EQ(j["auto"]["used"], 8);
  EXPECT_EQ(j["auto"]["ordering"], "AMD");  // a small mesh: minimum degree alone
  EXPECT_TRUE(j["verified"].get<bool>());
  EXPECT_TRUE(j["indices"]["field_mismatches"].empty());
  const std::map<int, std::string> used = report_singularities(j);
  ASSERT_EQ(used.size(), 8u);
  for (const auto& [v, index] : used) EXPECT_EQ(index, "1/4") << "vertex " << v;
  // The written singularities are exactly those of the field.
  const auto c = run_cli("check " + mesh + " " + field + " -N 4 -s " + sings);
  EXPECT_EQ(c.status, 0) << c.out << c.err;
  EXPECT_NE(c.out.find("matches the prescription"), std::string::npos) << c.out;
}

TEST(CliAuto, SingOutRoundTripsThroughS) {
  const std::string mesh = mesh_file(make_icosphere(2), "sphere.obj");
  const std::string sings = temp_file("used.sing"), r1 = temp_file("r1.json"), r2 = temp_file("r2.json");
  const auto a =
      run_cli("solve " + mesh + " -N 4 --sing 0:1/2 --sing 3:1 --sing 7:1/4 --sing 9:1/4 --sing-out " + sings + " --report " + r1);
  ASSERT_EQ(a.status, 0) << a.err;
  const std::string text = slurp(sings);
  EXPECT_EQ(text.rfind("# trivcon singularities", 0), 0u) << text;
  EXPECT_NE(text.find("\n0 1/2\n3 1\n7 1/4\n9 1/4\n"), std::string::npos) << text;
  const auto b = run_cli("solve " + mesh + " -N 4 -s " + sings + " --report " + r2);
  ASSERT_EQ(b.status, 0) << b.err;
  EXPECT_EQ(report_singularities(read_json(r1)), report_singularities(read_json(r2)));
  EXPECT_EQ(read_json(r1)["energy"], read_json(r2)["energy"]);
}

TEST(CliAuto, SingFromFieldReproducesAnotherFieldsSingularities) {
  const Mesh m = make_icosphere(3);
  const std::string mesh = mesh_file(m, "sphere.obj");
  // A field by another route: unit weights, written as Directional's .rawfield.
  const std::string raw = temp_file("other.rawfield"), r1 = temp_file("r1.json"), r2 = temp_file("r2.json");
  const auto a = run_cli(
      "solve " + mesh +
      " -N 4 --weights unit --sing 0:1/4 --sing 1:1/4 --sing 2:1/4 --sing 3:1/4 --sing 4:1/4 --sing 5:1/4 --sing 6:1/2 --field-out " + raw +
      " --report " + r1);
  ASSERT_EQ(a.status, 0) << a.err;
  const auto b = run_cli("solve " + mesh + " --sing-from-field " + raw + " --report " + r2);
  ASSERT_EQ(b.status, 0) << b.err;
  EXPECT_NE(b.out.find("has 7 singularities"), std::string::npos) << b.out;
  const nlohmann::json j2 = read_json(r2);
  EXPECT_EQ(j2["N"], 4);  // from the file
  EXPECT_EQ(report_singularities(read_json(r1)), report_singularities(j2));
  EXPECT_EQ(j2["sing_from_field"]["singularities"], 7);
  EXPECT_TRUE(read_json(r1)["indices"]["field_mismatches"].empty());
  EXPECT_TRUE(j2["verified"].get<bool>());

  // A field built by hand: the constant world direction z projected onto every face (N = 1), in the text
  // format; its singularities are whatever `check` finds in it.
  const std::string hand = temp_file("hand.txt"), r3 = temp_file("r3.json");
  {
    std::ofstream out(hand);
    out << "# N 1\n";
    for (int f = 0; f < m.F.rows(); ++f) {
      const Eigen::RowVector3d p0 = m.V.row(m.F(f, 0)), p1 = m.V.row(m.F(f, 1)), p2 = m.V.row(m.F(f, 2));
      const Eigen::RowVector3d n = (p1 - p0).cross(p2 - p0).normalized();
      const Eigen::RowVector3d z(0.3, 0.2, 1.0);
      const Eigen::RowVector3d d = z - z.dot(n) * n;
      out << d(0) << " " << d(1) << " " << d(2) << "\n";
    }
  }
  const auto c = run_cli("check " + mesh + " " + hand + " --json");
  ASSERT_EQ(c.status, 0) << c.err;
  std::map<int, std::string> found;
  const nlohmann::json check = nlohmann::json::parse(c.out);
  for (const auto& item : check["singularities"]) found[item["vertex"].get<int>()] = item["index"].get<std::string>();
  const auto s = run_cli("solve " + mesh + " --sing-from-field " + hand + " --report " + r3);
  ASSERT_EQ(s.status, 0) << s.err;
  EXPECT_EQ(report_singularities(read_json(r3)), found);
  EXPECT_FALSE(found.empty());
}

TEST(CliAuto, CancelOptionReportsFoundCancelledAndUsed) {
  Mesh m = make_icosphere(3);
  for (int v = 0; v < m.V.rows(); ++v) m.V.row(v) *= 1.0 + 0.08 * std::sin(37.0 * v);
  const std::string mesh = mesh_file(m, "noisy.obj"), report = temp_file("report.json");
  const auto r = run_cli("solve " + mesh + " -N 4 --auto --auto-cancel 4 --report " + report);
  ASSERT_EQ(r.status, 0) << r.err;
  const nlohmann::json j = read_json(report);
  const int found = j["auto"]["found"], pairs = j["auto"]["cancelled_pairs"], used = j["auto"]["used"];
  EXPECT_EQ(j["auto"]["coincident_removed"], 0);
  EXPECT_EQ(found, used + 2 * pairs);
  EXPECT_EQ(static_cast<int>(j["singularities"].size()), used);
  EXPECT_NE(r.out.find("auto: smoothest field found " + std::to_string(found) + " singularities, 0 removed by summing over coincident " +
                       "vertices, cancelled " + std::to_string(pairs) + " pairs, using " + std::to_string(used)),
            std::string::npos)
      << r.out;
  EXPECT_TRUE(j["verified"].get<bool>());
}

TEST(CliAuto, AlignedDiskGetsFourQuarterSingularities) {
  const std::string mesh = mesh_file(test::jittered_disk(12, 8, 0.3), "disk.obj"), report = temp_file("report.json");
  const auto r = run_cli("solve " + mesh + " -N 4 --align-boundary --auto --report " + report);
  ASSERT_EQ(r.status, 0) << r.err;
  const nlohmann::json j = read_json(report);
  const std::map<int, std::string> used = report_singularities(j);
  EXPECT_EQ(used.size(), 4u);
  for (const auto& [v, index] : used) EXPECT_EQ(index, "1/4") << "vertex " << v;
  EXPECT_TRUE(j["verified"].get<bool>());
}

// --fix faces are held by the smoothest field too (Dirichlet values), then by the exact solve.
// Under --auto every path's turn is read from the smoothest field (the sparse route); the same singularities given
// back with -s take the dense route, whose turns are chosen with the cycles: the same field.
TEST(CliAuto, FixedFacesAreHonoured) {
  const std::string mesh = mesh_file(make_icosphere(3), "sphere.obj");
  const auto [j, g] = solve_auto_then_given(mesh, "--fix 0:1,0,0 --fix 500:0,1,0");
  int sum = 0;
  for (const auto& [v, index] : report_singularities(j)) sum += index == "1/4" ? 1 : index == "-1/4" ? -1 : 100;
  EXPECT_EQ(sum, 8);
  EXPECT_EQ(j["fixed"]["faces"], 2);
  EXPECT_EQ(j["fixed"]["path_turns"], "from the guide");
  EXPECT_LE(j["fixed"]["max_error"].get<double>(), 1e-9);
  EXPECT_TRUE(j["verified"].get<bool>());
  EXPECT_EQ(g["fixed"]["path_turns"], "with the cycles");
  EXPECT_EQ(report_singularities(g), report_singularities(j));
  EXPECT_NEAR(g["energy"].get<double>(), j["energy"].get<double>(), 1e-9 * j["energy"].get<double>());
}

// More fixed-face paths than the dense route takes (a plate with 27 round holes, its boundary aligned: 2,111):
// their turns are read from the smoothest field, and the report says so; --auto's singularities given back with -s
// make the same field (the smallest turn per path would give several times the energy, docs/solver.md,
// "Fixed-face paths").
TEST(CliAuto, ManyFixedFacePathsTakeTheirTurnsFromTheSmoothestField) {
  const std::string mesh = mesh_file(test::perforated_plate(9, 3, 16, 4, 0.3), "plate.obj");
  const auto [a, g] = solve_auto_then_given(mesh, "--align-boundary");
  EXPECT_EQ(a["fixed"]["paths"], 2111);
  EXPECT_EQ(a["fixed"]["path_turns"], "from the guide");
  EXPECT_EQ(g["fixed"]["path_turns"], "from the guide");
  expect_same_field(a, g);
}

// Sharp edges aligned on a closed plate with holes (hundreds of fixed-face paths, fewer than the dense route
// takes): --auto reads their turns from the smoothest field; its singularities given back with -s, the dense
// route chooses them with the cycles; the fields are the same.
TEST(CliAuto, FeatureLinesUnderAutoMakeTheDenseRoutesField) {
  const std::string mesh = mesh_file(test::extruded(test::perforated_plate(3, 1, 6, 3, 0.3), 0.5), "plate.obj");
  const auto [a, g] = solve_auto_then_given(mesh, "--align-features 30");
  EXPECT_GT(a["fixed"]["paths"].get<int>(), 100);
  EXPECT_EQ(a["fixed"]["paths"], g["fixed"]["paths"]);
  EXPECT_EQ(a["fixed"]["path_turns"], "from the guide");
  EXPECT_EQ(g["fixed"]["path_turns"], "with the cycles");
  expect_same_field(a, g);
}

// A scan whose holes leave boundary vertices without an interior neighbour (strips one triangle wide): the field's
// extra whole turns at such a vertex go to the nearest interior vertex, so that --auto's singularities sum to what
// the aligned boundary needs (the dragon, 407 holes: its largest component was refused, a quarter short).
TEST(CliAuto, AlignedBoundaryOfAScanWithStripsOneTriangleWide) {
  TRIVCON_REQUIRE_SHARED();
  const std::string report = temp_file("dragon.json");
  const auto r = run_cli("solve " + test::shared_mesh("dragon_vrip.ply") + " -N 4 --auto --align-boundary -q --report " + report);
  ASSERT_EQ(r.status, 0) << r.err;
  const nlohmann::json j = read_json(report);
  EXPECT_TRUE(j["verified"].get<bool>());
  EXPECT_GT(j["fixed"]["faces"].get<int>(), 1000);
  EXPECT_GT(j["singularities"].size(), 100u);
}

TEST(CliAuto, CurvatureAlignmentOnAFatTorusHasNoSingularities) {
  const std::string mesh = mesh_file(make_torus(96, 24, 1.0, 0.4), "torus.obj"), report = temp_file("report.json");
  const auto r = run_cli("solve " + mesh + " -N 4 --auto --align curvature:-2 --report " + report);
  ASSERT_EQ(r.status, 0) << r.err;
  const nlohmann::json j = read_json(report);
  EXPECT_EQ(j["auto"]["align"]["guidance"], "curvature");
  EXPECT_EQ(j["auto"]["align"]["t"], -2.0);
  EXPECT_EQ(j["auto"]["used"], 0);
  EXPECT_TRUE(j["verified"].get<bool>());
}

TEST(CliAuto, UsageErrors) {
  const std::string mesh = mesh_file(make_icosphere(1), "sphere.obj"), sings = temp_file("s.sing");
  test::write_text(sings, "0 1\n1 1\n");
  EXPECT_EQ(run_cli("solve " + mesh + " --auto --sing 0:1 --sing 1:1").status, 2);
  EXPECT_EQ(run_cli("solve " + mesh + " --auto -s " + sings).status, 2);
  EXPECT_EQ(run_cli("solve " + mesh + " --auto-cancel 2").status, 2);
  EXPECT_EQ(run_cli("solve " + mesh + " --auto --auto-cancel -1").status, 2);
  EXPECT_EQ(run_cli("solve " + mesh + " --sing-from-field f.txt -s " + sings).status, 2);
  EXPECT_EQ(run_cli("solve " + mesh + " --align curvature").status, 2);  // needs --auto
  for (const std::string bad : {"bumps", "curvature:", "curvature:1", "curvature:x", "curvature:0.5x"}) {
    const auto u = run_cli("solve " + mesh + " --auto --align " + bad);
    EXPECT_EQ(u.status, 2) << bad;
    EXPECT_NE(u.err.find("expected curvature or curvature:T with a number T < 1, not '" + bad + "'"), std::string::npos) << u.err;
  }
  // N odd: principal directions are lines.
  const auto odd = run_cli("solve " + mesh + " -N 3 --auto --align curvature");
  EXPECT_EQ(odd.status, 1);
  EXPECT_NE(odd.err.find("curvature alignment needs an even N (principal directions are lines), not N = 3"), std::string::npos) << odd.err;
  // A field file that does not exist is bad input, named.
  const auto r = run_cli("solve " + mesh + " --sing-from-field " + temp_file("missing.txt"));
  EXPECT_EQ(r.status, 1);
  EXPECT_NE(r.err.find("missing.txt"), std::string::npos) << r.err;
}


// A boundary alignment that needs interior singularities and gets none is an error naming the sum; with
// --auto the same mesh solves, and says that its per-face field is exact.
TEST(CliAuto, AlignedDiskWithoutSingularitiesIsAnErrorAndAutoFixesIt) {
  const std::string mesh = mesh_file(make_disk(30, 120), "disk.obj"), report = temp_file("report.json");
  const auto bad = run_cli("solve " + mesh + " -N 4 --align-boundary");
  EXPECT_EQ(bad.status, 1) << bad.err;
  EXPECT_NE(bad.err.find("need interior singularities summing to 1 (Gauss-Bonnet with the boundary's turning, Euler characteristic 1), "
                         "but the prescription's sum to 0"),
            std::string::npos)
      << bad.err;
  EXPECT_NE(bad.err.find("--auto"), std::string::npos) << bad.err;
  const auto good = run_cli("solve " + mesh + " -N 4 --align-boundary --auto --report " + report);
  ASSERT_EQ(good.status, 0) << good.err;
  EXPECT_NE(good.out.find("field exact: yes"), std::string::npos) << good.out;
  const nlohmann::json j = read_json(report);
  EXPECT_TRUE(j["field_exact"].get<bool>());
  EXPECT_TRUE(j["verified"].get<bool>());
}

// Verified but not exact for a reader: two +1 crosses on a coarse icosphere turn by more than π/4 across the
// edges around them, so the per-face field reads other indices there. The program says so plainly.
TEST(CliAuto, AVerifiedFieldThatReadsOtherSingularitiesSaysItIsNotExact) {
  const std::string mesh = mesh_file(make_icosphere(1), "ico.obj"), report = temp_file("report.json");
  const auto r = run_cli("solve " + mesh + " -N 4 --sing 0:1 --sing 3:1 --report " + report);
  ASSERT_EQ(r.status, 0) << r.err;
  EXPECT_NE(r.out.find("field exact: NO"), std::string::npos) << r.out;
  EXPECT_NE(r.err.find("--split-large-turns"), std::string::npos) << r.err;
  const nlohmann::json j = read_json(report);
  EXPECT_TRUE(j["verified"].get<bool>());
  EXPECT_FALSE(j["field_exact"].get<bool>());
  EXPECT_FALSE(j["indices"]["field_mismatches"].empty());
  // Refined until no edge turns that much, it is exact.
  const auto s = run_cli("solve " + mesh + " -N 4 --sing 0:1 --sing 3:1 --split-large-turns --report " + report);
  ASSERT_EQ(s.status, 0) << s.err;
  EXPECT_TRUE(read_json(report)["field_exact"].get<bool>()) << s.out;
}

}  // namespace
}  // namespace trivcon
