// Matchings (trivcon/matching.h, --matching-out, check --matching): an independent principal matching, read
// from the field's world directions alone, sees other singularities where the connection turns by π/N or
// more; with the matching trivcon exports, an independent index computation finds exactly the prescription.
#include <Eigen/Geometry>
#include <cmath>
#include <fstream>
#include <map>
#include <nlohmann/json.hpp>
#include <sstream>

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

double wrap(double a) { return a - 2 * kPi * std::floor((a + kPi) / (2 * kPi)); }

// The test's own mesh data: per face its unit normal; per interior edge (i < j) its two faces, L holding
// the half-edge i → j.
struct Edges {
  std::map<std::pair<int, int>, std::pair<int, int>> faces;  // (i, j) → (L, R)
};
Edges edges_of(const MatrixX3i& F) {
  Edges out;
  std::map<std::pair<int, int>, int> half;
  for (int f = 0; f < F.rows(); ++f)
    for (int k = 0; k < 3; ++k) half[{F(f, k), F(f, (k + 1) % 3)}] = f;
  for (auto [h, f] : half)
    if (h.first < h.second && half.count({h.second, h.first})) out.faces[h] = {f, half.at({h.second, h.first})};
  return out;
}
Eigen::Vector3d normal_of(const MatrixX3d& V, const MatrixX3i& F, int f) {
  const Eigen::Vector3d a = V.row(F(f, 0)), b = V.row(F(f, 1)), c = V.row(F(f, 2));
  return (b - a).cross(c - a).normalized();
}
// The world direction d of face L, rotated about the shared edge into R's plane (the discrete
// Levi-Civita transport), then its signed angle to R's direction e about R's normal.
double transported_angle(const MatrixX3d& V, const MatrixX3i& F, int i, int j, int L, int R, const Eigen::Vector3d& d,
                         const Eigen::Vector3d& e) {
  const Eigen::Vector3d nL = normal_of(V, F, L), nR = normal_of(V, F, R);
  const Eigen::Vector3d axis = (Eigen::Vector3d(V.row(j)) - Eigen::Vector3d(V.row(i))).normalized();
  const double dihedral = std::atan2(nL.cross(nR).dot(axis), nL.dot(nR));
  const Eigen::Vector3d moved = Eigen::AngleAxisd(dihedral, axis) * d;
  return std::atan2(moved.cross(e).dot(nR), moved.dot(e));  // angle from moved to e, counter-clockwise about nR
}

// Independent indices from world directions: with `given` a matching per edge ((i, j) → m), else the
// principal one. Index of interior vertex v: (K_v + Σ over its edges of ± the jump) / 2π, K_v = 2π − Σ angles.
std::map<int, int> independent_indices(const MatrixX3d& V, const MatrixX3i& F, const MatrixX3d& dirs, int N,
                                       const std::map<std::pair<int, int>, int>* given) {
  const Edges edges = edges_of(F);
  std::map<int, double> defect, sum;
  std::map<int, int> boundary;
  for (int f = 0; f < F.rows(); ++f)
    for (int k = 0; k < 3; ++k) {
      const int v = F(f, k);
      const Eigen::Vector3d u = V.row(F(f, (k + 1) % 3)) - V.row(v), w = V.row(F(f, (k + 2) % 3)) - V.row(v);
      defect[v] += std::atan2(u.cross(w).norm(), u.dot(w));
      const int a = F(f, k), b = F(f, (k + 1) % 3);
      if (!edges.faces.count({std::min(a, b), std::max(a, b)})) boundary[a] = boundary[b] = 1;
    }
  for (auto [e, lr] : edges.faces) {
    const auto [L, R] = lr;
    // β_R + 2πm/N − (β_L + ρ): the angle from L's transported direction to R's direction m.
    double jump;
    const double base = transported_angle(V, F, e.first, e.second, L, R, dirs.row(L).transpose(), dirs.row(R).transpose());
    if (given) {
      jump = wrap(base + 2 * kPi * given->at(e) / N);
    } else {
      jump = base - (2 * kPi / N) * std::round(base / (2 * kPi / N));
    }
    sum[e.second] += jump, sum[e.first] -= jump;
  }
  std::map<int, int> out;
  for (auto [v, angles] : defect) {
    if (boundary.count(v)) continue;
    const int n = static_cast<int>(std::lround((2 * kPi - angles + sum[v]) / (2 * kPi) * N));
    if (n != 0) out[v] = n;
  }
  return out;
}

// A coarse icosphere with a large index at one vertex: the connection must turn by more than π/N across
// its edges.
struct LargeTurnCase {
  Mesh mesh = make_icosphere(1);
  IndexPrescription p;
  LargeTurnCase() {
    p.N = 4;
    p.vertex[0] = 6;  // +3/2
    p.vertex[1] = 1;
    p.vertex[2] = 1;
  }
};

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

