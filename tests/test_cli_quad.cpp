// SPDX-License-Identifier: MIT
// `trivcon quad`, run as a separate process: the quad mesh file read back and checked on its own (only quads,
// each edge in at most two, χ, boundary loops, valences at the written singularities), the report, --uv-out,
// --sing-out, PLY output, usage errors.
#include <cmath>
#include <fstream>
#include <map>
#include <nlohmann/json.hpp>
#include <set>
#include <sstream>

#include "support.h"
#include "trivcon/generate.h"
#include "trivcon/io.h"
#include "trivcon/request.h"

namespace trivcon {
namespace {

using test::perforated_plate;
using test::run_cli;
using test::slurp;
using test::temp_file;

std::string mesh_file(const Mesh& m, const std::string& name) {
  const std::string path = temp_file(name);
  write_obj(path, m.V, m.F);
  return path;
}

// A quad mesh file read back as its quads (each polygon of the file fanned into two triangles by the reader).
struct QuadFile {
  MatrixX3d V;
  std::vector<std::array<int, 4>> quads;
};

QuadFile read_quads(const std::string& path) {
  const MeshData m = read_mesh(path);
  QuadFile out{m.V, {}};
  EXPECT_EQ(static_cast<size_t>(m.F.rows()), 2 * static_cast<size_t>(m.polygon_count)) << "a polygon that is not a quad";
  for (int p = 0; p < m.polygon_count; ++p) {
    EXPECT_EQ(m.polygon_of_triangle[2 * p], p);
    EXPECT_EQ(m.polygon_of_triangle[2 * p + 1], p);
    out.quads.push_back({m.F(2 * p, 0), m.F(2 * p, 1), m.F(2 * p, 2), m.F(2 * p + 1, 2)});
  }
  return out;
}

struct Census {
  int euler = 0, boundary_edges = 0, over_shared_edges = 0;
  std::map<int, int> interior_valence;  // vertex -> valence, for vertices on no boundary edge
  std::map<int, int> boundary_valence;  // vertex -> valence, for vertices on a boundary edge
};

// χ = V − E + F, edges in more than two quads, valences of interior vertices: from the quads alone.
Census census(const QuadFile& q) {
  std::map<std::pair<int, int>, int> edge_uses;
  for (const auto& quad : q.quads)
    for (int k = 0; k < 4; ++k) ++edge_uses[std::minmax(quad[k], quad[(k + 1) % 4])];
  Census c;
  std::set<int> used, on_boundary;
  std::map<int, int> valence;
  for (const auto& [e, uses] : edge_uses) {
    used.insert(e.first), used.insert(e.second);
    ++valence[e.first], ++valence[e.second];
    if (uses == 1) ++c.boundary_edges, on_boundary.insert(e.first), on_boundary.insert(e.second);
    if (uses > 2) ++c.over_shared_edges;
  }
  c.euler = static_cast<int>(used.size()) - static_cast<int>(edge_uses.size()) + static_cast<int>(q.quads.size());
  for (auto [v, n] : valence) (on_boundary.count(v) ? c.boundary_valence : c.interior_valence)[v] = n;
  return c;
}

// A report's map without folds within the distortion goal, and its quads at the singularities, none inverted and
// every corner convex with a sine above 0.3.
void expect_clean_and_convex(const nlohmann::json& j) {
  EXPECT_EQ(j["param"]["flipped_faces"], 0);
  EXPECT_EQ(j["param"]["degenerate_faces"], 0);
  EXPECT_LE(j["param"]["mean_distortion"].get<double>(), 1.5);
  EXPECT_EQ(j["quad"]["singular_mismatches"], 0);
  EXPECT_EQ(j["quad"]["inverted_quads"], 0);
  EXPECT_EQ(j["quad"]["nonconvex_quads"], 0);
  EXPECT_GT(j["quad"]["min_scaled_jacobian"].get<double>(), 0.3);
}

// A cube: 8 singularities of +1/4 at the corners, the only irregular vertices, of valence 3, each at the
// position of its corner; the report agrees with the file; the map and the singularities are written.
TEST(CliQuad, CubeGivesEightValenceThreeCornersAndNothingElseIrregular) {
  const Mesh m = make_cube_sphere(8, false);
  const std::string mesh = mesh_file(m, "cube.obj"), out = temp_file("q.obj"), report = temp_file("r.json"), uv = temp_file("uv.obj"),
                    sings = temp_file("s.sing");
  const auto r = run_cli("quad " + mesh + " --auto --target-faces 400 -o " + out + " --report " + report + " --uv-out " + uv + " --sing-out " + sings);
  ASSERT_EQ(r.status, 0) << r.err;
  EXPECT_NE(r.out.find("irregular vertices: 8 (singularities: 8 of valence 3), exactly at the singularities"), std::string::npos) << r.out;
  const QuadFile q = read_quads(out);
  const Census c = census(q);
  EXPECT_EQ(c.euler, 2);
  EXPECT_EQ(c.boundary_edges, 0);
  EXPECT_EQ(c.over_shared_edges, 0);
  std::vector<int> irregular;
  for (auto [v, n] : c.interior_valence)
    if (n != 4) {
      EXPECT_EQ(n, 3) << "vertex " << v;
      irregular.push_back(v);
    }
  ASSERT_EQ(irregular.size(), 8u);
  // Each irregular vertex is at a written singularity's position.
  const std::map<int, std::string> written = test::read_singularity_texts(sings);
  EXPECT_EQ(written.size(), 8u);
  for (int v : irregular) {
    double nearest = 1e300;
    for (const auto& [s, index] : written) nearest = std::min(nearest, (q.V.row(v) - m.V.row(s)).norm());
    EXPECT_LT(nearest, 1e-9) << "quad vertex " << v;
  }
  for (const auto& [s, index] : written) EXPECT_EQ(index, "1/4");
  // Quads near the target, the report the file's numbers.
  EXPECT_GT(q.quads.size(), 280u);
  EXPECT_LT(q.quads.size(), 520u);
  const nlohmann::json j = nlohmann::json::parse(slurp(report));
  EXPECT_EQ(j["quad"]["quads"].get<size_t>(), q.quads.size());
  EXPECT_EQ(j["quad"]["irregular_vertices"], 8);
  EXPECT_EQ(j["quad"]["singular_mismatches"], 0);
  EXPECT_EQ(j["quad"]["euler_characteristic"], 2);
  EXPECT_TRUE(j["quad"]["manifold"].get<bool>());
  EXPECT_TRUE(j["quad"]["problems"].empty());
  EXPECT_GT(j["quad"]["min_scaled_jacobian"].get<double>(), 0.3);
  EXPECT_TRUE(j["param"]["seamless"].get<bool>());
  EXPECT_EQ(read_corner_uv(uv, m.F).rows(), m.F.rows());
  // The map step's time encloses the kept map's stages and the kept field's solve (one clock, nested).
  double stages = 0;
  for (const auto& [stage, seconds] : j["param"]["seconds"].items()) stages += seconds.get<double>();
  EXPECT_GE(j["seconds"]["map"].get<double>(), stages);
  EXPECT_GE(j["seconds"]["map"].get<double>(), j["seconds"]["field"].get<double>());
}

// A square plate with holes, its boundary aligned: the quads end on every boundary loop (as many loops, same χ),
// and binary PLY output reads back the same.
TEST(CliQuad, HoledPlateEndsOnItsBoundaryLoops) {
  const Mesh m = make_holed_grid(24, 3);
  const std::string mesh = mesh_file(m, "plate.obj"), out = temp_file("q.ply"), report = temp_file("r.json");
  const auto r = run_cli("quad " + mesh + " --align-boundary --auto --target-faces 600 -o " + out + " --report " + report);
  ASSERT_EQ(r.status, 0) << r.err;
  const QuadFile q = read_quads(out);
  const Census c = census(q);
  const nlohmann::json j = nlohmann::json::parse(slurp(report));
  EXPECT_EQ(c.euler, j["euler_characteristic"].get<int>());
  EXPECT_EQ(j["quad"]["boundary_loops"], j["boundary_loops"]);
  EXPECT_GT(c.boundary_edges, 0);
  EXPECT_EQ(c.over_shared_edges, 0);
  int irregular = 0;
  for (auto [v, n] : c.interior_valence) irregular += n != 4;
  EXPECT_EQ(irregular, j["quad"]["irregular_vertices"].get<int>());
  EXPECT_EQ(j["quad"]["singular_mismatches"], 0);
}

// A scan whose map folded around clustered singularities before the untangling (armadillo, --auto, 10,000
// quads): closed, manifold, χ 2, and every irregular vertex within 3 quad edges of a written singularity of the
// matching index (valence 4 − 4k), from the files alone.
// `quad MESH ARGS` on a shared mesh, checked from the files alone: exit 0, χ and boundary edges as given, no edge in
// more than two quads, every irregular interior vertex within 3 quad edges of a written singularity of index
// (4 − valence)/4, and as many irregular vertices as singularities.
void expect_quads_at_the_singularities(const std::string& name, const std::string& args, int euler, bool closed) {
  const std::string out = temp_file("q.obj"), sing = temp_file("q.sing"), report = temp_file("r.json");
  const auto r = run_cli("quad " + test::shared_mesh(name) + " " + args + " -o " + out + " --sing-out " + sing + " --report " + report);
  ASSERT_EQ(r.status, 0) << name << ": " << r.err;
  const QuadFile q = read_quads(out);
  const Census c = census(q);
  EXPECT_EQ(c.euler, euler) << name;
  if (closed) {
    EXPECT_EQ(c.boundary_edges, 0) << name;
  }
  EXPECT_EQ(c.over_shared_edges, 0) << name;
  const MeshData input = read_mesh(test::shared_mesh(name));
  std::map<int, int> index;  // singular vertex -> index in quarters
  for (const auto& [v, text] : test::read_singularity_texts(sing)) {
    const size_t slash = text.find('/');  // "p/q" (reduced: 1/2 is two quarters) or a whole number
    const int p = std::stoi(text.substr(0, slash)), den = slash == std::string::npos ? 1 : std::stoi(text.substr(slash + 1));
    ASSERT_EQ(4 % den, 0) << text;
    index[v] = p * (4 / den);
  }
  const nlohmann::json j = nlohmann::json::parse(slurp(report));
  const double h = j["param"]["edge_length"].get<double>();
  int irregular = 0;
  for (auto [v, n] : c.interior_valence) {
    if (n == 4) continue;
    ++irregular;
    bool near = false;
    for (auto [s, k] : index)
      if (4 - k == n && (q.V.row(v) - input.V.row(s)).norm() <= 3 * h) near = true;
    EXPECT_TRUE(near) << name << ": quad vertex " << v << " of valence " << n << " has no singularity of index " << (4 - n)
                      << "/4 within 3 quad edges";
  }
  EXPECT_EQ(irregular, static_cast<int>(index.size())) << name;
}

TEST(CliQuad, ArmadilloIsClosedWithItsIrregularVerticesAtTheSingularities) {
  TRIVCON_REQUIRE_SHARED();
  expect_quads_at_the_singularities("armadillo.obj", "--auto --target-faces 10000", 2, true);
}

// A map the untangling left fold-free but winding wrong (armadillo, --auto, 4,000 quads: a −1/2's ring wound
// once too few and its neighbour's once too often, so the quad mesh had an 8-sided hole and two irregular
// vertices off the singularities): the region is untangled again from its least squares.
TEST(CliQuad, ArmadilloAt4000QuadsWindsRightAroundEveryVertex) {
  TRIVCON_REQUIRE_SHARED();
  expect_quads_at_the_singularities("armadillo.obj", "--auto --target-faces 4000", 2, true);
}

// A detailed scan at a coarse scale (armadillo, 86k faces, 1,000 quads): the 103 singularities found fold the map
// (43 folded faces and wrong windings); placed again (relaxed, which folds more, then with pairs cancelled within 2
// and then 4 units), the map is clean and the quads are at the singularities written.
TEST(CliQuad, ArmadilloAt1000QuadsIsPlacedAgainUntilTheMapIsClean) {
  TRIVCON_REQUIRE_SHARED();
  expect_quads_at_the_singularities("armadillo.obj", "--auto --target-faces 1000", 2, true);
}

// A scanned CAD part with its creases at 45° (rocker-arm): 223 sharp edges, most in dashes of one or two edges and
// knots of faces sharp on all three edges. The map leaves those out (report features.loose_edges) and follows the
// rest: the quads are at the singularities, and every kept sharp edge lies on an iso-line.
TEST(CliQuad, RockerArmFollowsItsCreasesWithoutTheirNoise) {
  TRIVCON_REQUIRE_SHARED();
  expect_quads_at_the_singularities("rocker-arm.obj", "--auto --align-features 45 --target-faces 3000", 0, true);
  const std::string report = temp_file("r.json");
  ASSERT_EQ(run_cli("quad " + test::shared_mesh("rocker-arm.obj") + " --auto --align-features 45 --target-faces 3000 -o " + temp_file("q.obj") +
                    " --report " + report)
                .status,
            0);
  const nlohmann::json j = nlohmann::json::parse(slurp(report));
  EXPECT_GT(j["features"]["loose_edges"].get<int>(), 100);
  EXPECT_GT(j["features"]["sharp_edges"].get<int>(), 30);
  EXPECT_EQ(j["param"]["unaligned_edges"], 0);
  EXPECT_TRUE(j["quad"]["problems"].empty());
}

// A clean map whose quad mesh fails: bunny at 1,000 quads, three +1/4 around the tail gave one quad turned over
// against the surface; `quad` places again (pairs cancelled within 2 units) and the quad mesh passes every check.
TEST(CliQuad, BunnyAt1000QuadsIsPlacedAgainWhenAQuadTurnsOver) {
  TRIVCON_REQUIRE_SHARED();
  expect_quads_at_the_singularities("bunny_closed.obj", "--auto --target-faces 1000", 2, true);
}

// A plate with 27 round holes (radius 0.15 in unit cells), its boundary aligned, at 1,000 quads (about 6 quad edges
// around a hole): with every fixed-face path's turn chosen with the cycles (the dense route, 1,055 paths) the
// field's fans along the holes turn as the holes do, and the first placement's map is clean, within the goal, and
// every quad convex (rounded path by path, 34 fans turned a quarter off: dozens of folds, ratio 2.7, and after the
// relaxed placements still 12 quads with a reflex corner at a jog of a hole's iso-line). The boundary is aligned
// without being asked.
TEST(CliQuad, PlateWith27HolesIsCleanAtTheFirstPlacement) {
  const Mesh plate = perforated_plate(9, 3, 8, 6, 0.15);
  const std::string mesh = mesh_file(plate, "plate27.obj"), out = temp_file("q.obj"), report = temp_file("r.json");
  // No --align-boundary: with --auto, quad aligns the boundary unasked (quads end on it only so).
  const auto r = run_cli("quad " + mesh + " --auto --target-faces 1000 -o " + out + " --report " + report);
  ASSERT_EQ(r.status, 0) << r.err;
  EXPECT_NE(r.out.find("boundary: aligned"), std::string::npos) << r.out;
  const nlohmann::json j = nlohmann::json::parse(slurp(report));
  EXPECT_EQ(j["boundary_loops"], 28);
  EXPECT_EQ(j["align_boundary"], true);
  EXPECT_NEAR(j["quad"]["quads"].get<double>(), 1000, 300);
  EXPECT_EQ(j["placement"]["placements"], 1);
  EXPECT_EQ(j["placement"]["retried_maps"], 0);  // clean without the near-miss retries
  EXPECT_EQ(j["placement"]["relaxed"], false);
  expect_clean_and_convex(j);
  const QuadFile q = read_quads(out);
  const Census c = census(q);
  EXPECT_EQ(c.euler, -26);
  EXPECT_EQ(c.over_shared_edges, 0);
  int irregular = 0;
  for (auto [v, n] : c.interior_valence) irregular += n != 4;
  EXPECT_EQ(irregular, 108);  // 4 × −1/4 per hole, valence 5
  EXPECT_EQ(r.out.find("placement:"), std::string::npos) << r.out;
  // A search that ends at its first map says nothing of it.
  EXPECT_EQ(r.out.find("search:"), std::string::npos) << r.out;
  EXPECT_EQ(j["search"]["maps"], 1);
  EXPECT_EQ(j["search"]["stopped"], false);
}

// A plate with 8 round holes (radius 0.2 in unit cells) meshed on a triangle lattice, at 80 quads (about 4 quad
// edges around a hole): the −1/4 the smoothest field puts beside each rim sit a fraction of a unit from it, where
// the map has no integer point off the rim's iso-line, and the placements without corners keep folds or quads
// with reflex corners. Moved onto the rims as corners of the boundary (AutoOptions::onto_boundary), the map is
// clean and the quads convex, one irregular interior vertex left (a −2/4 in the middle, valence 6). --sing-out
// lists the corners as boundary vertices with their index; given back with -s and the boundary aligned, they make
// the same field and map; without the boundary aligned they are refused, naming the vertex.
TEST(CliQuad, SingularitiesBesideRoundHolesBecomeCornersOfTheirRims) {
  const std::string mesh = mesh_file(test::lattice_plate(4, 2, 0.2, 0.05), "lattice.obj"), out = temp_file("q.obj"), report = temp_file("r.json");
  const std::string sing = temp_file("s.txt");
  const auto r = run_cli("quad " + mesh + " --auto --target-faces 80 -o " + out + " --report " + report + " --sing-out " + sing);
  ASSERT_EQ(r.status, 0) << r.err;
  EXPECT_NE(r.out.find("those beside the boundary moved onto it as corners"), std::string::npos) << r.out;
  const nlohmann::json j = nlohmann::json::parse(slurp(report));
  EXPECT_EQ(j["boundary_loops"], 9);
  // The search's steps, printed as they end: the first placement's map with its problems, then the others.
  const int maps = j["search"]["maps"].get<int>();
  EXPECT_GT(maps, j["placement"]["placements"].get<int>());  // with retries and other scales
  EXPECT_EQ(j["search"]["stopped"], false);
  EXPECT_NE(r.out.find("\nsearch: map"), std::string::npos) << r.out;
  EXPECT_NE(r.out.find(" (placement the first): " + std::to_string(j["placement"]["first_problems"].get<int>()) + " problems"), std::string::npos)
      << r.out;
  // The last step: the placement with corners, clean, which ends the search.
  EXPECT_NE(r.out.find(std::to_string(maps) + " (placement the singularities found, those beside the boundary moved onto it as corners): 0 problems"),
            std::string::npos)
      << r.out;
  EXPECT_TRUE(j["placement"]["onto_boundary"].get<bool>());
  EXPECT_GT(j["placement"]["first_problems"].get<int>(), 0);
  expect_clean_and_convex(j);
  EXPECT_NEAR(j["quad"]["quads"].get<double>(), 80, 24);
  const QuadFile q = read_quads(out);
  const Census c = census(q);
  EXPECT_EQ(c.euler, -7);
  EXPECT_EQ(c.over_shared_edges, 0);
  // The rims' corners: boundary vertices with four edges (three quads: a concave corner of the plate), about four
  // per hole.
  int concave = 0;
  for (auto [v, edges] : c.boundary_valence) concave += edges == 4;
  EXPECT_GE(concave, 8 * 3);

  // The file: the interior singularities and the corners, each corner a boundary vertex.
  const MeshData plate = read_mesh(mesh);
  const Topology t = build_topology(plate.F, static_cast<int>(plate.V.rows()));
  IndexPrescription written;
  written.N = 4;
  read_singularities(sing, written);
  std::set<std::pair<int, std::string>> cones;
  for (const auto& k : j["singularities"]) cones.insert({k["vertex"].get<int>(), k["index"].get<std::string>()});
  int corners = 0;
  for (auto [v, n] : written.vertex) {
    if (t.is_boundary_vertex(v)) ++corners;
    else EXPECT_TRUE(cones.count({v, std::to_string(n) + "/4"})) << v;
  }
  EXPECT_GE(corners, 8 * 3);
  EXPECT_EQ(static_cast<int>(written.vertex.size()) - corners, static_cast<int>(cones.size()));
  ASSERT_EQ(static_cast<int>(j["corners"].size()), corners);
  for (const auto& k : j["corners"]) EXPECT_EQ(written.vertex.at(k["vertex"].get<int>()), -1);
  // `solve` takes the file with the boundary aligned and writes it back the same.
  const std::string sing2 = temp_file("s2.txt");
  const auto solved = run_cli("solve " + mesh + " -N 4 -s " + sing + " --align-boundary --sing-out " + sing2);
  ASSERT_EQ(solved.status, 0) << solved.err;
  EXPECT_NE(solved.out.find("boundary: " + std::to_string(corners) + " boundary vertices given an index are corners of the aligned boundary"),
            std::string::npos)
      << solved.out;
  EXPECT_EQ(slurp(sing2), slurp(sing));
  // Given back at the kept map's edge length: the same map.
  const std::string out2 = temp_file("q2.obj"), report2 = temp_file("r2.json");
  std::ostringstream length;
  length.precision(17);
  length << j["param"]["edge_length"].get<double>();
  const auto back = run_cli("quad " + mesh + " -s " + sing + " --align-boundary --edge-length " + length.str() + " -o " + out2 + " --report " + report2);
  ASSERT_EQ(back.status, 0) << back.err;
  const nlohmann::json k = nlohmann::json::parse(slurp(report2));
  expect_clean_and_convex(k);
  EXPECT_EQ(k["quad"]["quads"], j["quad"]["quads"]);
  EXPECT_EQ(k["singularities"], j["singularities"]);
  EXPECT_EQ(slurp(out2), slurp(out));
  // With --search-maps 1 the search stops after the first placement's maps (with the other sizings' where its own
  // has problems), problems and all, and says so.
  const auto bounded = run_cli("quad " + mesh + " --auto --target-faces 80 --search-maps 1 -o " + out2 + " --report " + report2);
  EXPECT_EQ(bounded.status, 3) << bounded.err;
  const nlohmann::json b = nlohmann::json::parse(slurp(report2));
  const int first = b["param"]["attempts"].get<int>();
  EXPECT_EQ(b["search"]["maps"], first);
  EXPECT_EQ(b["search"]["max_maps"], 1);
  EXPECT_EQ(b["search"]["stopped"], true);
  EXPECT_EQ(b["placement"]["placements"], 1);
  EXPECT_EQ(b["param"]["flipped_faces"].get<int>() + b["param"]["degenerate_faces"].get<int>() + b["param"]["winding_errors"].get<int>() +
                static_cast<int>(b["quad"]["problems"].size()) > 0,
            true);
  EXPECT_NE(bounded.out.find(" (placement the first): "), std::string::npos) << bounded.out;
  EXPECT_NE(bounded.out.find("search: stopped after " + std::to_string(first) + (first == 1 ? " map" : " maps") +
                             " (the bound given); the best of them kept\n"),
            std::string::npos)
      << bounded.out;
  EXPECT_NE(bounded.out.find(" s in all, the search stopped by --search-maps after " + std::to_string(first) + " maps\n"), std::string::npos)
      << bounded.out;
  const auto quiet = run_cli("quad " + mesh + " --auto --target-faces 80 --search-maps 1 -q -o " + out2);
  EXPECT_EQ(quiet.status, 3) << quiet.err;
  EXPECT_EQ(quiet.out, "");  // -q: no search lines either
  // Without the boundary aligned a boundary vertex carries no index.
  const auto refused = run_cli("quad " + mesh + " -s " + sing + " --edge-length 1 -o " + out2);
  EXPECT_EQ(refused.status, 1) << refused.err;
  EXPECT_NE(refused.err.find("is on boundary loop"), std::string::npos) << refused.err;
  EXPECT_NE(refused.err.find("or align the boundary, --align-boundary, to make the vertex a corner of it)"), std::string::npos) << refused.err;
}

// The placement is made again only with --auto and no --auto-cancel, and says so in the report (bones at 500
// quads: 26 closed components, the smallest of one or two squares, every map folds).
TEST(CliQuad, PlacedAgainOnlyWhenTheCancelDistanceIsTheProgramsOwn) {
  TRIVCON_REQUIRE_SHARED();
  const std::string out = temp_file("q.obj"), report = temp_file("r.json");
  for (const std::string extra : {"", " --auto-cancel 2"}) {
    const auto r = run_cli("quad " + test::shared_mesh("bones.off") + " --auto --target-faces 500 -o " + out + " --report " + report + extra);
    ASSERT_EQ(r.status, 3) << extra << ": " << r.err;  // the map folds either way (bones of two squares)
    const nlohmann::json j = nlohmann::json::parse(slurp(report));
    const int placements = j["placement"]["placements"].get<int>();
    if (extra.empty()) {
      // The first, relaxed, cancelled within 2 and 4 units, and those relaxed; none moved onto feature lines from
      // further or onto flat sectors (no sharp edges).
      EXPECT_EQ(placements, 6);
      EXPECT_EQ(j["placement"]["onto_features_units"].get<double>(), kMapOntoFeatures);
      EXPECT_FALSE(j["placement"]["onto_flat_sectors"].get<bool>());
      EXPECT_GT(j["placement"]["first_problems"].get<int>(), j["param"]["flipped_faces"].get<int>() + j["param"]["degenerate_faces"].get<int>());
      EXPECT_NE(r.out.find("placement: the singularities found gave"), std::string::npos) << r.out;
    } else {
      EXPECT_EQ(placements, 1);
      EXPECT_EQ(j["placement"]["cancel_units"].get<double>(), 0.0);
      EXPECT_EQ(j["placement"]["onto_features_units"].get<double>(), 0.0);
      EXPECT_EQ(r.out.find("placement:"), std::string::npos) << r.out;
    }
  }
}

// Meshes that failed before the gathering of close negative singularities (face: two −1/4 a third of a unit
// apart folded the map), the spreading of close positive ones and the relaxation of inverted quads (camelhead,
// bones: quads turned over on fold-free maps).
TEST(CliQuad, FaceCamelheadAndBonesGiveValidQuads) {
  TRIVCON_REQUIRE_SHARED();
  expect_quads_at_the_singularities("face.obj", "--auto --align-boundary --target-faces 10000", 1, false);
  expect_quads_at_the_singularities("camelhead.off", "--auto --align-boundary --target-faces 3000", 1, false);
  expect_quads_at_the_singularities("bones.off", "--auto --target-faces 10000", 52, true);  // 26 closed components
  // At 2,000 quads: two spreads of +1/4 onto one vertex made +1/2 and +3/4 (quads with a vertex twice) on the
  // small bones; at 1,000 the smallest bones, of three squares, get 16 of their own size.
  expect_quads_at_the_singularities("bones.off", "--auto --target-faces 2000", 52, true);
  expect_quads_at_the_singularities("bones.off", "--auto --target-faces 1000", 52, true);
}

// A round disk with its boundary aligned: the smoothest field puts one +1 at the centre, which no quad vertex
// can carry (valence 4 − 4); --auto for a map splits it into four +1/4 a unit around it, and the map's scale
// is corrected so that the quads meet the target although the layout shrinks the interior.
TEST(CliQuad, RoundDiskSplitsItsCentreIntoFourCorners) {
  const Mesh m = make_disk(20, 64);
  const std::string mesh = mesh_file(m, "disk.obj"), out = temp_file("q.obj"), sing = temp_file("q.sing");
  const auto r = run_cli("quad " + mesh + " --auto --align-boundary --target-faces 1000 -o " + out + " --sing-out " + sing);
  ASSERT_EQ(r.status, 0) << r.err;
  const std::map<int, std::string> written = test::read_singularity_texts(sing);
  ASSERT_EQ(written.size(), 4u);
  for (const auto& [v, text] : written) EXPECT_EQ(text, "1/4") << v;
  const QuadFile q = read_quads(out);
  const Census c = census(q);
  EXPECT_EQ(c.euler, 1);
  EXPECT_EQ(c.over_shared_edges, 0);
  int valence3 = 0, other = 0;
  for (auto [v, n] : c.interior_valence) n == 3 ? ++valence3 : n != 4 ? ++other : 0;
  EXPECT_EQ(valence3, 4);
  EXPECT_EQ(other, 0);
  EXPECT_NEAR(static_cast<double>(q.quads.size()), 1000.0, 300.0);
}

// A 20-sided prism (10 stacks, radius 1, height 2.85) whose caps are fans from one rim vertex, as CAD exports
// triangulate flat faces: no inner vertex. Vertex 0 is the fan's apex at the bottom, vertex 200 at the top.
Mesh fan_capped_prism() {
  const int n = 20, stacks = 10;
  Mesh m;
  m.V.resize(n * (stacks + 1), 3);
  for (int s = 0; s <= stacks; ++s)
    for (int k = 0; k < n; ++k) m.V.row(s * n + k) << std::cos(2 * kPi * k / n), 2.85 * s / stacks, std::sin(2 * kPi * k / n);
  std::vector<Eigen::Vector3i> faces;
  for (int s = 0; s < stacks; ++s)
    for (int k = 0; k < n; ++k) {
      const int a = s * n + k, b = s * n + (k + 1) % n;
      faces.emplace_back(a, a + n, b), faces.emplace_back(b, a + n, b + n);
    }
  for (int k = 1; k + 1 < n; ++k) faces.emplace_back(0, k, k + 1), faces.emplace_back(stacks * n, stacks * n + k + 1, stacks * n + k);
  m.F.resize(static_cast<Eigen::Index>(faces.size()), 3);
  for (size_t f = 0; f < faces.size(); ++f) m.F.row(static_cast<Eigen::Index>(f)) = faces[f].transpose();
  return m;
}

// With its rims as feature lines, every face of a fan cap has its three corners on a rim's iso-lines, so the map of
// the input folds whatever the singularities (the cap's faces between the apex and the rim's far side are flat in
// (u, v)). quad splits the fans' 2 × 17 inner edges at their midpoints and maps the refined mesh: the cube-like
// grid of a cylinder (8 corners of valence 3 on the rims), the refined mesh written as the map's file (the
// input's vertices first, with their ids) and each face's input face in the report.
TEST(CliQuad, FanCapsAreRefinedWhereTheMapFolds) {
  const Mesh m = fan_capped_prism();
  const std::string mesh = mesh_file(m, "fan_prism.obj"), out = temp_file("fan_prism_q.obj"), report = temp_file("fan_prism.json"),
                    uv = temp_file("fan_prism_uv.obj"), sings = temp_file("fan_prism.sing");
  const auto r = run_cli("quad " + mesh + " --auto --align-features 30 --target-faces 300 -o " + out + " --report " + report + " --uv-out " + uv +
                         " --sing-out " + sings);
  ASSERT_EQ(r.status, 0) << r.out << r.err;
  EXPECT_NE(r.out.find("refined: 34 edges whose ends lie on aligned lines split at their midpoints (the map folded beside them): 254 vertices, "
                       "504 faces"),
            std::string::npos)
      << r.out;
  EXPECT_NE(r.out.find("irregular vertices: 8 (singularities: 8 of valence 3), exactly at the singularities"), std::string::npos) << r.out;
  const auto j = nlohmann::json::parse(slurp(report));
  EXPECT_EQ(j["refine"]["split_edges"], 34);
  const std::vector<int> parent = j["refine"]["parent_face"];
  ASSERT_EQ(parent.size(), 504u);
  for (int f = 0; f < 504; ++f)  // each face keeps its id for its first child; the others are caps' faces (400 on)
    EXPECT_TRUE(f < 436 ? parent[f] == f : parent[f] >= 400 && parent[f] < 436) << f;
  EXPECT_TRUE(j["quad"]["problems"].empty());
  EXPECT_EQ(j["quad"]["euler_characteristic"], 2);
  EXPECT_EQ(j["param"]["flipped_faces"], 0);
  EXPECT_EQ(j["param"]["degenerate_faces"], 0);
  // The map's file: the refined mesh, its first 220 vertices the input's.
  const MeshData refined = read_mesh(uv);
  ASSERT_EQ(refined.V.rows(), 254);
  ASSERT_EQ(refined.F.rows(), 504);
  EXPECT_EQ((refined.V.topRows(220) - m.V).cwiseAbs().maxCoeff(), 0);
  EXPECT_EQ(read_corner_uv(uv, refined.F).rows(), 504);
  for (const auto& [v, index] : test::read_singularity_texts(sings)) {
    EXPECT_LT(v, 254);
    EXPECT_EQ(index, "1/4");
  }
}

// Singularities of index +1 (one per cap, on the apexes) cannot be mapped without folds, refined or not: no quad
// can be traced. The run says so and fails (exit 3) without writing an empty -o (no reader takes a mesh without
// faces), with the report written; the map keeps the field's scale instead of fitting its cancelled area to the
// target (which made the unit vanish and the (u, v) beyond 2^30).
TEST(CliQuad, MapWithoutQuadsIsAnErrorAndNoEmptyFile) {
  const std::string mesh = mesh_file(fan_capped_prism(), "fan_prism.obj"), out = temp_file("fan_prism_q.obj"),
                    report = temp_file("fan_prism.json");
  const auto r = run_cli("quad " + mesh + " --sing 0:1 --sing 200:1 --align-features 30 --target-faces 300 -o " + out + " --report " + report);
  EXPECT_EQ(r.status, 3) << r.err;
  EXPECT_NE(r.err.find("trivcon: error: the map gave no quads ("), std::string::npos) << r.err;
  EXPECT_NE(r.err.find("'" + out + "' not written"), std::string::npos) << r.err;
  EXPECT_FALSE(std::ifstream(out).good());
  const auto j = nlohmann::json::parse(slurp(report));
  EXPECT_EQ(j["quad"]["quads"], 0);
  EXPECT_GT(j["param"]["flipped_faces"].get<int>() + j["param"]["degenerate_faces"].get<int>(), 0);
  // The field's scale: the unit of 300 squares over the prism's area, not a vanishing one.
  const double edge = j["param"]["edge_length"];
  EXPECT_GT(edge, 0.1);
  EXPECT_LT(edge, 1.0);
}

TEST(CliQuad, UsageErrors) {
  const std::string mesh = mesh_file(make_icosphere(2), "sphere.obj"), out = temp_file("q.obj");
  EXPECT_EQ(run_cli("quad " + mesh + " --auto -o " + out).status, 2);                         // no scale
  EXPECT_EQ(run_cli("quad " + mesh + " --auto --target-faces 100").status, 2);                // no -o
  EXPECT_EQ(run_cli("quad " + mesh + " -N 6 --auto --target-faces 100 -o " + out).status, 2);  // N is 4
  EXPECT_EQ(run_cli("quad " + mesh + " --auto --target-faces 100 --edge-length 1 -o " + out).status, 2);
  const auto split = run_cli("quad " + mesh + " --auto --split-large-turns --target-faces 100 -o " + out);
  EXPECT_EQ(split.status, 2);
  EXPECT_NE(split.err.find("not needed by quad"), std::string::npos) << split.err;
}

// The closed plate 0.3 thick with 27 round holes, sharp edges aligned, at 900 quads: the placement's map keeps
// problems at the edge length asked for, the kept field's map at another edge length (kMapScales, never 1: it is
// kept only when better) is clean, and the quad mesh passes every check with the singularities where they were placed.
TEST(CliQuad, PlateFoldingAtTheTargetIsMappedAtAnotherScale) {
  const std::string mesh = mesh_file(test::extruded(perforated_plate(9, 3, 8, 4, 0.3), 0.3), "plate27x.obj");
  const std::string out = temp_file("q.obj"), report = temp_file("r.json");
  const auto r = run_cli("quad " + mesh + " --auto --align-features 30 --target-faces 900 -o " + out + " --report " + report);
  ASSERT_EQ(r.status, 0) << r.err;
  const nlohmann::json j = nlohmann::json::parse(slurp(report));
  const double scale = j["map_scale"].get<double>();
  EXPECT_TRUE(std::find(std::begin(kMapScales), std::end(kMapScales), scale) != std::end(kMapScales)) << scale;
  EXPECT_NE(r.out.find("scale: the map at the edge length asked for kept problems; made at"), std::string::npos) << r.out;
  EXPECT_EQ(j["param"]["flipped_faces"], 0);
  EXPECT_EQ(j["param"]["winding_errors"], 0);
  EXPECT_LE(j["param"]["mean_distortion"].get<double>(), 1.5);
  EXPECT_EQ(j["quad"]["singular_mismatches"], 0);
  EXPECT_EQ(j["quad"]["inverted_quads"], 0);
  EXPECT_NEAR(j["quad"]["quads"].get<double>(), 900, 0.3 * 900);
  const QuadFile q = read_quads(out);
  const Census c = census(q);
  EXPECT_EQ(c.euler, -52);
  EXPECT_EQ(c.over_shared_edges, 0);
  EXPECT_EQ(j["quad"]["irregular_vertices"], 224);
}

}  // namespace
}  // namespace trivcon
