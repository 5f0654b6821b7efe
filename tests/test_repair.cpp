// SPDX-License-Identifier: MIT
// trivcon/repair.h: duplicates dropped, non-manifold edges cut, fans split; the result is a manifold mesh the
// topology accepts, with maps back to the input's faces and vertices.
#include <gtest/gtest.h>

#include <iostream>
#include <set>

#include "support.h"
#include "trivcon/error.h"
#include "trivcon/generate.h"
#include "trivcon/io.h"
#include "trivcon/repair.h"
#include "trivcon/topology.h"

namespace trivcon {
namespace {

using test::error_of;
using test::faces;

// Every repaired face is its input face with each corner a copy of the input's corner, in order.
void expect_maps(const RepairedMesh& r, const MatrixX3d& V, const MatrixX3i& F) {
  ASSERT_EQ(r.input_face.size(), static_cast<size_t>(r.F.rows()));
  ASSERT_EQ(r.face_of_input.size(), static_cast<size_t>(F.rows()));
  ASSERT_EQ(r.vertex_origin.size(), static_cast<size_t>(r.V.rows()));
  for (int q = 0; q < r.F.rows(); ++q)
    for (int k = 0; k < 3; ++k) {
      EXPECT_EQ(r.vertex_origin[r.F(q, k)], F(r.input_face[q], k));
      EXPECT_EQ(r.V.row(r.F(q, k)), V.row(F(r.input_face[q], k)));
    }
  for (int f = 0; f < F.rows(); ++f) {
    std::multiset<int> a{F(f, 0), F(f, 1), F(f, 2)}, b;
    for (int k = 0; k < 3; ++k) b.insert(r.vertex_origin[r.F(r.face_of_input[f], k)]);
    EXPECT_EQ(a, b) << "face " << f;
  }
  for (int v = 0; v < V.rows(); ++v) EXPECT_EQ(r.vertex_origin[v], v);
  EXPECT_NO_THROW(build_topology(r.F, static_cast<int>(r.V.rows())));
}

TEST(Repair, ManifoldMeshIsUnchanged) {
  const Mesh m = make_torus(12, 6);
  const RepairedMesh r = repair_mesh(m.V, m.F);
  EXPECT_FALSE(r.changed());
  EXPECT_EQ(r.F, m.F);
  EXPECT_EQ(r.V, m.V);
  EXPECT_EQ(repair_summary(r), "");
}

TEST(Repair, TwoTetrahedraSharingAVertexSplitIt) {
  MatrixX3d V(7, 3);
  V << 0, 0, 0, 1, 0, 0, 0, 1, 0, 0, 0, 1, -1, 0, 0, 0, -1, 0, 0, 0, -1;
  const MatrixX3i F = faces({{0, 2, 1}, {0, 1, 3}, {0, 3, 2}, {1, 2, 3}, {0, 4, 5}, {0, 6, 4}, {0, 5, 6}, {4, 6, 5}});
  EXPECT_NE(error_of([&] { build_topology(F, 7); }).find("non-manifold vertex 0"), std::string::npos);
  const RepairedMesh r = repair_mesh(V, F);
  expect_maps(r, V, F);
  ASSERT_EQ(r.V.rows(), 8);
  EXPECT_EQ(r.split_vertices, (std::vector<std::pair<int, int>>{{0, 2}}));
  EXPECT_EQ(r.F(4, 0), 7);  // the second tetrahedron's corner at vertex 0 is the new vertex
  EXPECT_EQ(build_topology(r.F, 8).components.size(), 2u);
  EXPECT_EQ(fan_faces(r, 0), (std::vector<int>{0, 4}));
  EXPECT_EQ(fan_faces(r, 1), std::vector<int>{});
  EXPECT_EQ(repair_summary(r), "repaired: 1 vertex split into separate fans (first: vertex 0, 2 fans)");
}

TEST(Repair, ABookOfPagesIsCutIntoSheets) {
  // Four triangles on the spine (0, 1), pages 2..5; the consistently oriented pairs go together.
  MatrixX3d V(6, 3);
  V << 0, 0, 0, 0, 0, 1, 1, 0, 0, 0, 1, 0, -1, 0, 0, 0, -1, 0;
  const MatrixX3i F = faces({{0, 1, 2}, {0, 1, 3}, {1, 0, 4}, {1, 0, 5}});
  const RepairedMesh r = repair_mesh(V, F);
  expect_maps(r, V, F);
  EXPECT_EQ(r.cut_edges, (std::vector<std::pair<int, int>>{{0, 1}}));
  EXPECT_TRUE(r.unpaired_faces.empty());
  const Topology t = build_topology(r.F, static_cast<int>(r.V.rows()));
  EXPECT_EQ(t.components.size(), 2u);  // pages 0 + 2 and 1 + 3
  EXPECT_EQ(t.face_component[0], t.face_component[2]);
  EXPECT_EQ(t.face_component[1], t.face_component[3]);
  EXPECT_EQ(r.split_vertices, (std::vector<std::pair<int, int>>{{0, 2}, {1, 2}}));
  // Three pages: one is left as boundary.
  const MatrixX3i F3 = faces({{0, 1, 2}, {0, 1, 3}, {1, 0, 4}});
  const RepairedMesh r3 = repair_mesh(V, F3);
  expect_maps(r3, V, F3);
  EXPECT_EQ(r3.unpaired_faces, std::vector<int>{1});
}

TEST(Repair, DuplicatesInEitherOrderAreDropped) {
  const Mesh m = make_icosphere(0);
  MatrixX3i F(m.F.rows() + 2, 3);
  F << m.F, m.F(3, 2), m.F(3, 1), m.F(3, 0), m.F(7, 1), m.F(7, 2), m.F(7, 0);
  const RepairedMesh r = repair_mesh(m.V, F);
  expect_maps(r, m.V, F);
  EXPECT_EQ(r.F, m.F);
  EXPECT_EQ(r.duplicates, (std::vector<std::pair<int, int>>{{20, 3}, {21, 7}}));
  EXPECT_EQ(r.face_of_input[20], 3);
  EXPECT_EQ(r.face_of_input[21], 7);
  EXPECT_EQ(repair_summary(r), "repaired: 2 duplicate faces dropped (first: face 20, a copy of face 3)");
}

TEST(Repair, RefusesWhatItDoesNotRepair) {
  MatrixX3d V = MatrixX3d::Zero(3, 3);
  EXPECT_EQ(error_of([&] { repair_mesh(V, faces({{0, 1, 1}})); }), "no faces left: every face has a repeated vertex (first: face 0, (0, 1, 1))");
  EXPECT_EQ(error_of([&] { repair_mesh(V, faces({{0, 1, 3}})); }), "vertex index 3 out of range in face 0 (mesh has 3 vertices)");
}

// Two sheets on one edge joined again around both its ends: splitting cannot separate them, so the faces
// beyond the first two on the edge are dropped (reported) and the rest is repaired.
TEST(Repair, SheetsThatMeetAgainLoseTheirExtraFaces) {
  MatrixX3d V(6, 3);
  V << 0, 0, 0, 1, 0, 0, 0.5, 1, 0, 0.5, -1, 0, 0.5, 0.7, 0.7, 0.5, -0.7, 0.7;
  const MatrixX3i F = faces({{0, 1, 2}, {1, 0, 3}, {0, 1, 4}, {1, 0, 5}, {0, 2, 4}, {1, 3, 5}});
  const RepairedMesh r = repair_mesh(V, F);
  EXPECT_EQ(r.unseparated_faces, (std::vector<int>{2, 3}));
  EXPECT_EQ(r.F.rows(), 4);
  EXPECT_NO_THROW(build_topology(r.F, static_cast<int>(r.V.rows())));
  for (int f : {2, 3}) EXPECT_GE(r.face_of_input[f], 0);  // they read a neighbour's direction
  EXPECT_EQ(repair_summary(r).find("repaired: 2 faces dropped where sheets of an edge with more than two faces meet again (first: face 2)"),
            0u)
      << repair_summary(r);
}

// The broken meshes of ../shared (several fans, edges with more than two faces): repaired into meshes the
// topology accepts, or refused as non-orientable (what pairing leaves may be a Möbius sheet).
TEST(Repair, SharedBrokenMeshes) {
  int accepted = 0;
  for (const char* name : {"teapot.obj", "truck.obj", "hourglass_ico.obj", "dragon_vrip_res3.ply"}) {
    const std::string path = test::shared_mesh(name);
    if (path.empty()) GTEST_SKIP() << "../shared/data/meshes is not beside the project";
    const MeshData m = read_mesh(path);
    EXPECT_ANY_THROW(build_topology(m.F, static_cast<int>(m.V.rows()))) << name;
    std::string outcome;
    try {
      const RepairedMesh r = repair_mesh(m.V, m.F);
      EXPECT_TRUE(r.changed()) << name;
      outcome = repair_summary(r);
      build_topology(r.F, static_cast<int>(r.V.rows()));
      expect_maps(r, m.V, m.F);
      ++accepted;
    } catch (const Error& e) {
      outcome = e.what();
      EXPECT_EQ(outcome.find("non-orientable component"), 0u) << name << ": " << outcome;
    }
    std::cout << name << ": " << outcome << "\n";
  }
  EXPECT_GE(accepted, 2);
}

}  // namespace
}  // namespace trivcon