TEST(Matching, CentroidSplitKeepsIdsSurfaceAndOrientation) {
  const Mesh m = make_icosphere(1);
  std::vector<int> parent;
  const Mesh s = split_faces_at_centroids(m, {5, 3, 5}, &parent);
  ASSERT_EQ(s.V.rows(), m.V.rows() + 2);
  ASSERT_EQ(s.F.rows(), m.F.rows() + 4);
  EXPECT_TRUE(s.V.topRows(m.V.rows()) == m.V) << "input vertices keep their ids and positions";
  for (int f = 0; f < m.F.rows(); ++f)
    if (f != 3 && f != 5) {
      EXPECT_TRUE(s.F.row(f) == m.F.row(f)) << "face " << f;
    }
  // Face 3 (the smaller id) got the first centroid: (a, b, g) in place, then (b, c, g), (c, a, g).
  const int g = static_cast<int>(m.V.rows());
  EXPECT_EQ(s.F.row(3), Eigen::RowVector3i(m.F(3, 0), m.F(3, 1), g));
  EXPECT_EQ(s.F.row(m.F.rows()), Eigen::RowVector3i(m.F(3, 1), m.F(3, 2), g));
  EXPECT_EQ(s.F.row(m.F.rows() + 1), Eigen::RowVector3i(m.F(3, 2), m.F(3, 0), g));
  EXPECT_LE((Eigen::Vector3d(s.V.row(g)) - (m.V.row(m.F(3, 0)) + m.V.row(m.F(3, 1)) + m.V.row(m.F(3, 2))).transpose() / 3).norm(), 1e-15);
  EXPECT_EQ(parent[m.F.rows()], 3);
  EXPECT_EQ(parent[m.F.rows() + 3], 5);
  // Same total area, same orientation (every child's normal agrees with its parent's).
  auto area = [](const Mesh& mesh, int f) {
    const Eigen::Vector3d a = mesh.V.row(mesh.F(f, 0)), b = mesh.V.row(mesh.F(f, 1)), c = mesh.V.row(mesh.F(f, 2));
    return (b - a).cross(c - a);
  };
  Eigen::Vector3d total_in = Eigen::Vector3d::Zero(), total_out = Eigen::Vector3d::Zero();
  for (int f = 0; f < m.F.rows(); ++f) total_in += area(m, f);
  for (int f = 0; f < s.F.rows(); ++f) {
    total_out += area(s, f);
    EXPECT_GT(area(s, f).dot(area(m, parent[f])), 0) << "face " << f;
  }
  EXPECT_LE((total_in - total_out).norm(), 1e-12);
  EXPECT_EQ(error_of([&] { split_faces_at_centroids(m, {80}); }), "split_faces_at_centroids: face 80 out of range (mesh has 80 faces)");
}

// --split-large-turns: refined where the connection turns by π/N or more, the field on --mesh-out read by an
// independent principal matching has exactly the prescribed singularities at their vertex ids, and nothing else.
TEST(Matching, SplitLargeTurnsLetsAnyMatchingReadThePrescription) {
  const LargeTurnCase c;
  const std::string dir = test::temp_dir("matching_split");
  const std::string mesh = save(dir, "ico", c.mesh), field = dir + "/f.txt", refined = dir + "/refined.obj", report = dir + "/r.json";
  const std::string sing = " --sing 0:3/2 --sing 1:1/4 --sing 2:1/4";
  const test::CommandResult r = run_cli("solve " + q(mesh) + " -N 4" + sing + " --split-large-turns --field-out " + q(field) +
                                        " --mesh-out " + q(refined) + " --report " + q(report));
  ASSERT_EQ(r.status, 0) << r.err;
  EXPECT_EQ(r.err, "") << "no edge turns by pi/N or more any more, so no warning";
  EXPECT_TRUE(contains(r.out, "split-large-turns: round 1 split ")) << r.out;
  const MeshData out = read_mesh(refined);
  ASSERT_GT(out.F.rows(), c.mesh.F.rows());
  EXPECT_TRUE(out.V.topRows(c.mesh.V.rows()).isApprox(c.mesh.V, 1e-15)) << "input vertices keep their ids";
  const MatrixX3d dirs = read_field(field, static_cast<int>(out.F.rows()));
  EXPECT_EQ(independent_indices(out.V, out.F, dirs, 4, nullptr), c.p.vertex);
  const nlohmann::json j = nlohmann::json::parse(std::ifstream(report));
  EXPECT_TRUE(j["split_large_turns"]["converged"].get<bool>());
  EXPECT_TRUE(j["large_turns"]["edges"].empty());
  EXPECT_EQ(j["mesh"]["faces"].get<int>(), out.F.rows());
  // Not with prescribed generator or loop indices (the refined mesh has cycles of its own), nor a batch.
  const test::CommandResult g = run_cli("solve " + q(mesh) + " -N 4" + sing + " --split-large-turns --boundary 0:1");
  EXPECT_EQ(g.status, 1);
  EXPECT_TRUE(contains(g.err, "--split-large-turns makes new generators and boundary loops: leave their indices to be chosen")) << g.err;
}

