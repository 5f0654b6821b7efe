// SPDX-License-Identifier: MIT
// Refinement where the connection turns by π/N or more (trivcon/split_large_turns.h, --split-large-turns): the
// split keeps ids, surface and orientation; afterwards any matching, even one computed from the directions
// alone, reads exactly the prescription; fixed directions carry over; the library function's rounds.
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

using namespace reference;
using test::contains;
using test::error_of;
using test::q;
using test::run_cli;
using test::save;

TEST(SplitLargeTurns, CentroidSplitKeepsIdsSurfaceAndOrientation) {
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
TEST(SplitLargeTurns, SplitLargeTurnsLetsAnyMatchingReadThePrescription) {
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

TEST(SplitLargeTurns, SplitLargeTurnsKeepsFixedDirections) {
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
TEST(SplitLargeTurns, SplitLargeTurnsLibraryFunction) {
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
