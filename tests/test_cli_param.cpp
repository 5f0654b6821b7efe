// SPDX-License-Identifier: MIT
// `trivcon param`, run as a separate process: the OBJ it writes (the input's vertices and faces, one vt per
// corner) read back independently, the report, the usage errors.
#include <cmath>
#include <fstream>
#include <nlohmann/json.hpp>
#include <sstream>

#include "support.h"
#include "trivcon/generate.h"
#include "trivcon/io.h"

namespace trivcon {
namespace {

using test::q;
using test::run_cli;
using test::slurp;
using test::temp_file;

struct UvObj {
  std::vector<Eigen::Vector3d> v;
  std::vector<Eigen::Vector2d> vt;
  std::vector<std::array<int, 6>> f;  // vertex, vt per corner (0-based)
};

UvObj read_uv_obj(const std::string& path) {
  UvObj out;
  std::istringstream in(slurp(path));
  std::string line;
  while (std::getline(in, line)) {
    std::istringstream s(line);
    std::string key;
    s >> key;
    if (key == "v") {
      Eigen::Vector3d p;
      s >> p.x() >> p.y() >> p.z();
      out.v.push_back(p);
    } else if (key == "vt") {
      Eigen::Vector2d p;
      s >> p.x() >> p.y();
      out.vt.push_back(p);
    } else if (key == "f") {
      std::array<int, 6> c{};
      for (int k = 0; k < 3; ++k) {
        std::string corner;
        s >> corner;
        const size_t slash = corner.find('/');
        c[2 * k] = std::stoi(corner.substr(0, slash)) - 1;
        c[2 * k + 1] = std::stoi(corner.substr(slash + 1)) - 1;
      }
      out.f.push_back(c);
    }
  }
  return out;
}

double whole_offset(double x) { return std::abs(x - std::round(x)); }

std::string mesh_file(const Mesh& m, const std::string& name) {
  const std::string path = temp_file(name);
  write_obj(path, m.V, m.F);
  return path;
}

// The cube with its 8 corners found by --auto and the field along its sharp edges: at edge length 0.5 the map
// is the cube's own grid, every corner of every face on an integer point, and the file keeps the input's
// vertices and faces in order.
TEST(CliParam, CubeGridInTheObj) {
  const Mesh m = make_cube_sphere(4, false);
  const std::string mesh = mesh_file(m, "cube.obj"), obj = temp_file("cube_uv.obj"), report = temp_file("cube_param.json"),
                    sings = temp_file("cube.sing");
  const auto r = run_cli("param " + q(mesh) + " --auto --align-features 30 --edge-length 0.5 -o " + q(obj) + " --report " + q(report) +
                         " --sing-out " + q(sings));
  ASSERT_EQ(r.status, 0) << r.err;
  EXPECT_NE(r.out.find("seamless: yes"), std::string::npos) << r.out;
  EXPECT_EQ(r.err, "");
  const UvObj uv = read_uv_obj(obj);
  ASSERT_EQ(uv.v.size(), static_cast<size_t>(m.V.rows()));
  ASSERT_EQ(uv.f.size(), static_cast<size_t>(m.F.rows()));
  ASSERT_EQ(uv.vt.size(), 3 * uv.f.size());
  for (size_t v = 0; v < uv.v.size(); ++v) EXPECT_EQ(uv.v[v], Eigen::Vector3d(m.V.row(v))) << "vertex " << v;
  for (size_t f = 0; f < uv.f.size(); ++f)
    for (int k = 0; k < 3; ++k) {
      EXPECT_EQ(uv.f[f][2 * k], m.F(f, k));
      EXPECT_EQ(uv.f[f][2 * k + 1], static_cast<int>(3 * f + k));
    }
  for (const Eigen::Vector2d& p : uv.vt) EXPECT_LT(std::max(whole_offset(p.x()), whole_offset(p.y())), 1e-9);
  const nlohmann::json j = nlohmann::json::parse(slurp(report));
  EXPECT_TRUE(j["param"]["seamless"].get<bool>());
  EXPECT_EQ(j["param"]["flipped_faces"], 0);
  EXPECT_EQ(j["param"]["cones"], 8);
  EXPECT_EQ(j["singularities"].size(), 8u);
  EXPECT_NEAR(j["param"]["unit_squares"].get<double>(), 96, 1e-6);
  int listed = 0;
  for (const std::string& line : test::lines_of(slurp(sings))) listed += !line.empty() && line[0] != '#';
  EXPECT_EQ(listed, 8);
  // The checkerboard with the singularities marked: a map is of a cross field, so --uv alone reads indices of 1/4.
  const auto picture = run_cli("render " + q(mesh) + " --uv " + q(obj) + " -s " + q(sings) + " --size 200x150 -o " + q(temp_file("cube_uv.png")));
  EXPECT_EQ(picture.status, 0) << picture.err;
  EXPECT_EQ(picture.err, "");
}

TEST(CliParam, DiskWithAlignedBoundary) {
  const Mesh m = make_disk(10, 8);
  const std::string mesh = mesh_file(m, "disk.obj"), obj = temp_file("disk_uv.obj"), report = temp_file("disk_param.json");
  const auto r = run_cli("param " + q(mesh) + " --auto --align-boundary --target-faces 60 -o " + q(obj) + " --report " + q(report));
  ASSERT_EQ(r.status, 0) << r.err;
  const nlohmann::json j = nlohmann::json::parse(slurp(report));
  EXPECT_TRUE(j["param"]["seamless"].get<bool>());
  EXPECT_GT(j["param"]["aligned_edges"].get<int>(), 0);
  EXPECT_LT(j["param"]["max_alignment_error"].get<double>(), 1e-9);
  EXPECT_EQ(j["param"]["flipped_faces"], 0);
  // Every boundary edge whose face's field runs along it has one whole coordinate at both ends.
  const UvObj uv = read_uv_obj(obj);
  EXPECT_EQ(uv.vt.size(), 3 * static_cast<size_t>(m.F.rows()));
}

// `param --auto` moves singularities beside the sharp edges onto them, turning a sector at each; written with
// --sing-out and given back to `param -s`, they get the same sectors (FieldRequest::sectors_for_singularities), so
// the field and the map are the same to the byte. A closed plate 0.3 thick with three round holes, 30° sharp edges, 100 squares.
TEST(CliParam, SingularitiesMovedOntoLinesGivenBackMakeTheSameMap) {
  const std::string mesh = mesh_file(test::extruded(test::perforated_plate(3, 1, 8, 4, 0.3), 0.3), "plate3.obj");
  const std::string sing = temp_file("s.txt"), first = temp_file("a.obj"), again = temp_file("b.obj");
  const std::string auto_report = temp_file("a.json"), given_report = temp_file("b.json");
  const auto a = run_cli("param " + q(mesh) + " --auto --align-features 30 --target-faces 100 -o " + q(first) + " --sing-out " + q(sing) +
                         " --report " + q(auto_report));
  ASSERT_EQ(a.status, 0) << a.err;
  const nlohmann::json ja = nlohmann::json::parse(slurp(auto_report));
  const int moved = ja["features"]["singularities_moved_onto_them"].get<int>();
  ASSERT_GT(moved, 0);
  EXPECT_EQ(ja["features"]["sectors_turned_for_singularities"], 0);
  const auto b = run_cli("param " + q(mesh) + " -s " + q(sing) + " --align-features 30 --target-faces 100 -o " + q(again) + " --report " +
                         q(given_report));
  ASSERT_EQ(b.status, 0) << b.err;
  const nlohmann::json jb = nlohmann::json::parse(slurp(given_report));
  EXPECT_EQ(jb["features"]["sectors_turned_for_singularities"], moved);
  EXPECT_EQ(jb["features"]["singularities_moved_onto_them"], 0);
  EXPECT_NEAR(jb["field"]["energy"].get<double>(), ja["field"]["energy"].get<double>(), 1e-9 * ja["field"]["energy"].get<double>());
  EXPECT_EQ(jb["param"]["flipped_faces"], 0);
  EXPECT_EQ(jb["param"]["degenerate_faces"], 0);
  EXPECT_EQ(slurp(again), slurp(first));
}

// --uniform-size: no sizing (one unit of (u, v) everywhere); without it the map's own scale, and an annulus with
// its circles aligned (iso-lines ringing the hole as many at every radius) stretches less; --sizing connection
// (the connection's conformal factor, φ = −log r here) less still. --sizing uniform is --uniform-size.
TEST(CliParam, UniformSizeTurnsTheSizingOff) {
  const std::string mesh = mesh_file(make_annulus(12, 96, 0.5, 1.0), "annulus.obj"), obj = temp_file("annulus_uv.obj");
  const std::vector<std::pair<std::string, std::string>> runs{
      {"", "map"}, {" --uniform-size", "uniform"}, {" --sizing uniform", "uniform"}, {" --sizing connection", "connection"}};
  std::vector<double> ratio;
  for (size_t k = 0; k < runs.size(); ++k) {
    const std::string report = temp_file("annulus_" + std::to_string(k) + ".json");
    const auto r = run_cli("param " + q(mesh) + " --auto --align-boundary --target-faces 1600 -o " + q(obj) + " --report " + q(report) +
                           runs[k].first);
    ASSERT_EQ(r.status, 0) << r.err;
    const nlohmann::json j = nlohmann::json::parse(slurp(report));
    EXPECT_TRUE(j["param"]["seamless"].get<bool>());
    EXPECT_EQ(j["param"]["flipped_faces"], 0);
    EXPECT_EQ(j["param"]["sizing"], runs[k].second) << runs[k].first;
    ratio.push_back(j["param"]["mean_distortion"].get<double>());
  }
  EXPECT_LT(ratio[0], ratio[1] - 0.05) << "sized " << ratio[0] << ", uniform " << ratio[1];
  EXPECT_EQ(ratio[1], ratio[2]);
  EXPECT_LT(ratio[3], ratio[0]) << "connection " << ratio[3] << ", map " << ratio[0];
  auto r = run_cli("param " + q(mesh) + " --auto --align-boundary --target-faces 1600 -o " + q(obj) + " --sizing conformal");
  EXPECT_NE(r.status, 0);
  EXPECT_NE(r.err.find("--sizing: conformal not in {map,connection,uniform}"), std::string::npos) << r.err;
  r = run_cli("param " + q(mesh) + " --auto --align-boundary --target-faces 1600 -o " + q(obj) + " --sizing map --uniform-size");
  EXPECT_NE(r.status, 0);
  EXPECT_NE(r.err.find("excludes"), std::string::npos) << r.err;
}

TEST(CliParam, UsageErrors) {
  const std::string mesh = mesh_file(make_torus(12, 6), "torus.obj"), obj = temp_file("torus_uv.obj");
  auto r = run_cli("param " + q(mesh) + " -o " + q(obj));
  EXPECT_EQ(r.status, 2);
  EXPECT_NE(r.err.find("give the scale of the map: one of them"), std::string::npos) << r.err;
  r = run_cli("param " + q(mesh) + " --target-faces 10 --edge-length 1 -o " + q(obj));
  EXPECT_EQ(r.status, 2);
  r = run_cli("param " + q(mesh) + " --target-faces 0 -o " + q(obj));
  EXPECT_EQ(r.status, 2);
  r = run_cli("param " + q(mesh) + " -N 6 --target-faces 10 -o " + q(obj));
  EXPECT_EQ(r.status, 2);
  r = run_cli("param " + q(mesh) + " --split-large-turns --target-faces 10 -o " + q(obj));
  EXPECT_EQ(r.status, 2);
  EXPECT_NE(r.err.find("large turns are no problem"), std::string::npos) << r.err;
  EXPECT_FALSE(std::ifstream(obj).good());  // nothing written
}

// Real meshes, when ../shared is beside the project: seamless, cones on integer points, no folds.
TEST(CliParam, SharedMeshes) {
  for (const char* name : {"spot.obj", "fertility.off", "bob_small.ply", "face.obj"}) {
    const std::string mesh = test::shared_mesh(name);
    if (mesh.empty()) GTEST_SKIP() << "../shared/data/meshes is not beside the project";
    const std::string obj = temp_file(std::string(name) + "_uv.obj"), report = temp_file(std::string(name) + "_param.json");
    const auto r = run_cli("param " + q(mesh) + " --auto --target-faces 3000 -o " + q(obj) + " --report " + q(report));
    ASSERT_EQ(r.status, 0) << name << ": " << r.err;
    const nlohmann::json j = nlohmann::json::parse(slurp(report));
    EXPECT_TRUE(j["param"]["seamless"].get<bool>()) << name;
    EXPECT_LT(j["param"]["max_cone_offset"].get<double>(), 1e-9) << name;
    EXPECT_LT(j["param"]["max_cone_angle_error"].get<double>(), 1e-9) << name;
    EXPECT_EQ(j["param"]["flipped_faces"], 0) << name;
    EXPECT_EQ(j["param"]["degenerate_faces"], 0) << name;
    const double squares = j["param"]["unit_squares"].get<double>();
    EXPECT_NEAR(squares / 3000, 1.0, 0.3) << name;
    EXPECT_LE(j["param"]["mean_distortion"].get<double>(), 1.5) << name;
  }
}

}  // namespace
}  // namespace trivcon
