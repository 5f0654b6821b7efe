// SPDX-License-Identifier: MIT
// `trivcon solve --relax` (and `param --relax`), run as a separate process: singularities moved downhill in
// the field's energy (trivcon/relax.h), reported, written by --sing-out, pins held, usage errors.
#include <nlohmann/json.hpp>
#include <set>

#include "support.h"
#include "trivcon/io.h"
#include "trivcon/topology.h"

namespace trivcon {
namespace {

using test::run_cli;
using test::slurp;
using test::temp_file;
using test::write_text;

std::string mesh_file(const Mesh& m, const std::string& name) {
  const std::string path = temp_file(name);
  write_obj(path, m.V, m.F);
  return path;
}

// The smallest vertex `distance` edges from v.
int vertex_at_distance(const Topology& t, int v, int distance) { return test::vertex_ring(t, v, distance).front(); }

struct Box {
  std::string mesh;
  std::vector<int> corners, start;  // the 8 valence-3 corners; a vertex one or two edges from each
};

Box box() {
  const Mesh m = make_cube_sphere(6, false);
  Box b;
  b.mesh = mesh_file(m, "box.obj");
  b.corners = test::vertices_of_valence(m, 3);
  const Topology t = test::topo(m);
  for (size_t k = 0; k < b.corners.size(); ++k) b.start.push_back(vertex_at_distance(t, b.corners[k], 1 + static_cast<int>(k % 2)));
  return b;
}

std::string sing_options(const std::vector<int>& vertices, const std::string& index) {
  std::string s;
  for (int v : vertices) s += " --sing " + std::to_string(v) + ":" + index;
  return s;
}

// Eight +1/4 placed off a box's corners go to the corners; the report's energies only go down, each move
// one edge; --sing-out writes the relaxed set; the field solved is the relaxed one.
TEST(CliRelax, QuarterSingularitiesOffTheBoxCornersGoToTheCorners) {
  const Box b = box();
  const std::string report = temp_file("report.json"), sings = temp_file("relaxed.sing");
  const auto r = run_cli("solve " + b.mesh + " -N 4" + sing_options(b.start, "1/4") + " --relax --report " + report + " --sing-out " + sings);
  ASSERT_EQ(r.status, 0) << r.err;
  EXPECT_NE(r.out.find("relax: energy "), std::string::npos) << r.out;
  const nlohmann::json j = nlohmann::json::parse(slurp(report));
  const nlohmann::json& x = j["relax"];
  EXPECT_TRUE(x["converged"].get<bool>());
  EXPECT_EQ(x["moves"].size(), 12u) << "four singularities one edge away, four two edges away";
  double previous = x["energy_before"].get<double>();
  for (const auto& m : x["moves"]) {
    EXPECT_LT(m["energy"].get<double>(), previous);
    EXPECT_FALSE(m["cancelled"].get<bool>());
    EXPECT_EQ(m["index"].get<int>(), 1);
    previous = m["energy"].get<double>();
  }
  EXPECT_EQ(previous, x["energy_after"].get<double>());
  EXPECT_LT(x["energy_after"].get<double>(), 1e-9 * x["energy_before"].get<double>());
  EXPECT_NEAR(j["energy"].get<double>(), x["energy_after"].get<double>(), 1e-12);
  std::map<int, std::string> expected;
  for (int v : b.corners) expected[v] = "1/4";
  EXPECT_EQ(test::read_singularity_texts(sings), expected);
  std::set<int> reported;
  for (const auto& s : j["singularities"]) reported.insert(s["vertex"].get<int>());
  EXPECT_EQ(reported, std::set<int>(b.corners.begin(), b.corners.end()));
}

// A pinned singularity stays; no singularity moves onto a pinned vertex; --relax-max-moves stops early and says so.
TEST(CliRelax, PinsHoldAndMaxMovesStops) {
  const Box b = box();
  const std::string report = temp_file("report.json"), sings = temp_file("relaxed.sing");
  const auto r = run_cli("solve " + b.mesh + " -N 4" + sing_options(b.start, "1/4") + " --relax --relax-pin " + std::to_string(b.start[1]) +
                         " --relax-pin " + std::to_string(b.corners[0]) + " --report " + report + " --sing-out " + sings);
  ASSERT_EQ(r.status, 0) << r.err;
  const std::map<int, std::string> relaxed = test::read_singularity_texts(sings);
  EXPECT_EQ(relaxed.count(b.start[1]), 1u);
  EXPECT_EQ(relaxed.count(b.corners[0]), 0u);
  EXPECT_EQ(relaxed.size(), 8u);
  for (size_t k = 2; k < b.corners.size(); ++k) EXPECT_EQ(relaxed.count(b.corners[k]), 1u) << "corner " << b.corners[k];
  const auto one = run_cli("solve " + b.mesh + " -N 4" + sing_options(b.start, "1/4") + " --relax --relax-max-moves 1 --report " + report);
  ASSERT_EQ(one.status, 0) << one.err;
  EXPECT_NE(one.out.find(", 1 moves, "), std::string::npos) << one.out;
  EXPECT_NE(one.out.find("(stopped at --relax-max-moves: a move may still lower the energy)"), std::string::npos) << one.out;
  EXPECT_FALSE(nlohmann::json::parse(slurp(report))["relax"]["converged"].get<bool>());
  EXPECT_FALSE(nlohmann::json::parse(slurp(report))["relax"]["out_of_solves"].get<bool>()) << "no budget of solves from the CLI";
}

// A +1/4 and a −1/4 two edges apart on a sphere with eight +1/4 more: with --relax-cancel 2 they annihilate
// (reported as a cancelled pair); without it both stay, the same multiset of indices.
TEST(CliRelax, CancelAnnihilatesAnOppositePairOnlyWhenAsked) {
  const Mesh m = make_icosphere(3);
  const Topology t = test::topo(m);
  const std::string mesh = mesh_file(m, "sphere.obj"), report = temp_file("report.json"), sings = temp_file("relaxed.sing");
  const int plus = 0, minus = vertex_at_distance(t, 0, 2);
  std::vector<int> spread;
  for (int v : {5, 20, 40, 60, 80, 100, 120, 140}) spread.push_back(v);
  const std::string base = "solve " + mesh + " -N 4" + sing_options(spread, "1/4") + " --sing " + std::to_string(plus) + ":1/4 --sing " +
                           std::to_string(minus) + ":-1/4 --relax --report " + report + " --sing-out " + sings;
  const auto kept = run_cli(base);
  ASSERT_EQ(kept.status, 0) << kept.err;
  std::multiset<std::string> indices;
  for (const auto& [v, n] : test::read_singularity_texts(sings)) indices.insert(n);
  EXPECT_EQ(indices.count("-1/4"), 1u);
  EXPECT_EQ(indices.count("1/4"), 9u);
  const auto cancelled = run_cli(base + " --relax-cancel 2");
  ASSERT_EQ(cancelled.status, 0) << cancelled.err;
  EXPECT_NE(cancelled.out.find("(1 cancelling a pair)"), std::string::npos) << cancelled.out;
  const nlohmann::json j = nlohmann::json::parse(slurp(report));
  EXPECT_EQ(j["relax"]["cancelled_pairs"], 1);
  const std::map<int, std::string> after = test::read_singularity_texts(sings);
  EXPECT_EQ(after.size(), 8u);
  for (const auto& [v, n] : after) EXPECT_EQ(n, "1/4") << v;
}

// `param --relax`: the map is made from the relaxed singularities, reported.
TEST(CliRelax, ParamUsesTheRelaxedSingularities) {
  const Box b = box();
  const std::string out = temp_file("map.obj"), report = temp_file("report.json"), sings = temp_file("relaxed.sing");
  const auto r = run_cli("param " + b.mesh + sing_options(b.start, "1/4") + " --relax --target-faces 200 -o " + out + " --report " + report +
                         " --sing-out " + sings);
  ASSERT_EQ(r.status, 0) << r.err;
  EXPECT_NE(r.out.find("relax: energy "), std::string::npos) << r.out;
  std::map<int, std::string> expected;
  for (int v : b.corners) expected[v] = "1/4";
  EXPECT_EQ(test::read_singularity_texts(sings), expected);
  const nlohmann::json j = nlohmann::json::parse(slurp(report));
  EXPECT_TRUE(j["relax"]["converged"].get<bool>());
  EXPECT_TRUE(j["param"]["seamless"].get<bool>());
}

TEST(CliRelax, UsageErrors) {
  const Box b = box();
  const std::string batch = temp_file("batch.jsonl");
  write_text(batch, "{\"name\": \"a\", \"singularities\": {}}\n");
  EXPECT_EQ(run_cli("solve " + b.mesh + " -N 4 --relax-pin 3").status, 2);     // needs --relax
  EXPECT_EQ(run_cli("solve " + b.mesh + " -N 4 --relax-cancel 2").status, 2);  // needs --relax
  EXPECT_EQ(run_cli("solve " + b.mesh + " -N 4 --auto --relax --relax-cancel -1").status, 2);
  EXPECT_EQ(run_cli("solve " + b.mesh + " -N 4 --relax --sing-batch " + batch).status, 2);
  const auto pin = run_cli("solve " + b.mesh + " -N 4 --auto --relax --relax-pin 100000");
  EXPECT_EQ(pin.status, 1);
  EXPECT_NE(pin.err.find("relax: pinned vertex 100000 out of range"), std::string::npos) << pin.err;
}

}  // namespace
}  // namespace trivcon
