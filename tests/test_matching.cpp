// SPDX-License-Identifier: MIT
// Matchings (trivcon/matching.h, --matching-out, check --matching): an independent principal matching, read
// from the field's world directions alone, sees other singularities where the connection turns by π/N or
// more; with the matching trivcon exports, an independent index computation finds exactly the prescription.
#include <Eigen/Geometry>
#include <cmath>
#include <fstream>
#include <map>
#include <nlohmann/json.hpp>
#include <sstream>

#include "independent_matching.h"
#include "support.h"
#include "trivcon/error.h"
#include "trivcon/field_io.h"
#include "trivcon/io.h"
#include "trivcon/matching.h"
#include "trivcon/split_large_turns.h"

namespace trivcon {
namespace {

using test::contains;
using test::error_of;
using test::q;
using test::run_cli;
using test::save;

using namespace reference;

TEST(Matching, PrincipalMatchingSeesOtherSingularitiesAndOursReadsThePrescription) {
  const LargeTurnCase c;
  FieldDesigner designer(c.mesh.V, c.mesh.F);
  const Design d = designer.design(c.p);
  const Topology& t = designer.topology();
  const std::vector<int> large = large_turn_edges(t, d.connection.x, c.p.N);
  ASSERT_FALSE(large.empty()) << "the case must have turns of pi/N or more";
  const MatrixX3d dirs = field_directions(designer.geometry(), d.field);
  // Independent principal matching: not the prescription.
  const std::map<int, int> principal = independent_indices(c.mesh.V, c.mesh.F, dirs, c.p.N, nullptr);
  EXPECT_NE(principal, c.p.vertex);
  // … and the library's field_indices (principal) agree with it.
  std::map<int, int> library;
  for (int v = 0; v < t.num_vertices; ++v)
    if (d.indices.vertex[v] != 0) library[v] = d.indices.vertex[v];
  EXPECT_EQ(library, principal);
  // With the connection's matching, the independent computation reads exactly the prescription.
  const Eigen::VectorXi m = connection_matching(t, designer.geometry(), d.field, d.connection.x);
  std::map<std::pair<int, int>, int> given;
  for (int e = 0; e < t.num_edges; ++e)
    if (!t.is_boundary_edge(e)) given[{t.edge_vertices(e, 0), t.edge_vertices(e, 1)}] = m(e);
  EXPECT_EQ(independent_indices(c.mesh.V, c.mesh.F, dirs, c.p.N, &given), c.p.vertex);
  const FieldIndices with = indices_with_matching(t, designer.geometry(), designer.cycles(), d.field, m);
  for (int v = 0; v < t.num_vertices; ++v) EXPECT_EQ(with.vertex[v], c.p.vertex.count(v) ? c.p.vertex.at(v) : 0) << "vertex " << v;
  // The principal matching differs from ours exactly on the large-turn edges (here: no turn near a multiple of π/N).
  const Eigen::VectorXi pm = principal_matching(t, designer.geometry(), d.field);
  std::vector<int> differ;
  for (int e = 0; e < t.num_edges; ++e)
    if (pm(e) != m(e)) differ.push_back(e);
  EXPECT_EQ(differ, large);
}

TEST(Matching, SmallTurnsMakeBothMatchingsEqual) {
  const Mesh m = make_icosphere(3);
  FieldDesigner designer(m.V, m.F);
  IndexPrescription p;
  p.N = 4;
  for (int v : {0, 1, 2, 3, 6, 7, 9, 11}) p.vertex[v] = 1;
  const Design d = designer.design(p);
  ASSERT_TRUE(large_turn_edges(designer.topology(), d.connection.x, 4).empty());
  EXPECT_EQ(principal_matching(designer.topology(), designer.geometry(), d.field),
            connection_matching(designer.topology(), designer.geometry(), d.field, d.connection.x));
}

TEST(Matching, CliExportsTheMatchingWarnsAndCheckReadsIt) {
  const LargeTurnCase c;
  const std::string dir = test::temp_dir("matching_cli");
  const std::string mesh = save(dir, "ico", c.mesh), field = dir + "/f.txt", matching = dir + "/f.matching", report = dir + "/r.json";
  const std::string S = "solve " + q(mesh) + " -N 4 --sing 0:3/2 --sing 1:1/4 --sing 2:1/4 --field-out " + q(field) + " --matching-out " +
                        q(matching) + " --report " + q(report);
  const test::CommandResult r = run_cli(S);
  ASSERT_EQ(r.status, 0) << r.err;
  EXPECT_TRUE(test::starts_with(r.err, "trivcon: warning: ")) << r.err;
  EXPECT_TRUE(contains(r.err, " edges turn by pi/N or more; a tool that matches directions itself (Directional, QuadWild, MIQ) will read "))
      << r.err;
  EXPECT_EQ(std::count(r.err.begin(), r.err.end(), '\n'), 1) << r.err;
  EXPECT_EQ(run_cli(S + " -q").err, "") << "--quiet silences the warning";
  const nlohmann::json j = nlohmann::json::parse(std::ifstream(report));
  EXPECT_FALSE(j["large_turns"]["edges"].empty());
  // The file: "N E", then "L R i j m"; read independently.
  std::ifstream in(matching);
  int N = 0, count = 0;
  in >> N >> count;
  EXPECT_EQ(N, 4);
  const Edges edges = edges_of(c.mesh.F);
  EXPECT_EQ(count, static_cast<int>(edges.faces.size()));
  std::map<std::pair<int, int>, int> given;
  for (int k = 0; k < count; ++k) {
    int L, R, i, j2, m;
    in >> L >> R >> i >> j2 >> m;
    EXPECT_EQ(edges.faces.at({i, j2}), std::make_pair(L, R));
    EXPECT_GE(m, 0);
    EXPECT_LT(m, 4);
    given[{i, j2}] = m;
  }
  const MatrixX3d dirs = read_field(field, static_cast<int>(c.mesh.F.rows()));
  EXPECT_EQ(independent_indices(c.mesh.V, c.mesh.F, dirs, 4, &given), c.p.vertex);
  // What the report says a principal-matching tool reads is what the independent one reads.
  std::map<int, int> consumer;
  for (const auto& s : j["large_turns"]["principal_matching_singularities"])
    consumer[s["vertex"].get<int>()] = parse_index(s["index"].get<std::string>(), 4, "report");
  EXPECT_EQ(consumer, independent_indices(c.mesh.V, c.mesh.F, dirs, 4, nullptr));
  // check: differs without the matching (exit 4), matches with it.
  const std::string C = "check " + q(mesh) + " " + q(field) + " -N 4 --sing 0:3/2 --sing 1:1/4 --sing 2:1/4";
  EXPECT_EQ(run_cli(C).status, 4);
  const test::CommandResult ok = run_cli(C + " --matching " + q(matching));
  EXPECT_EQ(ok.status, 0) << ok.err;
  EXPECT_TRUE(contains(ok.out, "matches the prescription")) << ok.out;
}

TEST(Matching, ReaderNamesTheProblem) {
  const Mesh m = make_icosphere(0);
  const Topology t = test::topo(m);
  const std::string dir = test::temp_dir("matching_reader"), path = dir + "/m.matching";
  Eigen::VectorXi zero = Eigen::VectorXi::Zero(t.num_edges);
  write_matching(path, t, zero, 4);
  EXPECT_EQ(read_matching(path, t, 4), zero);
  EXPECT_EQ(error_of([&] { read_matching(path, t, 2); }), path + ": the matching is for N = 4, the field has N = 2");
  const std::string text = test::slurp(path);
  const std::vector<std::string> lines = test::lines_of(text);
  // A swapped face pair is read with the opposite sign.
  {
    std::istringstream first(lines[1]);
    int L, R, i, j, v;
    first >> L >> R >> i >> j >> v;
    std::string swapped =
        lines[0] + "\n" + std::to_string(R) + " " + std::to_string(L) + " " + std::to_string(i) + " " + std::to_string(j) + " 1\n";
    for (size_t k = 2; k < lines.size(); ++k) swapped += lines[k] + "\n";
    test::write_text(path, swapped);
    const Eigen::VectorXi back = read_matching(path, t, 4);
    EXPECT_EQ(back.sum(), 3) << "−1 modulo 4";
  }
  std::string duplicate = lines[0] + "\n" + lines[1] + "\n" + lines[1] + "\n";
  for (size_t k = 3; k < lines.size(); ++k) duplicate += lines[k] + "\n";
  test::write_text(path, duplicate);
  EXPECT_TRUE(contains(error_of([&] { read_matching(path, t, 4); }), ":3: edge (")) << error_of([&] { read_matching(path, t, 4); });
  test::write_text(path, "4 30\n0 1 0 99 1\n");
  EXPECT_EQ(error_of([&] { read_matching(path, t, 4); }), path + ":2: vertex '99' is not a whole number in [0, 11]");
  test::write_text(path, "4 29\n");
  EXPECT_EQ(error_of([&] { read_matching(path, t, 4); }), path + ":1: the file lists 29 edges, the mesh has 30 interior edges");
  test::write_text(path, "4 1000000000000\n");
  EXPECT_EQ(error_of([&] { read_matching(path, t, 4); }), path + ":1: the edge count '1000000000000' is not a whole number in [0, 30]");
}

}  // namespace
}  // namespace trivcon