TEST(Matching, SplitLargeTurnsKeepsFixedDirections) {
  // A coarse disk with the boundary aligned, a face fixed, and a large index at its centre (+1, what the
  // aligned boundary needs): the refined mesh is aligned and fixed too.
  const Mesh m = make_disk(6, 6);
  const std::string dir = test::temp_dir("matching_split_fixed");
  const std::string mesh = save(dir, "disk", m), field = dir + "/f.txt", refined = dir + "/refined.ply";
  const test::CommandResult r =
      run_cli("solve " + q(mesh) + " -N 4 --sing 0:1 --align-boundary --fix 40:1,0,0 --split-large-turns -q --field-out " + q(field) +
              " --mesh-out " + q(refined));
  ASSERT_EQ(r.status, 0) << r.err;
  const MeshData out = read_mesh(refined);
  const MatrixX3d dirs = read_field(field, static_cast<int>(out.F.rows()));
  // Face 40 keeps the --fix direction (1, 0, 0) modulo a quarter turn.
  const double a = std::atan2(dirs(40, 1), dirs(40, 0));
  EXPECT_LE(std::abs(std::remainder(a, kPi / 2)), 1e-9);
  std::map<int, int> want = {{0, 4}};
  EXPECT_EQ(independent_indices(out.V, out.F, dirs, 4, nullptr), want);
}

// The library function behind --split-large-turns (trivcon/split_large_turns.h): converged, ids kept, each face's
// parent the input face it lies in, a fixed face's direction passed to its children, and an independent
// principal matching reads exactly the prescription on the refined mesh.
TEST(Matching, SplitLargeTurnsLibraryFunction) {
  const LargeTurnCase c;
  FieldDesigner designer(c.mesh.V, c.mesh.F);
  IndexPrescription p = c.p;
  // A face at vertex 0 (index 3/2, where the large turns are): it is split, so its children other than
  // its first must be given its direction.
  int fixed_face = -1;
  for (int f = 0; f < c.mesh.F.rows() && fixed_face < 0; ++f)
    if (c.mesh.F(f, 0) == 0 || c.mesh.F(f, 1) == 0 || c.mesh.F(f, 2) == 0) fixed_face = f;
  const Eigen::Vector3d world = designer.geometry().direction_in_face(fixed_face, 0.3);
  p.fixed[fixed_face] = 0.3;
  designer.set_fixed_faces({fixed_face});
  const RefinedDesign r = split_large_turns(designer, c.mesh.F, p);
  EXPECT_TRUE(r.converged);
  ASSERT_GE(r.rounds.size(), 1u);
  ASSERT_TRUE(r.designer);
  EXPECT_EQ(r.rounds.back().faces, r.F.rows());
  EXPECT_EQ(r.rounds.back().vertices, r.V.rows());
  EXPECT_EQ(r.V.topRows(c.mesh.V.rows()), c.mesh.V);
  EXPECT_TRUE(design_verified(r.design));
  EXPECT_TRUE(large_turn_edges(r.designer->topology(), r.design.connection.x, 4).empty());
  ASSERT_EQ(static_cast<Eigen::Index>(r.parent_face.size()), r.F.rows());
  int children_of_fixed = 0;
  for (int f = 0; f < r.F.rows(); ++f) {
    // The face's centroid lies in its parent's plane.
    const int q = r.parent_face[f];
    const Eigen::Vector3d a = c.mesh.V.row(c.mesh.F(q, 0)), b = c.mesh.V.row(c.mesh.F(q, 1)), d = c.mesh.V.row(c.mesh.F(q, 2));
    const Eigen::Vector3d g = (r.V.row(r.F(f, 0)) + r.V.row(r.F(f, 1)) + r.V.row(r.F(f, 2))).transpose() / 3;
    EXPECT_NEAR((g - a).dot((b - a).cross(d - a).normalized()), 0, 1e-12) << "face " << f;
    if (q != fixed_face) continue;
    ++children_of_fixed;
    ASSERT_TRUE(r.prescription.fixed.count(f)) << f;
    const Eigen::Vector3d held = r.designer->geometry().direction_in_face(f, r.design.field.angle(f));
    const double turn = std::atan2(held.cross(world).dot(r.designer->geometry().normal.row(f)), held.dot(world));
    EXPECT_LE(std::abs(std::remainder(turn, kPi / 2)), 1e-9) << "face " << f;
  }
  EXPECT_GE(children_of_fixed, 3) << "the fixed face was not split: the test lost its point";
  EXPECT_EQ(static_cast<int>(r.prescription.fixed.size()), children_of_fixed);
  const MatrixX3d dirs = field_directions(r.designer->geometry(), r.design.field);
  EXPECT_EQ(independent_indices(r.V, r.F, dirs, 4, nullptr), c.p.vertex);
  // Generator or loop indices are refused (the refined mesh has cycles of its own).
  IndexPrescription bad = c.p;
  bad.generator[0] = 1;
  EXPECT_EQ(error_of([&] { split_large_turns(designer, c.mesh.F, bad); }),
            "splitting large turns makes new generators and boundary loops: leave their indices to be chosen");
}

}  // namespace
}  // namespace trivcon
