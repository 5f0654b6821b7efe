// SPDX-License-Identifier: MIT
// Tests of the `trivcon` program (apps/): run as a separate process through run_cli(), on meshes
// generated here and written with trivcon::write_obj / write_ply, and on the shared real meshes.
// Expected values come from the library (build_topology, compute_geometry, run in this process), from
// the generators' formulas, and from ../shared/data/meshes/SOURCES.md.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <map>
#include <nlohmann/json.hpp>
#include <random>
#include <regex>
#include <set>
#include <sstream>
#include <string>
#include <vector>

#include "support.h"
#include "trivcon/blas.h"
#include "trivcon/tuned_process.h"
#include "trivcon/generate.h"
#include "trivcon/geometry.h"
#include "trivcon/io.h"
#include "trivcon/topology.h"

namespace trivcon {
namespace {

namespace fs = std::filesystem;
using nlohmann::json;
using namespace test;  // run_cli, q, save, slurp, … (tests/support.h)

const std::string kError = "trivcon: error: ";

// Runs `trivcon info PATH --json [--cycles]`, expecting success, and parses stdout.
json info_json(const std::string& path, bool cycles = false) {
  const CommandResult r = run_cli("info " + q(path) + " --json" + (cycles ? " --cycles" : ""));
  EXPECT_EQ(r.status, 0) << r.err;
  EXPECT_EQ(r.err, "");
  try {
    return json::parse(r.out);
  } catch (const std::exception& e) {
    ADD_FAILURE() << "info --json output is not JSON (" << e.what() << "): " << r.out;
    return json::object();
  }
}

// A failure that must be reported cleanly: status 1, one "trivcon: error: " message naming the problem,
// and (for info and check, which print only at the end) nothing on stdout.
void expect_clean_error(const CommandResult& r, const std::vector<std::string>& parts, const std::string& what) {
  SCOPED_TRACE(what);
  EXPECT_EQ(r.status, 1) << "stderr: " << r.err;
  EXPECT_TRUE(starts_with(r.err, kError)) << r.err;
  EXPECT_EQ(std::count(r.err.begin(), r.err.end(), '\n'), 1) << r.err;
  if (!starts_with(what, "solve")) {
    EXPECT_EQ(r.out, "");
  }
  for (const auto& p : parts) EXPECT_TRUE(contains(r.err, p)) << "stderr lacks '" << p << "': " << r.err;
}

Mesh collinear_face_mesh() {  // flat, face 2 = three collinear points
  Mesh m;
  m.V.resize(5, 3);
  m.V << 0, 0, 0, 1, 0, 0, 2, 0, 0, 1, 1, 0, 1, -1, 0;
  m.F.resize(4, 3);
  m.F << 0, 1, 3, 1, 2, 3, 0, 2, 1, 0, 4, 2;
  return m;
}

Mesh with_extra_vertices(const Mesh& m, int extra) {
  Mesh out = m;
  out.V.conservativeResize(m.V.rows() + extra, 3);
  for (int i = 0; i < extra; ++i) out.V.row(m.V.rows() + i) << 5.0 + i, 5.0, 5.0;
  return out;
}

// ----------------------------------------------------------------------------------------------
// Version and help

TEST(Cli, Version) {
  const CommandResult r = run_cli("--version");
  EXPECT_EQ(r.status, 0);
  // Semantic versioning, MAJOR.MINOR.PATCH: the one version of CMakeLists.txt's project() (CHANGELOG.md).
  EXPECT_EQ(r.out, std::string("trivcon ") + TRIVCON_VERSION + "\n");
  EXPECT_TRUE(std::regex_match(r.out, std::regex("trivcon [0-9]+\\.[0-9]+\\.[0-9]+\n"))) << r.out;
}

// The help ends with the exit statuses, one line each, as the man page's EXIT STATUS shows them.
TEST(Cli, HelpListsTheExitStatuses) {
  const CommandResult r = run_cli("--help");
  EXPECT_EQ(r.status, 0);
  const std::string heading = "\nExit status:\n";
  const size_t at = r.out.find(heading);
  ASSERT_NE(at, std::string::npos) << r.out;
  std::istringstream lines(r.out.substr(at + heading.size()));
  std::vector<int> codes;
  for (std::string line; std::getline(lines, line) && line.rfind("  ", 0) == 0;) codes.push_back(std::stoi(line));
  EXPECT_EQ(codes, (std::vector<int>{0, 1, 2, 3, 4, 70}));
}

TEST(Cli, HelpListsTheSubcommands) {
  const CommandResult r = run_cli("--help");
  EXPECT_EQ(r.status, 0);
  for (const char* s : {"info", "solve", "check"}) EXPECT_TRUE(contains(r.out, s)) << r.out;
}

// ----------------------------------------------------------------------------------------------
// info

TEST(CliInfo, TextOutput) {
  const std::string dir = test::temp_dir("cli_info_text");
  const std::string torus = save(dir, "torus", make_torus(12, 6));
  CommandResult r = run_cli("info " + q(torus));
  ASSERT_EQ(r.status, 0) << r.err;
  EXPECT_EQ(r.err, "");
  EXPECT_TRUE(starts_with(r.out, "mesh " + torus + " (obj)\n")) << r.out;
  EXPECT_TRUE(contains(r.out, "vertices 72, faces 144, edges 216, Euler characteristic 0\n")) << r.out;
  EXPECT_TRUE(contains(r.out, "components 1, boundary loops 0\n")) << r.out;
  EXPECT_TRUE(contains(r.out, "  component 0: faces 144, vertices 72, chi 0, genus 1, boundary loops 0\n")) << r.out;
  EXPECT_TRUE(contains(r.out, "unreferenced vertices 0\n")) << r.out;
  EXPECT_TRUE(contains(r.out, "zero-area faces 0")) << r.out;
  EXPECT_TRUE(contains(r.out, "re-oriented faces 0\n")) << r.out;
  EXPECT_TRUE(contains(r.out, "interior edges with negative cotangent weight ")) << r.out;
  EXPECT_FALSE(contains(r.out, "generator")) << r.out;

  // Two components, one with two boundary loops, binary PLY, with --cycles.
  const std::string both = save(dir, "both", concatenate({make_genus_surface(2, 1), make_annulus(2, 8)}), true);
  r = run_cli("info " + q(both) + " --cycles");
  ASSERT_EQ(r.status, 0) << r.err;
  EXPECT_TRUE(starts_with(r.out, "mesh " + both + " (ply-binary-le)\n")) << r.out;
  EXPECT_TRUE(contains(r.out, "components 2, boundary loops 2\n")) << r.out;
  EXPECT_TRUE(contains(r.out, "  component 0: faces 400, vertices 198, chi -2, genus 2, boundary loops 0\n")) << r.out;
  EXPECT_TRUE(contains(r.out, "  component 1: faces 32, vertices 24, chi 0, genus 0, boundary loops 2\n")) << r.out;
  for (int g = 0; g < 4; ++g) EXPECT_TRUE(contains(r.out, "generator " + std::to_string(g) + ": component 0, ")) << r.out;
  EXPECT_FALSE(contains(r.out, "generator 4")) << r.out;
  EXPECT_TRUE(contains(r.out, "loop 0: component 1, 8 vertices starting at ")) << r.out;
  EXPECT_TRUE(contains(r.out, "loop 1: component 1, 8 vertices starting at ")) << r.out;
}

struct InfoCase {
  std::string name;
  Mesh mesh;
  std::vector<int> genus;  // expected per component
  int loops, chi, unreferenced, reoriented;
};

TEST(CliInfo, JsonMatchesTheLibraryAndTheFormulas) {
  const std::string dir = test::temp_dir("cli_info_json");
  Mesh flipped = make_torus(8, 5);
  for (int f : {3, 17, 40}) std::swap(flipped.F(f, 1), flipped.F(f, 2));
  const std::vector<InfoCase> cases = {
      {"icosphere", make_icosphere(2), {0}, 0, 2, 0, 0},
      {"torus", make_torus(10, 6), {1}, 0, 0, 0, 0},
      {"genus3", make_genus_surface(3, 1), {3}, 0, -4, 0, 0},
      {"disk", make_disk(3, 6), {0}, 1, 1, 0, 0},
      {"annulus", make_annulus(2, 9), {0}, 2, 0, 0, 0},
      {"holed", make_holed_grid(9, 2), {0}, 3, -1, 0, 0},
      {"several", concatenate({make_icosphere(0), make_torus(4, 4), make_genus_surface(2, 1), make_disk(2, 4)}), {0, 1, 2, 0}, 1, 1, 0, 0},
      {"unreferenced", with_extra_vertices(make_icosphere(1), 3), {0}, 0, 2, 3, 0},
      {"flipped", flipped, {1}, 0, 0, 0, 3},
      {"collinear", collinear_face_mesh(), {0}, 1, 1, 0, 0},
  };
  for (const auto& c : cases) {
    for (bool ply : {false, true}) {
      SCOPED_TRACE(c.name + (ply ? " (ply)" : " (obj)"));
      const std::string path = save(dir, c.name, c.mesh, ply);
      const json j = info_json(path);
      const Topology t = build_topology(c.mesh.F, static_cast<int>(c.mesh.V.rows()));
      const Geometry g = compute_geometry(c.mesh.V, t);
      EXPECT_EQ(j["file"], path);
      EXPECT_EQ(j["format"], ply ? "ply-binary-le" : "obj");
      EXPECT_EQ(j["vertices"], c.mesh.V.rows());
      EXPECT_EQ(j["faces"], c.mesh.F.rows());
      EXPECT_EQ(j["edges"], t.num_edges);
      EXPECT_EQ(j["euler_characteristic"], c.chi);
      EXPECT_EQ(j["boundary_loops"], c.loops);
      EXPECT_EQ(j["unreferenced_vertices"], c.unreferenced);
      EXPECT_EQ(j["reoriented_faces"], c.reoriented);
      EXPECT_EQ(j["zero_area_faces"], c.name == "collinear" ? 1 : 0);
      EXPECT_EQ(j["zero_area_faces"], g.zero_area_faces);
      EXPECT_EQ(j["degenerate_faces"], g.degenerate_faces);
      EXPECT_EQ(j["negative_cotan_edges"], g.negative_cotan_edges);
      ASSERT_TRUE(j["components"].is_array());
      ASSERT_EQ(j["components"].size(), c.genus.size());
      int faces = 0;
      for (size_t k = 0; k < c.genus.size(); ++k) {
        const json& cj = j["components"][k];
        const ComponentInfo& info = t.components[k];
        EXPECT_EQ(cj["id"], k);
        EXPECT_EQ(cj["genus"], c.genus[k]);
        EXPECT_EQ(cj["euler_characteristic"], info.euler_characteristic);
        EXPECT_EQ(cj["faces"], info.faces);
        EXPECT_EQ(cj["vertices"], info.vertices);
        EXPECT_EQ(cj["edges"], info.edges);
        EXPECT_EQ(cj["first_face"], info.first_face);
        EXPECT_EQ(cj["boundary_loops"].get<std::vector<int>>(), info.boundary_loops);
        faces += cj["faces"].get<int>();
      }
      EXPECT_EQ(faces, c.mesh.F.rows());
    }
  }
}

TEST(CliInfo, CyclesListGeneratorsAndLoops) {
  const std::string dir = test::temp_dir("cli_info_cycles");
  // Components: genus 2, torus, disk, annulus, genus 3, holed grid with 2 holes.
  const std::vector<Mesh> parts = {make_genus_surface(2, 1), make_torus(9, 5),         make_disk(3, 5),
                                   make_annulus(2, 10),      make_genus_surface(3, 1), make_holed_grid(9, 2)};
  const std::vector<int> genus = {2, 1, 0, 0, 3, 0};
  const Mesh m = concatenate(parts);
  const std::string path = save(dir, "parts", m);
  const json j = info_json(path, true);
  const Topology t = build_topology(m.F, static_cast<int>(m.V.rows()));
  ASSERT_TRUE(j.contains("cycles")) << j.dump();
  const json& gens = j["cycles"]["generators"];
  const json& loops = j["cycles"]["loops"];
  // 2g generators per component, grouped by component in order.
  std::vector<int> per_component(parts.size(), 0);
  int last_component = -1;
  for (size_t i = 0; i < gens.size(); ++i) {
    const json& g = gens[i];
    EXPECT_EQ(g["id"], i);
    const int c = g["component"];
    ASSERT_TRUE(c >= 0 && c < static_cast<int>(parts.size()));
    EXPECT_GE(c, last_component) << "generators not grouped by component";
    last_component = c;
    ++per_component[c];
    EXPECT_TRUE(std::isfinite(g["levi_civita_holonomy"].get<double>()));
    // The faces visited form a closed walk over faces of that component, consecutive faces adjacent.
    const std::vector<int> faces = g["faces"];
    EXPECT_EQ(g["length"], faces.size());
    ASSERT_GE(faces.size(), 2u);
    int not_adjacent = 0, wrong_component = 0;
    for (size_t k = 0; k < faces.size(); ++k) {
      const int a = faces[k], b = faces[(k + 1) % faces.size()];
      wrong_component += t.face_component[a] != c;
      bool shared = false;
      for (int x = 0; x < 3; ++x)
        for (int y = 0; y < 3; ++y) shared |= t.face_edges(a, x) == t.face_edges(b, y);
      not_adjacent += !shared;
    }
    EXPECT_EQ(not_adjacent, 0) << "generator " << i;
    EXPECT_EQ(wrong_component, 0) << "generator " << i;
  }
  for (size_t c = 0; c < parts.size(); ++c) EXPECT_EQ(per_component[c], 2 * genus[c]) << "component " << c;
  // Loops: the topology's loops, with their components and curvatures (flat: outer 2π, holes −2π).
  ASSERT_EQ(loops.size(), t.boundary_loops.size());
  ASSERT_EQ(loops.size(), 1u + 2u + 3u);
  int outer = 0, holes = 0;
  for (size_t l = 0; l < loops.size(); ++l) {
    EXPECT_EQ(loops[l]["id"], l);
    EXPECT_EQ(loops[l]["vertices"].get<std::vector<int>>(), t.boundary_loops[l]);
    EXPECT_EQ(loops[l]["length"], t.boundary_loops[l].size());
    EXPECT_EQ(loops[l]["component"], t.vertex_component[t.boundary_loops[l][0]]);
    const double k = loops[l]["curvature"];
    if (std::abs(k - 2 * kPi) < 1e-9)
      ++outer;
    else if (std::abs(k + 2 * kPi) < 1e-9)
      ++holes;
    else
      ADD_FAILURE() << "loop " << l << " curvature " << k << " is neither 2π nor −2π on a flat mesh";
  }
  EXPECT_EQ(outer, 3);  // disk, annulus outer, holed grid outer
  EXPECT_EQ(holes, 3);  // annulus inner, two holes
  // Without --cycles there is no "cycles" key.
  EXPECT_FALSE(info_json(path).contains("cycles"));
}

// ----------------------------------------------------------------------------------------------
// info on the shared real meshes (SOURCES.md)

struct SharedExpected {
  const char* file;
  int V, F, CC, BL, chi, largest_genus, other_genus_zero, iso;
  bool reoriented;
};

// Test names show the file, not the struct's bytes.
void PrintTo(const SharedExpected& x, std::ostream* os) { *os << x.file; }

const SharedExpected kValid[] = {
    {"spot.obj", 2930, 5856, 1, 0, 2, 0, 0, 0, false},
    {"bunny_closed.obj", 1839, 3674, 1, 0, 2, 0, 0, 0, false},
    {"armadillo.obj", 43243, 86482, 1, 0, 2, 0, 0, 0, false},
    {"torus.obj", 2304, 4608, 1, 0, 0, 1, 0, 0, false},
    {"kitten.off", 2500, 5000, 1, 0, 0, 1, 0, 0, false},
    {"bob_small.ply", 250, 500, 1, 0, 0, 1, 0, 0, false},
    {"rocker-arm.obj", 10044, 20088, 1, 0, 0, 1, 0, 0, false},
    {"eight.off", 5544, 11092, 1, 0, -2, 2, 0, 0, false},
    {"fertility.off", 4494, 9000, 1, 0, -6, 4, 0, 0, false},
    {"Input_wheel.off", 27925, 55890, 1, 0, -20, 11, 0, 0, false},
    {"cheese.off", 8629, 17786, 1, 0, -264, 133, 0, 0, false},
    {"bun_zipper.ply", 35947, 69451, 1, 5, -3, 0, 0, 1113, false},
    {"face.obj", 25905, 51712, 1, 1, 1, 0, 0, 0, false},
    {"camelhead.off", 11381, 22704, 1, 1, 1, 0, 0, 0, false},
    {"half-torus.obj", 300, 576, 1, 2, 0, 0, 0, 0, false},
    {"circle.obj", 5201, 10240, 1, 1, 1, 0, 0, 0, false},
    {"dragon_vrip.ply", 437645, 871414, 151, 407, -197, 46, 150, 0, false},
    {"capsule.obj", 5252, 10200, 1, 1, 1, 0, 0, 0, false},
    {"bones.off", 2154, 4204, 26, 0, 52, 0, 25, 0, false},
    {"blobby-shuffled.off", 2027, 4050, 1, 0, 2, 0, 0, 0, true},
};

class CliSharedInfo : public ::testing::TestWithParam<SharedExpected> {};

TEST_P(CliSharedInfo, JsonCountsMatchSources) {
  TRIVCON_REQUIRE_SHARED();
  const SharedExpected& x = GetParam();
  const json j = info_json(test::shared_mesh(x.file));
  ASSERT_TRUE(j.contains("components")) << j.dump();
  EXPECT_EQ(j["vertices"], x.V);
  EXPECT_EQ(j["faces"], x.F);
  EXPECT_EQ(j["components"].size(), static_cast<size_t>(x.CC));
  EXPECT_EQ(j["boundary_loops"], x.BL);
  EXPECT_EQ(j["euler_characteristic"], x.chi);
  EXPECT_EQ(j["unreferenced_vertices"], x.iso);
  if (x.reoriented) {
    EXPECT_GT(j["reoriented_faces"].get<int>(), 0);
  } else {
    EXPECT_EQ(j["reoriented_faces"], 0);
  }
  size_t largest = 0;
  int loops = 0, chi = 0;
  for (size_t c = 0; c < j["components"].size(); ++c) {
    if (j["components"][c]["faces"] > j["components"][largest]["faces"]) largest = c;
    loops += static_cast<int>(j["components"][c]["boundary_loops"].size());
    chi += j["components"][c]["euler_characteristic"].get<int>();
  }
  EXPECT_EQ(j["components"][largest]["genus"], x.largest_genus);
  int others_zero = 0;
  for (size_t c = 0; c < j["components"].size(); ++c)
    if (c != largest) others_zero += j["components"][c]["genus"] == 0;
  EXPECT_EQ(others_zero, x.other_genus_zero);
  EXPECT_EQ(loops, x.BL);
  EXPECT_EQ(chi, x.chi);
}

INSTANTIATE_TEST_SUITE_P(CliShared, CliSharedInfo, ::testing::ValuesIn(kValid),
                         [](const auto& info) { return test::test_name_of(info.param.file); });

TEST(CliSharedMeshes, BrokenMeshesFailCleanly) {
  TRIVCON_REQUIRE_SHARED();
  const std::pair<const char*, const char*> broken[] = {
      {"truck.obj", "non-manifold edge (413, 431) shared by 3 faces (1390, 1555, 4726)"},
      {"teapot.obj", "non-manifold vertex 66: its faces form 2 separate fans"},
      {"dragon_vrip_res3.ply", "non-manifold edge (6, 7) shared by 4 faces (6, 11, 12, 15)"},
      {"hourglass_ico.obj", "non-manifold vertex 22: its faces form 2 separate fans"},
      {"mobius.obj", "non-orientable component 0 ("},
  };
  for (const auto& [file, message] : broken) {
    const CommandResult r = run_cli("info --no-repair " + q(test::shared_mesh(file)) + " --json");
    expect_clean_error(r, {message}, file);
  }
}

// ----------------------------------------------------------------------------------------------
// Bad input: exit status 1, "trivcon: error: ", the problem named, never a crash

TEST(CliBadInput, MissingEmptyGarbage) {
  const std::string dir = test::temp_dir("cli_bad_input");
  expect_clean_error(run_cli("info " + q(dir + "/nonexistent.obj")),
                     {"cannot open '" + dir + "/nonexistent.obj'", "No such file or directory"}, "nonexistent");
  for (const char* ext : {".obj", ".off", ".ply", ".obj.gz"}) {
    const std::string empty = dir + "/empty" + ext;
    write_text(empty, "");
    expect_clean_error(run_cli("info " + q(empty)), {"empty" + std::string(ext)}, std::string("empty ") + ext);
  }
  expect_clean_error(run_cli("info " + q(dir + "/empty.obj")), {"empty.obj: empty file"}, "empty obj message");
  // Random bytes under every extension.
  std::mt19937 rng(42);
  for (int trial = 0; trial < 4; ++trial)
    for (const char* ext : {".obj", ".off", ".ply", ".obj.gz"}) {
      std::string bytes(200 + 300 * trial, '\0');
      for (char& c : bytes) c = static_cast<char>(rng());
      const std::string path = dir + "/garbage" + std::to_string(trial) + ext;
      write_text(path, bytes);
      expect_clean_error(run_cli("info " + q(path)), {"garbage" + std::to_string(trial) + ext}, path);
    }
  // A directory and an unknown extension.
  expect_clean_error(run_cli("info " + q(dir)), {"unknown mesh format"}, "directory");
  write_text(dir + "/mesh.vtk", "# vtk DataFile Version 2.0\n");
  expect_clean_error(run_cli("info " + q(dir + "/mesh.vtk")), {"mesh.vtk", "unknown mesh format"}, "vtk");
  write_text(dir + "/mesh.stl", "solid x\n");
  expect_clean_error(run_cli("info " + q(dir + "/mesh.stl")), {"mesh.stl", "file ends before 'endsolid'"}, "stl");
}

TEST(CliBadInput, TruncatedFiles) {
  const std::string dir = test::temp_dir("cli_truncated");
  // A face line cut short names the file and the line.
  write_text(dir + "/cut.obj", "v 0 0 0\nv 1 0 0\nv 0 1 0\nf 1 2");
  expect_clean_error(run_cli("info " + q(dir + "/cut.obj")), {"cut.obj:4:", "face 0 has 2 corners"}, "cut face");
  write_text(dir + "/cutv.obj", "v 0 0 0\nv 1 0 0\nv 0 1 0\nf 1 2 3\nv 0 1");
  expect_clean_error(run_cli("info " + q(dir + "/cutv.obj")), {"cutv.obj:5:"}, "cut vertex");
  // An OBJ cut at many places: either still a valid (smaller) mesh, or a clean error.
  const std::string full = dir + "/full.obj";
  write_obj(full, make_icosphere(1).V, make_icosphere(1).F);
  const std::string text = slurp(full);
  for (size_t cut = 1; cut < text.size(); cut += text.size() / 23) {
    const std::string path = dir + "/cut" + std::to_string(cut) + ".obj";
    write_text(path, text.substr(0, cut));
    const CommandResult r = run_cli("info " + q(path));
    EXPECT_TRUE(r.status == 0 || r.status == 1) << "cut at " << cut << ": status " << r.status << " " << r.err;
    if (r.status == 1) {
      EXPECT_TRUE(starts_with(r.err, kError + path)) << r.err;
    }
  }
  // A binary PLY cut anywhere after the header is always an error naming the file.
  const std::string ply = dir + "/full.ply";
  write_ply(ply, make_icosphere(1).V, make_icosphere(1).F);
  const std::string bytes = slurp(ply);
  for (size_t cut = bytes.size() - 1; cut > bytes.size() / 2; cut -= bytes.size() / 17) {
    const std::string path = dir + "/cut" + std::to_string(cut) + ".ply";
    write_text(path, bytes.substr(0, cut));
    expect_clean_error(run_cli("info " + q(path)), {"cut" + std::to_string(cut) + ".ply"}, "ply cut at " + std::to_string(cut));
  }
}

TEST(CliBadInput, InvalidMeshes) {
  const std::string dir = test::temp_dir("cli_invalid");
  write_text(dir + "/nm.obj", "v 0 0 0\nv 1 0 0\nv 0 1 0\nv 0 0 1\nv 1 1 1\nf 1 2 3\nf 2 1 4\nf 1 2 5\n");
  expect_clean_error(run_cli("info --no-repair " + q(dir + "/nm.obj")), {"non-manifold edge (0, 1) shared by 3 faces (0, 1, 2)"}, "nm edge");
  write_text(dir + "/bowtie.obj", "v 0 0 0\nv 1 0 0\nv 0 1 0\nv -1 0 0\nv 0 -1 0\nf 1 2 3\nf 1 4 5\n");
  expect_clean_error(run_cli("info --no-repair " + q(dir + "/bowtie.obj")), {"non-manifold vertex 0: its faces form 2 separate fans"}, "bow tie");
  const std::string mobius = save(dir, "mobius", mobius_strip(9));
  expect_clean_error(run_cli("info " + q(mobius)), {"non-orientable component 0 (", "cannot be oriented consistently across edge ("},
                     "mobius");
  write_text(dir + "/nan.obj", "v 0 0 0\nv nan 0 0\nv 0 1 0\nf 1 2 3\n");
  expect_clean_error(run_cli("info " + q(dir + "/nan.obj")), {"nan.obj:2:", "non-finite coordinate in vertex 1"}, "nan");
  write_text(dir + "/range.obj", "v 0 0 0\nv 1 0 0\nv 0 1 0\nf 1 2 4\n");
  expect_clean_error(run_cli("info " + q(dir + "/range.obj")), {"range.obj:4:", "out of range"}, "index out of range");
  write_text(dir + "/repeat.obj", "v 0 0 0\nv 1 0 0\nv 0 1 0\nf 1 1 2\n");
  expect_clean_error(run_cli("info --no-repair " + q(dir + "/repeat.obj")), {"repeat.obj:4:", "repeated vertex"}, "repeated vertex");
  expect_clean_error(run_cli("info " + q(dir + "/repeat.obj")), {"no faces left: every face has a repeated vertex (first: face 0, (0, 0, 1))"},
                     "repeated vertex, repaired");
  // The same through solve and check.
  expect_clean_error(run_cli("solve --no-repair " + q(dir + "/nm.obj")), {"non-manifold edge (0, 1)"}, "solve nm");
  expect_clean_error(run_cli("solve " + q(mobius)), {"non-orientable component 0 ("}, "solve mobius");
  expect_clean_error(run_cli("check --no-repair " + q(dir + "/nm.obj") + " " + q(dir + "/none.txt")), {"non-manifold edge (0, 1)"}, "check nm");
}

// ----------------------------------------------------------------------------------------------
// Usage errors (CLI11): non-zero status, CLI11's message, no crash

TEST(CliUsage, MissingAndUnknownArguments) {
  struct Case {
    std::string args, message;
  };
  const std::vector<Case> cases = {
      {"", "A subcommand is required"},
      {"info", "mesh is required"},
      {"solve", "mesh is required"},
      {"check", "is required"},
      {"bogus", "A subcommand is required"},
      {"info a.obj b.obj", "The following argument was not expected: b.obj"},
      {"info --frobnicate a.obj", "--frobnicate"},
      {"solve a.obj --weights foo", "--weights: foo not in {cotan,unit}"},
      {"solve a.obj --solver lu", "--solver"},
      {"solve a.obj -N 0", "--symmetry: Value 0 not in range 1 to 1000"},
      {"solve a.obj -N x", "--symmetry"},
      {"solve a.obj --field-out", "--field-out"},
  };
  for (const auto& c : cases) {
    SCOPED_TRACE("trivcon " + c.args);
    const CommandResult r = run_cli(c.args);
    EXPECT_NE(r.status, 0);
    EXPECT_NE(r.status, 1) << "usage errors are CLI11's, not trivcon::Error";
    EXPECT_LT(r.status, 128) << "crashed";
    EXPECT_TRUE(contains(r.err, c.message)) << r.err;
    EXPECT_TRUE(contains(r.err, "Run with --help for more information.")) << r.err;
  }
}

// ----------------------------------------------------------------------------------------------
// solve and check

struct SolveFiles {
  std::string dir, mesh, field_txt, field_raw, field_ply, connection, lines, report;
};

SolveFiles sphere_files(const std::string& name) {
  SolveFiles s;
  s.dir = test::temp_dir(name);
  s.mesh = save(s.dir, "sphere", make_uv_sphere(8, 12));  // vertex 0 north pole, 85 south pole
  s.field_txt = s.dir + "/field.txt";
  s.field_raw = s.dir + "/field.rawfield";
  s.field_ply = s.dir + "/field.ply";
  s.connection = s.dir + "/connection.txt";
  s.lines = s.dir + "/lines.obj";
  s.report = s.dir + "/report.json";
  return s;
}

TEST(CliSolve, SphereWithTwoPoles) {
  const SolveFiles s = sphere_files("cli_solve_sphere");
  const Mesh m = make_uv_sphere(8, 12);
  const int nV = static_cast<int>(m.V.rows()), nF = static_cast<int>(m.F.rows()), south = nV - 1;
  ASSERT_EQ(south, 85);
  const Topology t = build_topology(m.F, nV);
  const std::string sings = " --sing 0:1 --sing 85:1";
  CommandResult r = run_cli("solve " + q(s.mesh) + sings + " --field-out " + q(s.field_txt) + " --connection-out " + q(s.connection) +
                            " --lines-out " + q(s.lines) + " --report " + q(s.report));
  ASSERT_EQ(r.status, 0) << r.err;
  EXPECT_EQ(r.err, "");
  EXPECT_TRUE(contains(r.out, "86 vertices, 168 faces, 1 component(s), chi 2, 0 generator(s), 0 boundary loop(s)")) << r.out;
  EXPECT_TRUE(contains(r.out, "N 1, 2 singular vertices")) << r.out;
  EXPECT_TRUE(contains(r.out, "indices read back from the field: 0 differ from the prescription")) << r.out;

  // Report.
  const json rep = json::parse(slurp(s.report));
  EXPECT_EQ(rep["N"], 1);
  EXPECT_EQ(rep["mesh"]["vertices"], nV);
  EXPECT_EQ(rep["mesh"]["faces"], nF);
  EXPECT_EQ(rep["mesh"]["euler_characteristic"], 2);
  EXPECT_TRUE(rep["energy"].is_number());
  EXPECT_TRUE(std::isfinite(rep["energy"].get<double>()));
  EXPECT_GT(rep["energy"].get<double>(), 0);
  EXPECT_LE(rep["residuals"]["max_vertex"].get<double>(), 1e-9);
  EXPECT_LE(rep["residuals"]["transport_mismatch"].get<double>(), 1e-9);
  EXPECT_TRUE(rep["indices"]["field_mismatches"].is_array());
  EXPECT_TRUE(rep["indices"]["field_mismatches"].empty()) << rep["indices"].dump();
  EXPECT_EQ(rep["indices"]["singular_vertices"], 2);
  EXPECT_EQ(rep["singularities"], json::parse(R"([{"vertex": 0, "index": "1"}, {"vertex": 85, "index": "1"}])"));
  EXPECT_TRUE(rep["generators"].empty());
  EXPECT_TRUE(rep["boundary_loops"].empty());
  // The ordering and symbolic factorization ran on the second thread (trivcon/design.h) and were used.
  // The wall time of the preparation covers the first thread's stages one after the other, and the
  // cycles of the second (the constructor waits for them).
  EXPECT_EQ(rep["symbolic_analysis"], "concurrent");
  EXPECT_EQ(rep["ordering"], "AMD");
  const json& sec = rep["seconds"];
  for (const char* k : {"topology", "geometry", "cycles", "plan", "analysis", "setup", "setup_analysis_wait", "prepare"})
    EXPECT_GE(sec[k].get<double>(), 0.0) << k;
  auto seconds = [&](const char* k) { return sec[k].get<double>(); };
  EXPECT_GE(seconds("prepare"), seconds("topology") + seconds("geometry") + seconds("plan") + seconds("setup") - 1e-6);
  EXPECT_GE(seconds("prepare"), seconds("topology") + seconds("cycles") + seconds("setup") - 1e-6);
  // The BLAS kernels (trivcon/blas.h): the program re-executes itself rather than run OpenBLAS's generic
  // kernels on a CPU that supports better ones, unless OPENBLAS_CORETYPE chooses for it.
  ASSERT_TRUE(rep["blas_kernels"].is_string());
  if (std::getenv("OPENBLAS_CORETYPE") == nullptr && !native_blas_kernels().empty()) {
    EXPECT_NE(rep["blas_kernels"].get<std::string>(), "Prescott");
  }
  // Huge pages (trivcon/tuned_process.h): asked for where the kernel gives them only on request, unless the
  // environment chooses (GLIBC_TUNABLES naming glibc.malloc.hugetlb).
  EXPECT_EQ(rep["huge_pages"]["kernel"], transparent_huge_pages_mode());
  const char* tunables = std::getenv("GLIBC_TUNABLES");
  if (std::string(transparent_huge_pages_mode()) == "madvise" && (!tunables || !std::strstr(tunables, "glibc.malloc.hugetlb"))) {
    EXPECT_EQ(rep["huge_pages"]["malloc"], true);
  }
  // OpenBLAS's idle threads sleep at once (trivcon/tuned_process.h), unless OPENBLAS_THREAD_TIMEOUT chooses.
  if (const char* timeout = std::getenv("OPENBLAS_THREAD_TIMEOUT")) {
    EXPECT_EQ(rep["blas_thread_timeout"], timeout);
  } else if (!blas_kernels().empty()) {
    EXPECT_EQ(rep["blas_thread_timeout"], "4");
  }
  // OpenMP's idle threads sleep after microseconds (trivcon/tuned_process.h), unless GOMP_SPINCOUNT or
  // OMP_WAIT_POLICY chooses.
  if (const char* spin = std::getenv("GOMP_SPINCOUNT")) {
    EXPECT_EQ(rep["openmp_spin_count"], spin);
  } else if (std::getenv("OMP_WAIT_POLICY") == nullptr) {
    EXPECT_EQ(rep["openmp_spin_count"], "10000");
  } else {
    EXPECT_TRUE(rep["openmp_spin_count"].is_null());
  }

  // Field text: header, one unit vector per face.
  const std::vector<std::string> field = lines_of(slurp(s.field_txt));
  ASSERT_GE(field.size(), 3u);
  EXPECT_TRUE(starts_with(field[0], "# trivcon field")) << field[0];
  EXPECT_EQ(field[1], "# N 1");
  EXPECT_EQ(field[2], "# faces 168");
  int rows = 0, bad = 0;
  for (const auto& line : field) {
    if (line.empty() || line[0] == '#') continue;
    std::istringstream in(line);
    double x, y, z;
    bad += !(in >> x >> y >> z) || std::abs(std::sqrt(x * x + y * y + z * z) - 1) > 1e-9;
    ++rows;
  }
  EXPECT_EQ(rows, nF);
  EXPECT_EQ(bad, 0);
  // Connection: "i j x" per interior edge, sorted by (i, j).
  std::vector<std::pair<int, int>> edges;
  for (const auto& line : lines_of(slurp(s.connection))) {
    if (line.empty() || line[0] == '#') continue;
    std::istringstream in(line);
    int i, j;
    double x;
    ASSERT_TRUE(in >> i >> j >> x) << line;
    EXPECT_LT(i, j);
    EXPECT_TRUE(std::isfinite(x));
    edges.emplace_back(i, j);
  }
  EXPECT_EQ(static_cast<int>(edges.size()), t.num_edges);
  EXPECT_TRUE(std::is_sorted(edges.begin(), edges.end()));
  EXPECT_TRUE(contains(slurp(s.connection), "# N 1\n"));
  // Lines: F segments (N = 1).
  int v_lines = 0, l_lines = 0;
  for (const auto& line : lines_of(slurp(s.lines))) {
    v_lines += starts_with(line, "v ");
    l_lines += starts_with(line, "l ");
  }
  EXPECT_EQ(v_lines, 2 * nF);
  EXPECT_EQ(l_lines, nF);

  // The other field formats, then check each field.
  for (const std::string& f : {s.field_raw, s.field_ply}) {
    r = run_cli("solve " + q(s.mesh) + sings + " -q --field-out " + q(f));
    ASSERT_EQ(r.status, 0) << r.err;
    EXPECT_EQ(r.out, "") << "-q prints nothing on success";
    EXPECT_TRUE(fs::exists(f));
  }
  {
    const std::vector<std::string> raw = lines_of(slurp(s.field_raw));
    ASSERT_FALSE(raw.empty());
    EXPECT_EQ(raw[0], "1 168");
  }
  for (const std::string& f : {s.field_txt, s.field_raw, s.field_ply}) {
    SCOPED_TRACE(f);
    r = run_cli("check " + q(s.mesh) + " " + q(f) + sings);
    EXPECT_EQ(r.status, 0) << r.err;
    EXPECT_TRUE(contains(r.out, "N 1: 2 singular vertices in the field\n")) << r.out;
    EXPECT_TRUE(contains(r.out, "  vertex 0 index 1\n")) << r.out;
    EXPECT_TRUE(contains(r.out, "  vertex 85 index 1\n")) << r.out;
    EXPECT_TRUE(contains(r.out, "matches the prescription")) << r.out;
    r = run_cli("check " + q(s.mesh) + " " + q(f) + sings + " --json");
    ASSERT_EQ(r.status, 0) << r.err;
    const json j = json::parse(r.out);
    EXPECT_EQ(j["singularities"], json::parse(R"([{"vertex": 0, "index": "1"}, {"vertex": 85, "index": "1"}])"));
    EXPECT_TRUE(j["differences"].empty());
    // A wrong prescription: status 4, the differences listed.
    r = run_cli("check " + q(s.mesh) + " " + q(f) + " --sing 0:1 --sing 40:1");
    EXPECT_EQ(r.status, 4) << r.err;
    EXPECT_TRUE(contains(r.out, "2 vertices differ from the prescription")) << r.out;
    EXPECT_TRUE(contains(r.out, "  vertex 40: found 0, prescribed 1\n")) << r.out;
    EXPECT_TRUE(contains(r.out, "  vertex 85: found 1, prescribed 0\n")) << r.out;
    r = run_cli("check " + q(s.mesh) + " " + q(f) + " --sing 0:2 --json");
    EXPECT_EQ(r.status, 4) << r.err;
    EXPECT_EQ(json::parse(r.out)["differences"].size(), 2u);
  }
}

TEST(CliSolve, CrossFieldOnACubeFromASingularityFile) {
  const std::string dir = test::temp_dir("cli_solve_cube");
  const Mesh m = make_cube_sphere(4, true);
  const std::string mesh = save(dir, "cube", m, true);
  const Topology t = build_topology(m.F, static_cast<int>(m.V.rows()));
  // The 8 corners are the valence-3 vertices.
  std::string sings = "# the cube's corners\n";
  std::vector<int> corners;
  for (int v = 0; v < t.num_vertices; ++v)
    if (t.vertex_edge_offsets[v + 1] - t.vertex_edge_offsets[v] == 3) corners.push_back(v);
  ASSERT_EQ(corners.size(), 8u);
  for (int v : corners) sings += std::to_string(v) + " 1/4\n";
  write_text(dir + "/corners.txt", sings);
  const std::string field = dir + "/cross.txt", report = dir + "/report.json";
  CommandResult r =
      run_cli("solve " + q(mesh) + " -N 4 -s " + q(dir + "/corners.txt") + " -q --field-out " + q(field) + " --report " + q(report));
  ASSERT_EQ(r.status, 0) << r.err;
  const json rep = json::parse(slurp(report));
  EXPECT_EQ(rep["N"], 4);
  EXPECT_EQ(rep["singularities"].size(), 8u);
  EXPECT_EQ(rep["singularities"][0]["index"], "1/4");
  EXPECT_LE(rep["residuals"]["max_vertex"].get<double>(), 1e-9);
  EXPECT_TRUE(rep["indices"]["field_mismatches"].empty());
  // check takes N from the file.
  r = run_cli("check " + q(mesh) + " " + q(field) + " -s " + q(dir + "/corners.txt"));
  EXPECT_EQ(r.status, 0) << r.err;
  EXPECT_TRUE(contains(r.out, "N 4: 8 singular vertices in the field\n")) << r.out;
  EXPECT_TRUE(contains(r.out, "index 1/4\n")) << r.out;
}

#ifdef TRIVCON_WITH_SUITESPARSE
TEST(CliSolve, FactorizationCholmodGivesTheSameConnection) {
  // --factorization cholmod (CHOLMOD's own numeric factorization) against the default, on a genus-2
  // surface (cycle rows): the same x on every edge to round-off, the same energy line.
  const std::string dir = test::temp_dir("cli_solve_factorization");
  const std::string mesh = save(dir, "genus2", make_genus_surface(2, 2), true);
  std::string conn[2], energy[2];
  int k = 0;
  for (const char* f : {"own", "cholmod"}) {
    const std::string path = dir + "/conn_" + f + ".txt";
    const CommandResult r = run_cli("solve " + q(mesh) +
                                    " -N 4 --sing 0:-1/4 --sing 40:-1/4 --sing 80:-1/4 --sing 120:-1/4 --sing 160:-1/4"
                                    " --sing 200:-1/4 --sing 240:-1/4 --sing 280:-1/4 --factorization " +
                                    f + " --connection-out " + q(path));
    ASSERT_EQ(r.status, 0) << r.err;
    conn[k] = slurp(path);
    energy[k] = r.out.substr(r.out.find("energy "), r.out.find('\n', r.out.find("energy ")) - r.out.find("energy "));
    ++k;
  }
  EXPECT_EQ(energy[0].substr(0, 14), energy[1].substr(0, 14));
  std::istringstream a(conn[0]), b(conn[1]);
  std::string la, lb;
  int lines = 0;
  double worst = 0;
  while (std::getline(a, la) && std::getline(b, lb)) {
    if (la.empty() || la[0] == '#') continue;
    int i = 0, j = 0, i2 = 0, j2 = 0;
    double x = 0, y = 0;
    std::istringstream(la) >> i >> j >> x;
    std::istringstream(lb) >> i2 >> j2 >> y;
    ASSERT_EQ(i, i2);
    ASSERT_EQ(j, j2);
    worst = std::max(worst, std::abs(x - y));
    ++lines;
  }
  EXPECT_GT(lines, 1000);
  EXPECT_LE(worst, 1e-10);
}
#else
TEST(CliSolve, FactorizationCholmodIsRefusedWithoutCholmod) {
  const std::string dir = test::temp_dir("cli_solve_factorization");
  const std::string mesh = save(dir, "genus2", make_genus_surface(2, 2), true);
  const CommandResult r = run_cli("solve " + q(mesh) + " -N 4 --factorization cholmod");
  EXPECT_NE(r.status, 0);
  EXPECT_TRUE(contains(r.err, "the cholmod factorization needs CHOLMOD")) << r.err;
  EXPECT_TRUE(contains(r.err, "GPL")) << r.err;
}
#endif

TEST(CliSolve, TorusWithoutSingularities) {
  const std::string dir = test::temp_dir("cli_solve_torus");
  const std::string mesh = save(dir, "torus", make_torus(16, 8));
  const std::string report = dir + "/report.json";
  const CommandResult r = run_cli("solve " + q(mesh) + " -q --report " + q(report));
  ASSERT_EQ(r.status, 0) << r.err;
  const json rep = json::parse(slurp(report));
  EXPECT_EQ(rep["generators"].size(), 2u);
  for (const auto& g : rep["generators"]) EXPECT_EQ(g["chosen"], true);
  EXPECT_LE(rep["residuals"]["max_vertex"].get<double>(), 1e-9);
  EXPECT_LE(rep["residuals"]["max_cycle"].get<double>(), 1e-9);
  EXPECT_TRUE(rep["singularities"].empty());
  EXPECT_EQ(rep["ordering"], "CAMD");
  EXPECT_EQ(rep["symbolic_analysis"], "concurrent");
  // With a fixed face the system has a path row: the set-up analyses its own.
  const CommandResult f = run_cli("solve " + q(mesh) + " -q --fix 0:angle=0 --fix 100:angle=0.5 --report " + q(report));
  ASSERT_EQ(f.status, 0) << f.err;
  const json fixed = json::parse(slurp(report));
  EXPECT_EQ(fixed["symbolic_analysis"], "in set-up");
  EXPECT_EQ(fixed["fixed"]["faces"], 2);
  EXPECT_LE(fixed["residuals"]["max_cycle"].get<double>(), 1e-9);
}

// Runs a solve that must fail with exactly `message` and leave none of its outputs behind.
void expect_solve_error(const std::string& dir, const std::string& args, const std::string& message) {
  SCOPED_TRACE("trivcon solve " + args);
  const std::vector<std::string> outputs = {dir + "/out.txt",  dir + "/out.rawfield", dir + "/out.ply",
                                            dir + "/conn.txt", dir + "/lines.obj",    dir + "/report.json"};
  for (const auto& o : outputs) fs::remove(o);
  const CommandResult r = run_cli("solve " + args + " --field-out " + q(outputs[0]) + " --connection-out " + q(outputs[3]) +
                                  " --lines-out " + q(outputs[4]) + " --report " + q(outputs[5]));
  EXPECT_EQ(r.status, 1);
  EXPECT_EQ(r.err, kError + message + "\n");  // (stdout may hold the mesh summary printed before the solve)
  for (const auto& o : {outputs[0], outputs[3], outputs[4], outputs[5]}) EXPECT_FALSE(fs::exists(o)) << o << " left behind";
  // The other field formats too.
  for (const auto& o : {outputs[1], outputs[2]}) {
    const CommandResult r2 = run_cli("solve " + args + " --field-out " + q(o));
    EXPECT_EQ(r2.status, 1);
    EXPECT_FALSE(fs::exists(o)) << o << " left behind";
  }
  // No temporary files either.
  for (const auto& entry : fs::directory_iterator(dir)) {
    const std::string name = entry.path().filename().string();
    EXPECT_TRUE(name == "sphere.obj" || name == "disk.obj" || name == "extra.obj" || name == "torus.obj" || name.find("sing") == 0)
        << "unexpected file " << name;
  }
}

TEST(CliSolve, ErrorsWithExactMessagesAndNoOutputs) {
  const std::string dir = test::temp_dir("cli_solve_errors");
  const std::string sphere = save(dir, "sphere", make_uv_sphere(8, 12));                        // 86 vertices, χ = 2
  const std::string disk = save(dir, "disk", make_disk(3, 6));                                  // 37 vertices; 19..36 on the boundary
  const std::string extra = save(dir, "extra", with_extra_vertices(make_uv_sphere(8, 12), 2));  // 86, 87 unreferenced
  const std::string torus = save(dir, "torus", make_torus(8, 6));
  const std::string S = q(sphere);

  expect_solve_error(dir, S + " --sing 0:1 --sing 86:1", "singular vertex 86 out of range (mesh has 86 vertices)");
  expect_solve_error(dir, S + " --sing 0:1 --sing 1000000:1", "singular vertex 1000000 out of range (mesh has 86 vertices)");
  expect_solve_error(dir, S + " --sing 0:1 --sing -1:1", "--sing -1:1: malformed vertex id '-1'");
  expect_solve_error(dir, q(extra) + " --sing 0:1 --sing 86:1", "singular vertex 86 is not used by any face");
  expect_solve_error(dir, q(disk) + " --sing 36:1",
                     "singular vertex 36 is on boundary loop 0: a boundary vertex has no dual cycle (set the loop's index with "
                     "--boundary instead, or align the boundary, --align-boundary, to make the vertex a corner of it)");
  expect_solve_error(dir, S + " -N 4 --sing 0:1/3 --sing 85:5/3",
                     "--sing 0:1/3: index 1/3 is not a multiple of 1/4 (use -N to change the symmetry)");
  expect_solve_error(dir, S + " --sing 0:1/2 --sing 85:3/2",
                     "--sing 0:1/2: index 1/2 is not a multiple of 1/1 (use -N to change the symmetry)");
  expect_solve_error(dir, S + " --sing 0:1", "the indices on component 0 sum to 1, but Gauss-Bonnet needs its Euler characteristic 2");
  expect_solve_error(dir, S + " -N 4 --sing 0:1/4",
                     "the indices on component 0 sum to 1/4, but Gauss-Bonnet needs its Euler characteristic 2");
  expect_solve_error(dir, S, "the indices on component 0 sum to 0, but Gauss-Bonnet needs its Euler characteristic 2");
  expect_solve_error(dir, S + " --sing 0:1 --sing 0:1", "--sing 0:1: vertex 0 is given twice");
  expect_solve_error(dir, S + " --sing 0", "--sing '0': expected ID:INDEX, e.g. 12:1/4");
  expect_solve_error(dir, S + " --sing 0:x --sing 85:1", "--sing 0:x: malformed index 'x' (expected an integer or a fraction p/q, q > 0)");
  expect_solve_error(dir, q(disk) + " --boundary 1:1", "boundary loop 1 out of range (the mesh has 1 boundary loops)");
  expect_solve_error(dir, q(torus) + " --generator 2:1", "generator 2 out of range (the mesh has 2 generators)");
  expect_solve_error(dir, S + " --sing 0:1 --sing 85:1 --root-face 168", "root face 168 out of range (mesh has 168 faces)");
  expect_solve_error(dir, S + " --sing 0:1 --sing 85:1 --root-angle 1", "--root-angle given without a matching --root-face");

  // Singularity files: file and line in the message.
  const std::string s1 = dir + "/sing1.txt", s2 = dir + "/sing2.txt", s3 = dir + "/sing3.txt", s4 = dir + "/sing4.sings";
  write_text(s1, "# poles\n0 1\n\n85 x\n");
  write_text(s2, "0 1\n85 1 extra\n");
  write_text(s3, "0 1\n0 1\n");
  write_text(s4, "1 3\n0 1\n85 1\n");
  expect_solve_error(dir, S + " -s " + q(s1), s1 + ":4: malformed index 'x' (expected an integer or a fraction p/q, q > 0)");
  expect_solve_error(dir, S + " -s " + q(s2), s2 + ":2: expected two fields, got '85 1 extra'");
  expect_solve_error(dir, S + " -s " + q(s3), s3 + ":2: vertex 0 is given twice");
  expect_solve_error(dir, S + " -s " + q(s4), s4 + ": the header announces 3 singularities but the file lists 2");
  expect_solve_error(dir, S + " -s " + q(dir + "/sing_missing.txt"),
                     "cannot open '" + dir + "/sing_missing.txt': No such file or directory");
  // A vertex both in a file and on the command line.
  write_text(dir + "/sing5.txt", "0 1\n");
  expect_solve_error(dir, S + " -s " + q(dir + "/sing5.txt") + " --sing 0:1", "--sing 0:1: vertex 0 is given twice");

  // The valid versions of the same succeed (so the failures above are about the one thing named).
  EXPECT_EQ(run_cli("solve " + S + " -q --sing 0:1 --sing 85:1").status, 0);
  EXPECT_EQ(run_cli("solve " + q(disk) + " -q --sing 0:1").status, 0);
  write_text(dir + "/sing6.sings", "1 2\n0 1\n85 1\n");
  EXPECT_EQ(run_cli("solve " + S + " -q -s " + q(dir + "/sing6.sings")).status, 0);
  EXPECT_EQ(run_cli("solve " + S + " -q -N 4 --sing 0:1/2 --sing 85:3/2").status, 0);
}

// A solve that fails while writing its outputs must not leave the outputs it had already written.
// (All outputs are staged and renamed into place together, apps/cmd_solve.cpp.)
TEST(CliSolve, NoPartialOutputsWhenALaterWriteFails) {
  const SolveFiles s = sphere_files("cli_solve_partial");
  const CommandResult r = run_cli("solve " + q(s.mesh) + " -q --sing 0:1 --sing 85:1 --field-out " + q(s.field_txt) + " --lines-out " +
                                  q(s.dir + "/no/such/dir/lines.obj"));
  EXPECT_EQ(r.status, 1);
  EXPECT_TRUE(contains(r.err, "cannot write")) << r.err;
  EXPECT_FALSE(fs::exists(s.field_txt)) << "field written although the solve failed";
}

TEST(CliCheck, Errors) {
  const SolveFiles s = sphere_files("cli_check_errors");
  ASSERT_EQ(run_cli("solve " + q(s.mesh) + " -q --sing 0:1 --sing 85:1 --field-out " + q(s.field_txt)).status, 0);
  // A field for another mesh: the face count does not match.
  const std::string other = save(s.dir, "other", make_icosphere(1));
  expect_clean_error(run_cli("check " + q(other) + " " + q(s.field_txt) + " --sing 0:1 --sing 11:1"), {"field.txt"}, "face count");
  expect_clean_error(run_cli("check " + q(s.mesh) + " " + q(s.dir + "/missing.txt") + " --sing 0:1 --sing 85:1"), {"missing.txt"},
                     "missing field");
  write_text(s.dir + "/bad.txt", "# trivcon field\n1 2\n");
  expect_clean_error(run_cli("check " + q(s.mesh) + " " + q(s.dir + "/bad.txt") + " --sing 0:1 --sing 85:1"), {"bad.txt"}, "bad field");
  expect_clean_error(run_cli("check " + q(s.mesh) + " " + q(s.field_txt) + " --sing 86:1"), {"singular vertex 86 out of range"},
                     "vertex out of range");
}

}  // namespace
}  // namespace trivcon
