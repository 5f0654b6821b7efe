// SPDX-License-Identifier: MIT
// Meshes as users have them, through the program: repaired by default (trivcon/repair.h), every output indexed
// by the input file, --mesh-out the repaired mesh; --no-repair refuses them with the topology's messages.
#include <cmath>
#include <Eigen/Geometry>
#include <map>
#include <nlohmann/json.hpp>
#include <set>
#include <sstream>

#include "support.h"
#include "trivcon/design.h"
#include "trivcon/field_io.h"
#include "trivcon/io.h"
#include "trivcon/topology.h"

namespace trivcon {
namespace {

using nlohmann::json;
using test::q;
using test::run_cli;
using test::slurp;
using test::write_text;

std::string obj(const std::vector<std::array<double, 3>>& V, const std::vector<std::array<int, 3>>& F) {
  std::ostringstream s;
  s.precision(17);
  for (const auto& v : V) s << "v " << v[0] << " " << v[1] << " " << v[2] << "\n";
  for (const auto& f : F) s << "f " << f[0] + 1 << " " << f[1] + 1 << " " << f[2] + 1 << "\n";
  return s.str();
}

// A closed box [o, o + 1]^3 as 12 triangles on vertices base..base+7 (x, y, z bits of the index).
void add_box(std::vector<std::array<double, 3>>& V, std::vector<std::array<int, 3>>& F, std::array<double, 3> o) {
  const int b = static_cast<int>(V.size());
  for (int i = 0; i < 8; ++i) V.push_back({o[0] + (i >> 2 & 1), o[1] + (i >> 1 & 1), o[2] + (i & 1)});
  const int quads[6][4] = {{0, 1, 3, 2}, {4, 6, 7, 5}, {0, 4, 5, 1}, {2, 3, 7, 6}, {0, 2, 6, 4}, {1, 5, 7, 3}};
  for (const auto& qd : quads) F.push_back({b + qd[0], b + qd[1], b + qd[2]}), F.push_back({b + qd[0], b + qd[2], b + qd[3]});
}

struct Case {
  std::string name, text, summary;
  int input_faces = 0;
};

// The generated non-manifold meshes of the issue: two boxes sharing a corner, three fins on one edge, a doubled
// face, a bow tie, a face with a repeated vertex.
std::vector<Case> cases() {
  std::vector<Case> out;
  {  // box 2's corner 0 is box 1's corner 7, (1, 1, 1)
    std::vector<std::array<double, 3>> V;
    std::vector<std::array<int, 3>> F;
    add_box(V, F, {0, 0, 0});
    add_box(V, F, {1, 1, 1});
    for (auto& f : F)
      for (int& v : f) v = v == 8 ? 7 : v > 8 ? v - 1 : v;
    V.erase(V.begin() + 8);
    out.push_back({"two_boxes", obj(V, F), "repaired: 1 vertex split into separate fans (first: vertex 7, 2 fans)", 24});
  }
  out.push_back({"fins",
                 obj({{0, 0, 0}, {1, 0, 0}, {0.5, 1, 0}, {0.5, -1, 0.1}, {0.5, 0, 1}}, {{0, 1, 2}, {1, 0, 3}, {0, 1, 4}}),
                 "repaired: 1 edge with more than two faces cut (first: (0, 1)); 2 vertices split into separate fans (first: vertex 0, 2 fans)",
                 3});
  {
    std::vector<std::array<double, 3>> V;
    std::vector<std::array<int, 3>> F;
    add_box(V, F, {0, 0, 0});
    F.push_back({F[3][2], F[3][1], F[3][0]});
    out.push_back({"doubled", obj(V, F), "repaired: 1 duplicate face dropped (first: face 12, a copy of face 3)", 13});
  }
  out.push_back({"bowtie", obj({{0, 0, 0}, {1, 0, 0}, {0, 1, 0}, {-1, 0, 0}, {0, -1, 0}}, {{0, 1, 2}, {0, 3, 4}}),
                 "repaired: 1 vertex split into separate fans (first: vertex 0, 2 fans)", 2});
  {
    std::vector<std::array<double, 3>> V;
    std::vector<std::array<int, 3>> F;
    add_box(V, F, {0, 0, 0});
    F.insert(F.begin() + 5, {2, 2, 6});
    out.push_back({"repeated", obj(V, F), "repaired: 1 face with a repeated vertex dropped (first: face 5)", 13});
  }
  return out;
}

TEST(CliRepair, NonManifoldMeshesSolveByDefaultWithInputIds) {
  const std::string dir = test::temp_dir("cli_repair");
  for (const Case& c : cases()) {
    SCOPED_TRACE(c.name);
    const std::string mesh = dir + "/" + c.name + ".obj", field = dir + "/" + c.name + ".field.txt",
                      repaired = dir + "/" + c.name + ".repaired.obj", report = dir + "/" + c.name + ".json",
                      sing = dir + "/" + c.name + ".sing";
    write_text(mesh, c.text);
    // (The bow tie's two lone triangles have no interior edge: every field on them is equally smooth.)
    const auto r = run_cli("solve " + q(mesh) + " -N 4 --auto --field-out " + q(field) + " --mesh-out " + q(repaired) + " --report " +
                           q(report) + " --sing-out " + q(sing) + " -q");
    ASSERT_EQ(r.status, 0) << r.err;
    // A field row per input face, each a unit vector in the plane of its input face.
    const MeshData input = read_mesh(mesh);
    const MatrixX3d d = read_field(field, c.input_faces);
    for (int f = 0; f < c.input_faces; ++f) {
      EXPECT_NEAR(d.row(f).norm(), 1.0, 1e-9) << "face " << f;
      const Eigen::Vector3d a = input.V.row(input.F(f, 0)), b = input.V.row(input.F(f, 1)), e = input.V.row(input.F(f, 2));
      const Eigen::Vector3d n = (b - a).cross(e - a);
      if (n.norm() > 0) {
        EXPECT_NEAR(d.row(f).dot(n.normalized()), 0.0, 1e-9) << "face " << f;
      }
    }
    // The repaired mesh: manifold, the input's distinct faces in order at their input positions.
    const MeshData m = read_mesh(repaired);
    EXPECT_NO_THROW(build_topology(m.F, static_cast<int>(m.V.rows())));
    const json j = json::parse(slurp(report));
    ASSERT_TRUE(j.contains("repair"));
    EXPECT_EQ(j["repair"]["summary"], c.summary);
    std::set<int> dropped(j["repair"]["degenerate_faces"].begin(), j["repair"]["degenerate_faces"].end());
    for (const auto& p : j["repair"]["duplicate_faces"]) dropped.insert(p[0].get<int>());
    ASSERT_EQ(m.F.rows() + static_cast<Eigen::Index>(dropped.size()), c.input_faces);
    for (int f = 0, q = 0; f < c.input_faces; ++f) {
      if (dropped.count(f)) continue;
      for (int k = 0; k < 3; ++k) EXPECT_EQ(m.V.row(m.F(q, k)), input.V.row(input.F(f, k))) << "face " << f;
      ++q;
    }
    // Exact on the repaired mesh.
    EXPECT_TRUE(j["verified"].get<bool>());
    // Singularities named by input vertices.
    const std::string s = slurp(sing);
    std::istringstream lines(s);
    for (std::string line; std::getline(lines, line);)
      if (!line.empty() && line[0] != '#') {
        EXPECT_LT(std::stoi(line), input.V.rows()) << line;
      }
  }
}

TEST(CliRepair, NoRepairRefusesWithTheTopologysMessages) {
  const std::string dir = test::temp_dir("cli_repair_refuse");
  const std::map<std::string, std::string> message = {
      {"two_boxes", "non-manifold vertex 7: its faces form 2 separate fans"},
      {"fins", "non-manifold edge (0, 1) shared by 3 faces (0, 1, 2)"},
      {"doubled", "non-manifold edge"},
      {"bowtie", "non-manifold vertex 0: its faces form 2 separate fans"},
      {"repeated", "repeated.obj:14: face 5 has a repeated vertex (2, 2, 6)"}};
  for (const Case& c : cases()) {
    SCOPED_TRACE(c.name);
    const std::string mesh = dir + "/" + c.name + ".obj";
    write_text(mesh, c.text);
    for (const char* command : {"info", "solve"}) {
      const auto r = run_cli(std::string(command) + " --no-repair " + q(mesh) + (std::string(command) == "solve" ? " -N 4 --auto" : ""));
      EXPECT_EQ(r.status, 1);
      EXPECT_TRUE(test::contains(r.err, message.at(c.name))) << r.err;
    }
    // By default: a warning naming what was done, then the mesh.
    const auto r = run_cli("info " + q(mesh));
    EXPECT_EQ(r.status, 0) << r.err;
    EXPECT_TRUE(test::contains(r.out, c.summary)) << r.out;
  }
}

TEST(CliRepair, IdsOnARepairedMesh) {
  const std::string dir = test::temp_dir("cli_repair_ids");
  const std::vector<Case> all = cases();
  const std::string boxes = dir + "/two_boxes.obj", doubled = dir + "/doubled.obj";
  write_text(boxes, all[0].text);
  write_text(doubled, all[2].text);
  // A singularity at a split vertex cannot be told apart: an error naming the fans' first faces.
  auto r = run_cli("solve " + q(boxes) + " -N 4 --sing 7:1/4 -q");
  EXPECT_EQ(r.status, 1);
  EXPECT_TRUE(test::contains(r.err, "singular vertex 7 is where 2 sheets of the mesh touch (repair split it into one vertex per fan; "
                                    "first faces of the fans: 2, 12)"))
      << r.err;
  // Edge files name the repaired mesh's vertices: only beside it.
  r = run_cli("solve " + q(boxes) + " -N 4 --auto --connection-out " + q(dir + "/c.txt") + " -q");
  EXPECT_EQ(r.status, 1);
  EXPECT_TRUE(test::contains(r.err, "write it with --mesh-out")) << r.err;
  EXPECT_EQ(run_cli("solve " + q(boxes) + " -N 4 --auto --connection-out " + q(dir + "/c.txt") + " --mesh-out " + q(dir + "/m.obj") + " -q")
                .status,
            0);
  // A fixed face given by its input id (the duplicate 12 is face 3 of the repaired mesh, in the plane x = 1) holds
  // its direction.
  r = run_cli("solve " + q(doubled) + " -N 4 --auto --fix 12:0,1,1 --field-out " + q(dir + "/d.txt") + " -q");
  ASSERT_EQ(r.status, 0) << r.err;
  const MatrixX3d d = read_field(dir + "/d.txt", 13);
  for (int f : {3, 12}) {
    // One of the cross's four directions is the fixed one: the first is along it or across it.
    const Eigen::Vector3d v = d.row(f), want = Eigen::Vector3d(0, 1, 1).normalized();
    EXPECT_LT(std::min(std::abs(std::abs(v.dot(want)) - 1), std::abs(v.dot(want))), 1e-9) << "face " << f;
  }
  // check reads a field file with a row per input face.
  r = run_cli("check " + q(doubled) + " " + q(dir + "/d.txt") + " -N 4");
  EXPECT_EQ(r.status, 0) << r.err;
  // param writes the input's faces, a duplicate with the corners of the face it copies.
  r = run_cli("param " + q(doubled) + " --auto --target-faces 60 -o " + q(dir + "/p.obj") + " -q");
  EXPECT_EQ(r.status, 0) << r.err;
  EXPECT_EQ(read_mesh(dir + "/p.obj").F.rows(), 13);
}

TEST(CliRepair, SharedMeshesRefusedBeforeAreSolvedNow) {
  TRIVCON_REQUIRE_SHARED();
  const std::string dir = test::temp_dir("cli_repair_shared");
  for (const char* file : {"teapot.obj", "hourglass_ico.obj"}) {
    SCOPED_TRACE(file);
    const MeshData input = read_mesh(test::shared_mesh(file));
    const auto r = run_cli("solve " + q(test::shared_mesh(file)) + " -N 4 --auto --field-out " + q(dir + "/f.txt") + " --report " +
                           q(dir + "/r.json") + " -q");
    ASSERT_EQ(r.status, 0) << r.err;
    EXPECT_EQ(read_field(dir + "/f.txt", static_cast<int>(input.F.rows())).rows(), input.F.rows());
    const json j = json::parse(slurp(dir + "/r.json"));
    EXPECT_TRUE(j["verified"].get<bool>());
    EXPECT_FALSE(j["repair"]["split_vertices"].empty() && j["repair"]["unseparated_faces"].empty());
  }
  // What pairing leaves non-orientable stays refused, with a cycle of faces to look at.
  for (const char* file : {"truck.obj", "dragon_vrip_res3.ply"}) {
    const auto r = run_cli("info " + q(test::shared_mesh(file)));
    EXPECT_EQ(r.status, 1);
    EXPECT_TRUE(test::contains(r.err, "non-orientable component")) << r.err;
    EXPECT_TRUE(test::contains(r.err, "the orientation flips once along the cycle of faces")) << r.err;
  }
}

}  // namespace
}  // namespace trivcon
