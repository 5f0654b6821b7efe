// SPDX-License-Identifier: MIT
// `trivcon solve --align-features / --features / --sharp-out / --field-out *.rosy`, `check` on a .rosy and
// `render --align-features`, run as a separate process.
#include <Eigen/Geometry>
#include <cmath>
#include <fstream>
#include <nlohmann/json.hpp>
#include <set>

#include "support.h"
#include "trivcon/features.h"
#include "trivcon/field_io.h"
#include "trivcon/io.h"
#include "trivcon/render.h"

namespace trivcon {
namespace {

using test::q;
using test::run_cli;
using test::slurp;
using test::temp_file;

std::string mesh_file(const Mesh& m, const std::string& name) {
  const std::string path = temp_file(name);
  write_obj(path, m.V, m.F);
  return path;
}

// Every face-edge of a .sharp lies on an edge of the cube [−1, 1]³, and the face's direction in `d` (one row
// per face of `m`) runs along it modulo π/2, from the positions alone.
void expect_along_cube_edges(const Mesh& m, const MatrixX3d& d, const std::vector<SharpFaceEdge>& lines) {
  for (const SharpFaceEdge& s : lines) {
    const Eigen::Vector3d a = m.V.row(m.F(s.face, s.edge)), b = m.V.row(m.F(s.face, (s.edge + 1) % 3));
    EXPECT_GE(((a.array().abs() == 1.0) && (b.array().abs() == 1.0)).count(), 2) << "not on a cube edge";
    const Eigen::Vector3d p0 = m.V.row(m.F(s.face, 0)), p1 = m.V.row(m.F(s.face, 1)), p2 = m.V.row(m.F(s.face, 2));
    const Eigen::Vector3d normal = (p1 - p0).cross(p2 - p0).normalized(), dir = d.row(s.face);
    EXPECT_NEAR(dir.dot(normal), 0, 1e-12);
    const double angle = std::atan2(dir.cross(b - a).dot(normal), dir.dot(b - a));
    EXPECT_LE(std::abs(angle - kPi / 2 * std::round(angle / (kPi / 2))), 1e-9) << "face " << s.face;
  }
}

// The solve of the QuadWild pipeline (docs/howto/other-tools.md) on the flat-faced cube: --auto puts +1/4 at the 8 corners, the .rosy
// has every face beside a cube edge along it (modulo π/2), the .sharp lists both sides of the 12 · n edges.
TEST(CliFeatures, CubePipelineForQuadWild) {
  const int n = 6;
  const Mesh m = make_cube_sphere(n, false);
  const std::string mesh = mesh_file(m, "cube.obj"), rosy = temp_file("m.rosy"), sharp = temp_file("m.sharp");
  const std::string sings = temp_file("m.sing"), report = temp_file("r.json");
  const auto r = run_cli("solve " + q(mesh) + " -N 4 --auto --align-features 30 --field-out " + q(rosy) + " --sharp-out " + q(sharp) +
                         " --sing-out " + q(sings) + " --report " + q(report));
  ASSERT_EQ(r.status, 0) << r.err;
  EXPECT_NE(r.out.find("features: " + std::to_string(12 * n) + " sharp edges (" + std::to_string(12 * n) + " convex)"), std::string::npos)
      << r.out;
  const nlohmann::json j = nlohmann::json::parse(slurp(report));
  EXPECT_TRUE(j["verified"].get<bool>());
  EXPECT_EQ(j["features"]["sharp_edges"], 12 * n);
  EXPECT_EQ(j["features"]["conflicts"].size(), 0u);
  EXPECT_LE(j["fixed"]["max_error"].get<double>(), 1e-9);
  // The 8 corners, +1/4 each, and nothing else.
  std::set<int> corners;
  for (int v : test::vertices_of_valence(m, 3)) corners.insert(v);
  std::set<int> used;
  for (const auto& s : j["singularities"]) {
    EXPECT_EQ(s["index"].get<std::string>(), "1/4");
    used.insert(s["vertex"].get<int>());
  }
  EXPECT_EQ(used, corners);

  const Topology t = test::topo(m);
  const Geometry g = compute_geometry(m.V, t);
  int N = 0;
  const MatrixX3d d = read_field(rosy, static_cast<int>(m.F.rows()), &N);
  EXPECT_EQ(N, 4);
  const std::vector<SharpFaceEdge> lines = read_sharp(sharp, static_cast<int>(m.F.rows()));
  EXPECT_EQ(lines.size(), 2u * 12 * n);
  for (const SharpFaceEdge& s : lines) EXPECT_EQ(s.convex, 1);
  expect_along_cube_edges(m, d, lines);
  // check reads the .rosy and finds the same singularities.
  const auto c = run_cli("check " + q(mesh) + " " + q(rosy) + " -N 4 -s " + q(sings));
  EXPECT_EQ(c.status, 0) << c.out << c.err;
  EXPECT_NE(c.out.find("8 singular vertices in the field"), std::string::npos) << c.out;
  EXPECT_NE(c.out.find("matches the prescription"), std::string::npos) << c.out;
}

// --split-large-turns with feature alignment: the .rosy and the .sharp belong to the refined mesh
// (--mesh-out), the sharp edges found again on it, its fixed faces along them, and a principal matching
// (`check` on the .rosy, as QuadWild reads it) finds exactly the prescription there. A ± pair on
// neighbouring vertices of a cube face makes the field turn by π/4 or more between them.
TEST(CliFeatures, SplitLargeTurnsCarriesTheQuadWildFilesToTheRefinedMesh) {
  const int n = 6;
  const Mesh m = make_cube_sphere(n, false);
  const std::string mesh = mesh_file(m, "split_cube.obj"), refined = temp_file("split_cube.ref.obj");
  const std::string rosy = temp_file("split.rosy"), sharp = temp_file("split.sharp"), sings = temp_file("split.sing"),
                    report = temp_file("split.json");
  // The eight corners +1/4, and a +1/4, −1/4 pair at the middle of the top face and a neighbour of it.
  int middle = -1;
  double best = 1e300, top = m.V.col(2).maxCoeff();
  for (int v = 0; v < m.V.rows(); ++v)
    if (std::abs(m.V(v, 2) - top) < 1e-12 && m.V.row(v).head<2>().norm() < best) best = m.V.row(v).head<2>().norm(), middle = v;
  int neighbour = -1;
  for (int f = 0; f < m.F.rows() && neighbour < 0; ++f)
    for (int k = 0; k < 3; ++k)
      if (m.F(f, k) == middle && std::abs(m.V(m.F(f, (k + 1) % 3), 2) - top) < 1e-12) neighbour = m.F(f, (k + 1) % 3);
  ASSERT_GE(neighbour, 0);
  {
    std::ofstream out(sings);
    for (int v : test::vertices_of_valence(m, 3)) out << v << " 1/4\n";
    out << middle << " 1/4\n" << neighbour << " -1/4\n";
  }
  const auto r = run_cli("solve " + q(mesh) + " -N 4 -s " + q(sings) + " --align-features 30 --split-large-turns --mesh-out " + q(refined) +
                         " --field-out " + q(rosy) + " --sharp-out " + q(sharp) + " --report " + q(report) + " --quiet");
  ASSERT_EQ(r.status, 0) << r.err;
  const nlohmann::json j = nlohmann::json::parse(slurp(report));
  EXPECT_TRUE(j["verified"].get<bool>());
  ASSERT_GE(j["split_large_turns"]["rounds"].size(), 1u) << "no large turn to split: the test lost its point";
  EXPECT_TRUE(j["split_large_turns"]["converged"].get<bool>());
  EXPECT_EQ(j["indices"]["large_turn_edges"], 0);

  const MeshData ref = read_mesh(refined);
  const int nF = static_cast<int>(ref.F.rows());
  EXPECT_GT(nF, m.F.rows());
  // Input ids kept: the refined mesh starts with the input's vertices.
  EXPECT_EQ(ref.V.topRows(m.V.rows()), m.V);
  int N = 0;
  const MatrixX3d d = read_field(rosy, nF, &N);
  EXPECT_EQ(N, 4);
  // The sharp edges of the refined mesh (the cube's edges, split or not), both sides, each face's
  // direction along its edge modulo π/2.
  const Topology t = build_topology(ref.F, static_cast<int>(ref.V.rows()));
  const Geometry g = compute_geometry(ref.V, t);
  const std::vector<int> edges = sharp_edges(ref.V, t, g, 30);
  EXPECT_EQ(j["features"]["sharp_edges"], static_cast<int>(edges.size()));
  const std::vector<SharpFaceEdge> lines = read_sharp(sharp, nF);
  EXPECT_EQ(lines.size(), 2 * edges.size());
  expect_along_cube_edges(ref, d, lines);
  // What a consumer with its own (principal) matching reads on the refined mesh: exactly the prescription.
  const auto c = run_cli("check " + q(refined) + " " + q(rosy) + " -N 4 -s " + q(sings));
  EXPECT_EQ(c.status, 0) << c.out << c.err;
  EXPECT_NE(c.out.find("10 singular vertices in the field"), std::string::npos) << c.out;
  EXPECT_NE(c.out.find("matches the prescription"), std::string::npos) << c.out;
  // On the unrefined mesh the same prescription has a large turn, which the principal matching misreads.
  const std::string plain_rosy = temp_file("split_plain.rosy");
  ASSERT_EQ(run_cli("solve " + q(mesh) + " -N 4 -s " + q(sings) + " --align-features 30 --field-out " + q(plain_rosy) + " --quiet").status, 0);
  const auto c0 = run_cli("check " + q(mesh) + " " + q(plain_rosy) + " -N 4 -s " + q(sings));
  EXPECT_EQ(c0.out.find("matches the prescription"), std::string::npos) << c0.out;
}

TEST(CliFeatures, FeaturesFileWithSingularitiesByHand) {
  // Only the cube's four vertical edges (along y) listed; the corners given by hand.
  const Mesh m = make_cube_sphere(4, false);
  const Topology t = test::topo(m);
  std::string list = "# vertical cube edges\n";
  int listed = 0;
  for (int e = 0; e < t.num_edges; ++e) {
    const Eigen::Vector3d a = m.V.row(t.edge_vertices(e, 0)), b = m.V.row(t.edge_vertices(e, 1));
    if (std::abs(a.x()) == 1 && std::abs(a.z()) == 1 && std::abs(b.x()) == 1 && std::abs(b.z()) == 1 && a.x() == b.x() && a.z() == b.z())
      list += std::to_string(t.edge_vertices(e, 1)) + " " + std::to_string(t.edge_vertices(e, 0)) + "\n", ++listed;
  }
  ASSERT_EQ(listed, 16);
  const std::string mesh = mesh_file(m, "cube.obj"), edges = temp_file("edges.txt"), sings = temp_file("corners.sing");
  test::write_text(edges, list);
  std::string corners;
  for (int v : test::vertices_of_valence(m, 3)) corners += std::to_string(v) + " 1/4\n";
  test::write_text(sings, corners);
  const std::string report = temp_file("r.json"), sharp = temp_file("m.sharp");
  const auto r = run_cli("solve " + q(mesh) + " -N 4 -s " + q(sings) + " --features " + q(edges) + " --sharp-out " + q(sharp) +
                         " --report " + q(report));
  ASSERT_EQ(r.status, 0) << r.err;
  const nlohmann::json j = nlohmann::json::parse(slurp(report));
  EXPECT_TRUE(j["verified"].get<bool>());
  EXPECT_EQ(j["features"]["sharp_edges"], 16);
  EXPECT_EQ(j["fixed"]["faces"], 32);
  EXPECT_EQ(read_sharp(sharp, static_cast<int>(m.F.rows())).size(), 32u);
}

TEST(CliFeatures, CornerConflictsAreReported) {
  // The cube with N = 2: a line field cannot follow two perpendicular edges at once.
  const std::string mesh = mesh_file(make_cube_sphere(4, false), "cube.obj"), report = temp_file("r.json");
  const auto r = run_cli("solve " + q(mesh) + " -N 2 --auto --align-features 30 --report " + q(report));
  ASSERT_EQ(r.status, 0) << r.err;
  EXPECT_NE(r.err.find("24 face-edge pairs at corners where sharp edges meet"), std::string::npos) << r.err;
  const nlohmann::json j = nlohmann::json::parse(slurp(report));
  EXPECT_EQ(j["features"]["conflicts"].size(), 24u);
  EXPECT_EQ(j["features"]["corner_faces"], 24);
}

// The flat-faced cube with a small spike raised from the middle of its top face: the spike's rim is sharp, a
// closed piece of creases a quarter across, apart from the cube's twelve edges.
Mesh spiked_cube(int n) {
  Mesh m = make_cube_sphere(n, false);
  for (int v = 0; v < m.V.rows(); ++v)
    if (m.V(v, 2) == 1.0 && m.V(v, 0) == 0.0 && m.V(v, 1) == 0.0) m.V(v, 2) += 0.15;
  return m;
}

// solve follows every sharp edge unless --feature-min-length is given; with it, the spike's piece (less than the
// length across) is left out and said so. quad leaves it out by itself (one unit of the map) and makes its quads.
TEST(CliFeatures, SmallPiecesOfCreasesAreLeftOutOfAMap) {
  const int n = 16;
  const Mesh m = spiked_cube(n);
  const std::string mesh = mesh_file(m, "spiked.obj"), report = temp_file("r.json"), out = temp_file("q.obj");
  FieldDesigner designer(m.V, m.F);
  const size_t all = sharp_edges(m.V, designer.topology(), designer.geometry(), 30).size(), cube = 12 * n;
  ASSERT_GT(all, cube);
  auto r = run_cli("solve " + q(mesh) + " -N 4 --auto --align-features 30 --report " + q(report));
  ASSERT_EQ(r.status, 0) << r.err;
  nlohmann::json j = nlohmann::json::parse(slurp(report));
  EXPECT_EQ(j["features"]["sharp_edges"].get<size_t>(), all);
  EXPECT_EQ(j["features"]["loose_edges"], 0);
  r = run_cli("solve " + q(mesh) + " -N 4 --auto --align-features 30 --feature-min-length 0.3 --report " + q(report));
  ASSERT_EQ(r.status, 0) << r.err;
  j = nlohmann::json::parse(slurp(report));
  EXPECT_EQ(j["features"]["sharp_edges"].get<size_t>(), cube);
  EXPECT_EQ(j["features"]["loose_edges"].get<size_t>(), all - cube);
  EXPECT_NE(r.out.find("features: " + std::to_string(all - cube) +
                       " sharp edges left out (faces sharp on all three edges, chains with a loose end or pieces shorter than 0.3;"),
            std::string::npos)
      << r.out;
  // The map's unit at 200 squares: √(area / 200), above the spike's width.
  double area = 0;
  for (int f = 0; f < designer.topology().num_faces; ++f) area += designer.geometry().face_area[f];
  r = run_cli("quad " + q(mesh) + " --auto --align-features 30 --target-faces 200 -o " + q(out) + " --report " + q(report));
  ASSERT_EQ(r.status, 0) << r.out << r.err;
  j = nlohmann::json::parse(slurp(report));
  EXPECT_EQ(j["features"]["sharp_edges"].get<size_t>(), cube);
  EXPECT_EQ(j["features"]["loose_edges"].get<size_t>(), all - cube);
  EXPECT_NEAR(j["features"]["min_length"].get<double>(), std::sqrt(area / 200), 1e-9);
  EXPECT_TRUE(j["quad"]["problems"].empty());
  EXPECT_EQ(j["quad"]["euler_characteristic"], 2);
  EXPECT_EQ(j["quad"]["singular_mismatches"], 0);
  EXPECT_EQ(j["param"]["flipped_faces"], 0);
}

TEST(CliFeatures, UsageAndInputErrors) {
  const std::string mesh = mesh_file(make_cube_sphere(2, false), "cube.obj");
  for (const std::string bad : {"-1", "200", "nan", "abc", "30x"}) {
    const auto r = run_cli("solve " + q(mesh) + " -N 4 --align-features " + bad);
    EXPECT_EQ(r.status, 2) << bad << ": " << r.err;
    EXPECT_NE(r.err.find("expected an angle in degrees in [0, 180]"), std::string::npos) << r.err;
  }
  auto r = run_cli("solve " + q(mesh) + " -N 4 --sharp-out " + q(temp_file("m.sharp")));
  EXPECT_EQ(r.status, 2);
  EXPECT_NE(r.err.find("needs --align-features or --features"), std::string::npos) << r.err;
  r = run_cli("solve " + q(mesh) + " -N 2 --align-features 30 --field-out " + q(temp_file("m.rosy")));
  EXPECT_EQ(r.status, 2);
  EXPECT_NE(r.err.find("-N 4"), std::string::npos) << r.err;
  r = run_cli("solve " + q(mesh) + " -N 4 --features " + q(temp_file("missing.txt")));
  EXPECT_EQ(r.status, 1);
  EXPECT_NE(r.err.find("missing.txt"), std::string::npos) << r.err;
  const std::string edges = temp_file("edges.txt");
  test::write_text(edges, "0 1\nnot numbers\n");
  r = run_cli("solve " + q(mesh) + " -N 4 --features " + q(edges));
  EXPECT_EQ(r.status, 1);
  EXPECT_NE(r.err.find(edges + ":"), std::string::npos) << r.err;
  r = run_cli("solve " + q(mesh) + " -N 4 --features " + q(edges) + " --split-large-turns");
  EXPECT_EQ(r.status, 1);
  r = run_cli("solve " + q(mesh) + " -N 4 --feature-min-length 1");
  EXPECT_EQ(r.status, 2);
  EXPECT_NE(r.err.find("--feature-min-length requires --align-features"), std::string::npos) << r.err;
  for (const std::string bad : {"-1", "abc"}) {
    r = run_cli("solve " + q(mesh) + " -N 4 --align-features 30 --feature-min-length " + bad);
    EXPECT_EQ(r.status, 2) << bad << ": " << r.err;
  }
  r = run_cli("solve " + q(mesh) + " -N 4 --align-features 30 --feature-min-length nan");
  EXPECT_NE(r.status, 0);
  EXPECT_NE(r.err.find("--feature-min-length: expected a finite length >= 0"), std::string::npos) << r.err;
}

TEST(CliFeatures, RenderDrawsTheSharpEdges) {
  const Mesh m = make_cube_sphere(6, false);
  const std::string mesh = mesh_file(m, "cube.obj"), rosy = temp_file("m.rosy");
  ASSERT_EQ(run_cli("solve " + q(mesh) + " -q -N 4 --auto --align-features 30 --field-out " + q(rosy)).status, 0);
  const std::string with = temp_file("with.png"), without = temp_file("without.png");
  auto r = run_cli("render " + q(mesh) + " --field " + q(rosy) + " --align-features 30 --size 400x300 -o " + q(with));
  ASSERT_EQ(r.status, 0) << r.err;
  ASSERT_EQ(run_cli("render " + q(mesh) + " --field " + q(rosy) + " --size 400x300 -o " + q(without)).status, 0);
  EXPECT_NE(slurp(with), slurp(without));
  // In the library: the sharp colour appears only when edges are given.
  const Topology t = test::topo(m);
  const Geometry g = compute_geometry(m.V, t);
  const Field field = field_from_directions(g, read_field(rosy, static_cast<int>(m.F.rows())), 4);
  RenderOptions o;
  o.width = 400, o.height = 300;
  auto count_sharp = [&](const Image& image) {
    int n = 0;
    for (int y = 0; y < image.height; ++y)
      for (int x = 0; x < image.width; ++x) n += image.pixel(x, y) == o.palette.sharp;
    return n;
  };
  EXPECT_EQ(count_sharp(render_field(m.V, t, g, field, {}, o)), 0);
  o.sharp_edges = sharp_edges(m.V, t, g, 30);
  EXPECT_GT(count_sharp(render_field(m.V, t, g, field, {}, o)), 200);
  r = run_cli("render " + q(mesh) + " --field " + q(rosy) + " --align-features 500 -o " + q(with));
  EXPECT_EQ(r.status, 2);
}

}  // namespace
}  // namespace trivcon
