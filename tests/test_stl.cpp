// SPDX-License-Identifier: MIT
// The STL reader (trivcon/io.h read_stl, by extension in read_mesh): ASCII and binary, corners welded by exact
// position into vertices numbered in order of first appearance; the errors name the file and the triangle.
#include <gtest/gtest.h>

#include <cstdint>
#include <cstring>
#include <string>

#include "support.h"
#include "trivcon/error.h"
#include "trivcon/generate.h"
#include "trivcon/io.h"
#include "trivcon/topology.h"

namespace trivcon {
namespace {

using test::error_of;

// The flat-sided cube (make_cube_sphere(1, false): 8 vertices, 12 triangles) as STL triangles.
std::string ascii_stl(const Mesh& m) {
  std::string s = "solid cube\n";
  for (int f = 0; f < m.F.rows(); ++f) {
    s += "  facet normal 0 0 0\n    outer loop\n";
    for (int k = 0; k < 3; ++k) {
      char line[128];
      std::snprintf(line, sizeof line, "      vertex %.17g %.17g %.17g\n", m.V(m.F(f, k), 0), m.V(m.F(f, k), 1), m.V(m.F(f, k), 2));
      s += line;
    }
    s += "    endloop\n  endfacet\n";
  }
  return s + "endsolid cube\n";
}

std::string binary_stl(const Mesh& m, const char* header = "solid but binary") {
  std::string s(80, '\0');
  std::memcpy(&s[0], header, std::strlen(header));
  const std::uint32_t n = static_cast<std::uint32_t>(m.F.rows());
  s.append(reinterpret_cast<const char*>(&n), 4);
  for (int f = 0; f < m.F.rows(); ++f) {
    const float normal[3] = {0, 0, 0};
    s.append(reinterpret_cast<const char*>(normal), 12);
    for (int k = 0; k < 3; ++k)
      for (int a = 0; a < 3; ++a) {
        const float c = static_cast<float>(m.V(m.F(f, k), a));
        s.append(reinterpret_cast<const char*>(&c), 4);
      }
    s.append(2, '\0');
  }
  return s;
}

// Welded: the cube's 8 corners, 12 faces, the same triangles (by position), closed, χ = 2.
void expect_cube(const MeshData& d, const Mesh& m) {
  ASSERT_EQ(d.V.rows(), 8);
  ASSERT_EQ(d.F.rows(), 12);
  for (int f = 0; f < 12; ++f)
    for (int k = 0; k < 3; ++k) EXPECT_EQ(d.V.row(d.F(f, k)), m.V.row(m.F(f, k)));
  const Topology t = build_topology(d.F, 8);
  EXPECT_EQ(t.euler_characteristic(), 2);
  EXPECT_TRUE(t.boundary_loops.empty());
  // Ids in order of first appearance.
  EXPECT_EQ(d.F(0, 0), 0);
  EXPECT_EQ(d.F(0, 1), 1);
  EXPECT_EQ(d.F(0, 2), 2);
}

TEST(Stl, AsciiAndBinaryWeldTheCube) {
  const Mesh m = make_cube_sphere(1, false);
  const MeshData a = read_stl(ascii_stl(m), "cube.stl");
  EXPECT_EQ(a.format, "stl-ascii");
  expect_cube(a, m);
  const MeshData b = read_stl(binary_stl(m), "cube.stl");  // its header starts with "solid" too
  EXPECT_EQ(b.format, "stl-binary");
  expect_cube(b, m);
  const std::string path = test::temp_file("cube.stl");
  test::write_text(path, binary_stl(m));
  EXPECT_EQ(read_mesh(path).F, b.F);
}

TEST(Stl, Errors) {
  const Mesh m = make_cube_sphere(1, false);
  std::string cut = binary_stl(m, "binary");
  cut.resize(cut.size() - 10);
  EXPECT_EQ(error_of([&] { read_stl(cut, "c.stl"); }),
            "c.stl: binary STL of 674 bytes, but its header announces 12 triangles (684 bytes): the file is cut short or not STL");
  EXPECT_EQ(error_of([&] { read_stl("", "e.stl"); }), "e.stl: empty file");
  EXPECT_EQ(error_of([&] { read_stl("hello", "h.stl"); }), "h.stl: not an STL file (neither 'solid' nor a binary header of 84 bytes)");
  const std::string degenerate =
      "solid d\nfacet normal 0 0 1\nouter loop\nvertex 0 0 0\nvertex 1 0 0\nvertex 0 0 0\nendloop\nendfacet\nendsolid d\n";
  // Read (repair drops it), and named for a front end that does not repair.
  EXPECT_EQ(read_stl(degenerate, "d.stl").repeated_vertex,
            "d.stl:8: triangle 0 has two corners at the same position (a degenerate triangle)");
  const std::string bad = "solid d\nfacet normal 0 0 1\nouter loop\nvertex 0 0 x\n";
  EXPECT_EQ(error_of([&] { read_stl(bad, "b.stl"); }), "b.stl:4: malformed number 'x'");
  const std::string word = "solid d\nfacet normal 0 0 1\nouter lop\n";
  EXPECT_EQ(error_of([&] { read_stl(word, "w.stl"); }), "w.stl:3: expected 'loop', found 'lop'");
  const std::string nan = "solid d\nfacet normal 0 0 1\nouter loop\nvertex 0 0 nan\nvertex 1 0 0\nvertex 0 1 0\nendloop\nendfacet\nendsolid\n";
  EXPECT_EQ(error_of([&] { read_stl(nan, "n.stl"); }), "n.stl:8: triangle 0 has a coordinate that is not finite");
  EXPECT_EQ(error_of([&] { read_stl("solid x\n", "s.stl"); }), "s.stl:1: file ends before 'endsolid'");
  EXPECT_EQ(error_of([&] { read_stl("solid x\nendsolid x\n", "z.stl"); }), "z.stl: no faces");
  EXPECT_EQ(error_of([&] { read_stl(std::string(84, '\0'), "z.stl"); }), "z.stl: no faces");
}

}  // namespace
// --weld: corners within the tolerance of an earlier vertex join it; the earliest wins and keeps its position.
TEST(Stl, WeldsWithinATolerance) {
  const std::string text =
      "solid t\n"
      "facet normal 0 0 1\nouter loop\nvertex 0 0 0\nvertex 1 0 0\nvertex 0 1 0\nendloop\nendfacet\n"
      "facet normal 0 0 1\nouter loop\nvertex 1.0000001 0 0\nvertex 1 1 0\nvertex 0 1.0000002 0\nendloop\nendfacet\n"
      "endsolid t\n";
  EXPECT_EQ(read_stl(text, "t.stl").V.rows(), 6);
  const MeshData m = read_stl(text, "t.stl", 1e-6);
  ASSERT_EQ(m.V.rows(), 4);
  EXPECT_EQ(m.F(1, 0), 1);
  EXPECT_EQ(m.F(1, 2), 2);
  EXPECT_EQ(m.V(1, 0), 1.0);  // the first corner's position
  EXPECT_EQ(read_stl(text, "t.stl", 1e-8).V.rows(), 6);
  EXPECT_EQ(error_of([&] { read_stl(text, "t.stl", -1); }), "t.stl: the weld tolerance must be a finite number >= 0, not -1.000000");
}

}  // namespace trivcon
