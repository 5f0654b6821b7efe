// SPDX-License-Identifier: MIT
// tests/test_io.cpp: the mesh readers and writers of trivcon/io.h.
//
// Small hand-written files cover every accepted variant of OBJ, OFF and PLY (ASCII and binary of
// both byte orders, all PLY scalar types) and gzip; malformed files (truncated at every byte,
// randomly mutated, wrong or huge counts, bad numbers and indices) must give a trivcon::Error naming
// the file and place, never a crash; writers must round-trip exactly. When the shared folder of
// real meshes exists, every file there is read and its counts checked.
#include <gmock/gmock.h>
#include <gtest/gtest.h>
#include <zlib.h>

#include <algorithm>
#include <array>
#include <cmath>
#include <cstdint>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <functional>
#include <limits>
#include <random>
#include <sstream>
#include <string>
#include <vector>

#include "trivcon/error.h"
#include "support.h"
#include "trivcon/io.h"

namespace {

namespace fs = std::filesystem;
using testing::AllOf;
using testing::HasSubstr;
using testing::StartsWith;
using trivcon::MatrixX3d;
using trivcon::MatrixX3i;
using trivcon::MeshData;

// ------------------------------------------------------------------------------------------------
// Helpers

// A fresh directory per test: ctest may run the tests of this file in parallel processes.
fs::path test_dir() {
#ifdef TRIVCON_TEST_TMP
  const fs::path root = fs::path(TRIVCON_TEST_TMP) / "test_io";
#else
  const fs::path root = fs::temp_directory_path() / "trivcon_test_io";
#endif
  const testing::TestInfo* info = testing::UnitTest::GetInstance()->current_test_info();
  const fs::path dir = root / (std::string(info->test_suite_name()) + "." + info->name());
  fs::remove_all(dir);
  fs::create_directories(dir);
  return dir;
}

void write_bytes(const fs::path& path, const std::string& bytes) {
  std::ofstream out(path, std::ios::binary);
  out.write(bytes.data(), static_cast<std::streamsize>(bytes.size()));
  ASSERT_TRUE(out.good()) << path;
}

std::string read_bytes(const fs::path& path) {
  std::ifstream in(path, std::ios::binary);
  std::ostringstream text;
  text << in.rdbuf();
  return text.str();
}

// Writes `parts` as consecutive gzip members (one member when there is one part), like gzip would.
void write_gzip(const fs::path& path, const std::vector<std::string>& parts) {
  for (std::size_t i = 0; i < parts.size(); ++i) {
    gzFile file = gzopen(path.c_str(), i == 0 ? "wb" : "ab");
    ASSERT_NE(file, nullptr) << path;
    if (!parts[i].empty()) {
      ASSERT_EQ(gzwrite(file, parts[i].data(), static_cast<unsigned>(parts[i].size())), static_cast<int>(parts[i].size()));
    }
    ASSERT_EQ(gzclose(file), Z_OK);
  }
}

// The message of the trivcon::Error that `action` throws; a test failure if it throws nothing or
// something else.
std::string error_of(const std::function<void()>& action) {
  try {
    action();
  } catch (const trivcon::Error& error) {
    return error.what();
  } catch (const std::exception& error) {
    ADD_FAILURE() << "expected trivcon::Error, got another exception: " << error.what();
    return {};
  }
  ADD_FAILURE() << "expected trivcon::Error, nothing was thrown";
  return {};
}

// The error a reader throws, or the one a front end that does not repair gives for a polygon with a repeated
// corner (the reader reads it and names the first in MeshData::repeated_vertex).
std::string read_error(const std::function<MeshData()>& read) {
  return error_of([&] {
    const MeshData m = read();
    if (!m.repeated_vertex.empty()) throw trivcon::Error(m.repeated_vertex);
  });
}
std::string obj_error(const std::string& text) {
  return read_error([&] { return trivcon::read_obj(text, "m.obj"); });
}
std::string off_error(const std::string& text) {
  return read_error([&] { return trivcon::read_off(text, "m.off"); });
}
std::string ply_error(const std::string& text) {
  return read_error([&] { return trivcon::read_ply(text, "m.ply"); });
}

std::string to_crlf(const std::string& text) {
  std::string out;
  for (char c : text) {
    if (c == '\n') out += '\r';
    out += c;
  }
  return out;
}

MatrixX3d matrix_v(const std::vector<std::array<double, 3>>& rows) {
  MatrixX3d V(static_cast<Eigen::Index>(rows.size()), 3);
  for (std::size_t i = 0; i < rows.size(); ++i) V.row(static_cast<Eigen::Index>(i)) << rows[i][0], rows[i][1], rows[i][2];
  return V;
}

MatrixX3i matrix_f(const std::vector<std::array<int, 3>>& rows) {
  MatrixX3i F(static_cast<Eigen::Index>(rows.size()), 3);
  for (std::size_t i = 0; i < rows.size(); ++i) F.row(static_cast<Eigen::Index>(i)) << rows[i][0], rows[i][1], rows[i][2];
  return F;
}

// Bitwise equality, so that -0.0 vs 0.0 or a changed last bit is caught.
bool bitwise_equal(const MatrixX3d& a, const MatrixX3d& b) {
  return a.rows() == b.rows() && std::memcmp(a.data(), b.data(), sizeof(double) * a.size()) == 0;
}

// Structural invariants every successful read must satisfy.
void expect_consistent(const MeshData& mesh) {
  ASSERT_EQ(mesh.polygon_of_triangle.size(), static_cast<std::size_t>(mesh.F.rows()));
  EXPECT_GT(mesh.F.rows(), 0);
  EXPECT_TRUE(mesh.V.allFinite());
  for (Eigen::Index f = 0; f < mesh.F.rows(); ++f) {
    for (int c = 0; c < 3; ++c) {
      ASSERT_GE(mesh.F(f, c), 0);
      ASSERT_LT(mesh.F(f, c), mesh.V.rows());
    }
    if (mesh.repeated_vertex.empty()) {  // a face with a repeated vertex is read and named there
      ASSERT_NE(mesh.F(f, 0), mesh.F(f, 1));
      ASSERT_NE(mesh.F(f, 1), mesh.F(f, 2));
      ASSERT_NE(mesh.F(f, 0), mesh.F(f, 2));
    }
    const int polygon = mesh.polygon_of_triangle[static_cast<std::size_t>(f)];
    ASSERT_GE(polygon, f == 0 ? 0 : mesh.polygon_of_triangle[static_cast<std::size_t>(f - 1)]);
    ASSERT_LT(polygon, mesh.polygon_count);
  }
}

// Binary PLY data in either byte order; `type` is a PLY type name (old or new spelling).
class PlyBytes {
 public:
  explicit PlyBytes(bool big_endian) : big_endian_(big_endian) {}

  void put(const std::string& type, double value) {
    if (type == "char" || type == "int8") return raw(static_cast<std::int8_t>(value));
    if (type == "uchar" || type == "uint8") return raw(static_cast<std::uint8_t>(value));
    if (type == "short" || type == "int16") return raw(static_cast<std::int16_t>(value));
    if (type == "ushort" || type == "uint16") return raw(static_cast<std::uint16_t>(value));
    if (type == "int" || type == "int32") return raw(static_cast<std::int32_t>(value));
    if (type == "uint" || type == "uint32") return raw(static_cast<std::uint32_t>(value));
    if (type == "float" || type == "float32") return raw(static_cast<float>(value));
    if (type == "double" || type == "float64") return raw(value);
    ADD_FAILURE() << "unknown type " << type;
  }
  const std::string& bytes() const { return bytes_; }

 private:
  template <class T>
  void raw(T value) {
    char buffer[sizeof(T)];
    std::memcpy(buffer, &value, sizeof buffer);
    const std::uint16_t probe = 1;
    const bool host_big = *reinterpret_cast<const unsigned char*>(&probe) == 0;
    if (host_big != big_endian_) std::reverse(buffer, buffer + sizeof buffer);
    bytes_.append(buffer, sizeof buffer);
  }

  bool big_endian_;
  std::string bytes_;
};

bool is_float_type(const std::string& type) { return type == "float" || type == "float32" || type == "double" || type == "float64"; }

// What a value of `type` holding `value` reads back as.
double stored_as(const std::string& type, double value) {
  if (type == "float" || type == "float32") return static_cast<float>(value);
  return value;
}

struct BinaryPlySpec {
  bool big_endian = false;
  std::string coordinate_type = "float";
  std::string count_type = "uchar";
  std::string index_type = "int";
  std::string index_name = "vertex_indices";
  bool extras = false;  // extra properties, lists and elements around the ones we read
  bool crlf_header = false;
};

// A binary PLY of the given vertices and polygons written by hand, independently of write_ply.
std::string make_binary_ply(const BinaryPlySpec& spec, const std::vector<std::array<double, 3>>& vertices,
                            const std::vector<std::vector<int>>& polygons) {
  std::string header =
      "ply\nformat " + std::string(spec.big_endian ? "binary_big_endian" : "binary_little_endian") + " 1.0\ncomment hand-made\n";
  if (spec.extras) header += "obj_info a test\nelement material 1\nproperty list uchar uchar name\n";
  header += "element vertex " + std::to_string(vertices.size()) + "\n";
  header += "property " + spec.coordinate_type + " x\n";
  if (spec.extras) header += "property uchar red\n";
  header += "property " + spec.coordinate_type + " y\n";
  if (spec.extras) header += "property list uchar float uv\n";
  header += "property " + spec.coordinate_type + " z\n";
  if (spec.extras) header += "property double confidence\nelement edge 1\nproperty int vertex1\nproperty int vertex2\n";
  header += "element face " + std::to_string(polygons.size()) + "\n";
  if (spec.extras) header += "property uchar flags\n";
  header += "property list " + spec.count_type + " " + spec.index_type + " " + spec.index_name + "\n";
  if (spec.extras) header += "property list ushort double other\nelement camera 1\nproperty float view_px\n";
  header += "end_header\n";
  if (spec.crlf_header) header = to_crlf(header);

  PlyBytes data(spec.big_endian);
  if (spec.extras) {  // material: name "ab"
    data.put("uchar", 2);
    data.put("uchar", 'a');
    data.put("uchar", 'b');
  }
  for (const auto& v : vertices) {
    data.put(spec.coordinate_type, v[0]);
    if (spec.extras) data.put("uchar", 200);
    data.put(spec.coordinate_type, v[1]);
    if (spec.extras) {
      data.put("uchar", 2);
      data.put("float", 0.25);
      data.put("float", 0.75);
    }
    data.put(spec.coordinate_type, v[2]);
    if (spec.extras) data.put("double", 0.5);
  }
  if (spec.extras) {  // edge
    data.put("int", 0);
    data.put("int", 1);
  }
  for (const auto& polygon : polygons) {
    if (spec.extras) data.put("uchar", 7);
    data.put(spec.count_type, static_cast<double>(polygon.size()));
    for (int index : polygon) data.put(spec.index_type, index);
    if (spec.extras) {
      data.put("ushort", 3);
      for (int i = 0; i < 3; ++i) data.put("double", i);
    }
  }
  if (spec.extras) data.put("float", 1.5);  // camera
  return header + data.bytes();
}

// A quad, two triangles and a pentagon over 6 vertices, and the expected fan triangulation.
const std::vector<std::vector<int>> kPolygons = {{0, 1, 2, 3}, {0, 1, 4}, {1, 2, 4}, {0, 4, 2, 5, 3}};
const MatrixX3i kTriangles = matrix_f({{0, 1, 2}, {0, 2, 3}, {0, 1, 4}, {1, 2, 4}, {0, 4, 2}, {0, 2, 5}, {0, 5, 3}});
const std::vector<int> kPolygonOfTriangle = {0, 0, 1, 2, 3, 3, 3};

// ------------------------------------------------------------------------------------------------
// OBJ

const char* const kObjVariants = R"(# a comment
mtllib scene.mtl
o thing
g group one
s off
v 0 0 0 1 0 0
v 1 0 0 1.0
v	1	1	0
v 0 1 0
v +1.5e0 -2.5E-1 .5
vt 0.1 0.2
vn 0 0 1
vp 0.5
usemtl red
f 1 2 3
f 1/1 3/1 4/1
f 1/1/1 2/1/1 5/1/1
f 2//1 3//1 5//1
f -5 -3 -2
l 1 2
p 1
f 1 2 3 4 5
f 4 3 \
  2
f 1 2 4 # trailing comment
v 2 2 2
f -1 -2 1
)";

TEST(ReadObj, AcceptsAllVariants) {
  for (const std::string& text : {std::string(kObjVariants), to_crlf(kObjVariants)}) {
    const MeshData mesh = trivcon::read_obj(text, "m.obj");
    EXPECT_EQ(mesh.format, "obj");
    EXPECT_TRUE(bitwise_equal(mesh.V, matrix_v({{0, 0, 0}, {1, 0, 0}, {1, 1, 0}, {0, 1, 0}, {1.5, -0.25, 0.5}, {2, 2, 2}})));
    EXPECT_EQ(
        mesh.F,
        matrix_f(
            {{0, 1, 2}, {0, 2, 3}, {0, 1, 4}, {1, 2, 4}, {0, 2, 3}, {0, 1, 2}, {0, 2, 3}, {0, 3, 4}, {3, 2, 1}, {0, 1, 3}, {5, 4, 0}}));
    EXPECT_EQ(mesh.polygon_of_triangle, (std::vector<int>{0, 1, 2, 3, 4, 5, 5, 5, 6, 7, 8}));
    EXPECT_EQ(mesh.polygon_count, 9);
  }
}

TEST(ReadObj, KeepsUnreferencedVerticesAndAllowsForwardReferences) {
  const MeshData mesh = trivcon::read_obj("f 2 3 4\nv 9 9 9\nv 0 0 0\nv 1 0 0\nv 0 1 0\nv 8 8 8\n", "m.obj");
  EXPECT_EQ(mesh.V.rows(), 5);
  EXPECT_EQ(mesh.V.row(0), Eigen::RowVector3d(9, 9, 9));
  EXPECT_EQ(mesh.V.row(4), Eigen::RowVector3d(8, 8, 8));
  EXPECT_EQ(mesh.F, matrix_f({{1, 2, 3}}));
}

TEST(ReadObj, ParsesNumbersExactly) {
  // Correct rounding (from_chars), denormals, underflow to zero, signs.
  const MeshData mesh = trivcon::read_obj(
      "v 0.1 -0.0 3.141592653589793\nv 4.9e-324 1e-400 -1e-400\nv 1.7976931348623157e308 2.2250738585072014e-308 "
      "0.30000000000000004\nf 1 2 3\n",
      "m.obj");
  EXPECT_EQ(mesh.V(0, 0), 0.1);
  EXPECT_TRUE(std::signbit(mesh.V(0, 1)));
  EXPECT_EQ(mesh.V(0, 2), 3.141592653589793);
  EXPECT_EQ(mesh.V(1, 0), std::numeric_limits<double>::denorm_min());
  EXPECT_EQ(mesh.V(1, 1), 0.0);
  EXPECT_TRUE(std::signbit(mesh.V(1, 2)));
  EXPECT_EQ(mesh.V(2, 0), std::numeric_limits<double>::max());
  EXPECT_EQ(mesh.V(2, 1), std::numeric_limits<double>::min());
  EXPECT_EQ(mesh.V(2, 2), 0.1 + 0.2);
}

TEST(ReadObj, ReportsErrorsWithFileAndLine) {
  EXPECT_EQ(obj_error(""), "m.obj: empty file");
  EXPECT_EQ(obj_error("# nothing\nv 0 0 0\nvt 0 0\n"), "m.obj: no faces");
  EXPECT_EQ(obj_error("v 0 0 0\nv 1 0 0\nv 0 1 0\nf 1 0 2\n"), "m.obj:4: face index 0 is invalid (OBJ indices start at 1)");
  EXPECT_EQ(obj_error("v 0 0 0\nv 1 0 0\nv 0 1 0\nf -1 -2 -4\n"), "m.obj:4: face index -4 out of range (3 vertices defined so far)");
  EXPECT_EQ(obj_error("f 1 2 5\nv 0 0 0\nv 1 0 0\nv 0 1 0\nf 1 2 3\n"), "m.obj:1: face index 5 out of range (file has 3 vertices)");
  EXPECT_EQ(obj_error("v 0 0 0\nv 1 0 0\nv 0 1 0\nf 1 2 99999999999\n"),
            "m.obj:4: face index 99999999999 out of range (too large for any file)");
  EXPECT_EQ(obj_error("v 0 0 0\nv 1 0 0\nv 0 1 0\n\n# x\nf 1 2 x\n"), "m.obj:6: malformed face corner 'x'");
  EXPECT_EQ(obj_error("v 0 0 0\nv 1 0 0\nv 0 1 0\nf 1 2/\n"), "m.obj:4: face 0 has 2 corners (at least 3 needed)");
  EXPECT_EQ(obj_error("v 0 0 0\nv 1 0 0\nv 0 1 0\nf 1/2/3\n"), "m.obj:4: face 0 has 1 corner (at least 3 needed)");
  EXPECT_EQ(obj_error("v 0 0 0\nv 1 0 0\nv 0 1 0\nf\n"), "m.obj:4: face 0 has 0 corners (at least 3 needed)");
  EXPECT_EQ(obj_error("v 0 0 0\nv 1 0\n"), "m.obj:2: expected 3 coordinates for vertex 1");
  EXPECT_EQ(obj_error("v 0 0 0\nv 1 0 0\nv 0 1 0\nv 1 1 1\nv 1 abc 0\n"), "m.obj:5: malformed number 'abc'");
  EXPECT_EQ(obj_error("v 1,5 0 0\n"), "m.obj:1: malformed number '1,5'");
  EXPECT_EQ(obj_error("v 0 0 0\nv nan 0 0\n"), "m.obj:2: non-finite coordinate in vertex 1 (nan)");
  EXPECT_EQ(obj_error("v 0 0 -inf\n"), "m.obj:1: non-finite coordinate in vertex 0 (-inf)");
  EXPECT_EQ(obj_error("v 0 1e999 0\n"), "m.obj:1: non-finite coordinate in vertex 0 (inf)");
  EXPECT_EQ(obj_error("v 0 0 0\r\nv 1 0 0\r\nv 0 1 0\r\nf 1 2 3 1\r\n"), "m.obj:4: face 0 has a repeated vertex (0, 1, 2, 0)");
  EXPECT_EQ(obj_error("v 0 0 0\nv 1 0 0\nv 0 1 0\nf 1 2 3\nf 1 \\\n 1 2\n"), "m.obj:5: face 1 has a repeated vertex (0, 0, 1)");

  // The example of the header: the fifth polygon, on line 15, repeats a vertex.
  std::string text;
  for (int v = 0; v < 10; ++v) text += "v " + std::to_string(v) + " 0 0\n";
  text += "f 1 2 3\nf 2 3 4\nf 3 4 5\nf 4 5 6\nf 4 4 10\n";
  EXPECT_EQ(obj_error(text), "m.obj:15: face 4 has a repeated vertex (3, 3, 9)");

  // The example of the header: index 40 in a file of 39 vertices.
  text.clear();
  for (int v = 0; v < 39; ++v) text += "v " + std::to_string(v) + " 1 2\n";
  text += "f 1 2 40\n";
  EXPECT_EQ(obj_error(text), "m.obj:40: face index 40 out of range (file has 39 vertices)");
}

TEST(ReadObj, LongPolygonsAreFannedAndChecked) {
  std::string text;
  for (int v = 0; v < 40; ++v) text += "v " + std::to_string(std::cos(v)) + " " + std::to_string(std::sin(v)) + " 0\n";
  text += "f";
  for (int v = 1; v <= 40; ++v) text += " " + std::to_string(v);
  const MeshData mesh = trivcon::read_obj(text + "\n", "m.obj");
  ASSERT_EQ(mesh.F.rows(), 38);
  for (int t = 0; t < 38; ++t) EXPECT_EQ(mesh.F.row(t), Eigen::RowVector3i(0, t + 1, t + 2));
  EXPECT_EQ(mesh.polygon_count, 1);
  EXPECT_THAT(obj_error(text + " 17\n"), AllOf(StartsWith("m.obj:41: face 0 has a repeated vertex (0, 1, 2,"), HasSubstr(", ...)")));
}

// ------------------------------------------------------------------------------------------------
// OFF

const MatrixX3d kOffVertices = matrix_v({{0, 0, 0}, {1, 0, 0}, {1, 1, 0}, {0, 1, 0}, {0.5, 0.5, 1.5}});
const MatrixX3i kOffTriangles = matrix_f({{0, 1, 2}, {0, 2, 3}, {0, 1, 4}});

TEST(ReadOff, AcceptsAllVariants) {
  const std::vector<std::string> files = {
      // Plain.
      "OFF\n5 2 0\n0 0 0\n1 0 0\n1 1 0\n0 1 0\n0.5 0.5 1.5\n4 0 1 2 3\n3 0 1 4\n",
      // Comments before and inside, blank lines, counts on the header line, colours (COFF), no final newline.
      "# Output of a CGAL tool\n#CBP\n\nCOFF 5 2 0  # counts here\n# vertices\n0 0 0 255 0 0 255\n1 0 0 0 255 0 255\n\n"
      "1 1 0 0 0 255 255\n0 1 0 1 1 1 1\n  0.5 0.5 1.5 1 1 1 1\n# faces\n4 0 1 2 3 255 0 0\n3 0 1 4 0.5 0.5 0.5 1",
      // Normals (NOFF), edge count omitted, tabs.
      "NOFF\n5\t2\n0 0 0 0 0 1\n1 0 0 0 0 1\n1 1 0 0 0 1\n0 1 0 0 0 1\n0.5 0.5 1.5 0 0 1\n4\t0 1 2 3\n3 0 1 4\n",
      // Other [ST][C][N] variants.
      "STOFF\n5 2 0\n0 0 0 0 0\n1 0 0 1 0\n1 1 0 1 1\n0 1 0 0 1\n0.5 0.5 1.5 0 0\n4 0 1 2 3\n3 0 1 4\n",
      "CNOFF 5 2 0\n0 0 0 0 0 1 1 1 1 1\n1 0 0 0 0 1 1 1 1 1\n1 1 0 0 0 1 1 1 1 1\n0 1 0 0 0 1 1 1 1 1\n"
      "0.5 0.5 1.5 0 0 1 1 1 1 1\n4 0 1 2 3\n3 0 1 4\n",
      // No keyword: the counts come first (the keyword is optional in Geomview's definition).
      "5 2 0\n0 0 0\n1 0 0\n1 1 0\n0 1 0\n0.5 0.5 1.5\n4 0 1 2 3\n3 0 1 4\n",
      // Trailing content after the announced faces is ignored.
      "OFF\n5 2 0\n0 0 0\n1 0 0\n1 1 0\n0 1 0\n0.5 0.5 1.5\n4 0 1 2 3\n3 0 1 4\n\n# end\n",
  };
  for (const std::string& file : files) {
    for (const std::string& text : {file, to_crlf(file)}) {
      SCOPED_TRACE(text);
      const MeshData mesh = trivcon::read_off(text, "m.off");
      EXPECT_EQ(mesh.format, "off");
      EXPECT_TRUE(bitwise_equal(mesh.V, kOffVertices));
      EXPECT_EQ(mesh.F, kOffTriangles);
      EXPECT_EQ(mesh.polygon_of_triangle, (std::vector<int>{0, 0, 1}));
      EXPECT_EQ(mesh.polygon_count, 2);
    }
  }
}

TEST(ReadOff, ReportsErrorsWithFileAndLine) {
  EXPECT_EQ(off_error(""), "m.off: empty file");
  EXPECT_EQ(off_error("# only a comment\n\n"), "m.off: no OFF header (only comments and blank lines)");
  EXPECT_EQ(off_error("OFF\n# nothing else\n"), "m.off:2: file ends before the vertex and face counts");
  EXPECT_EQ(off_error("OFF\n3\n"), "m.off:2: expected the face count after the vertex count");
  EXPECT_EQ(off_error("hello world\n"), "m.off:1: not an OFF file: expected 'OFF', found 'hello'");
  EXPECT_EQ(off_error("4OFF\n3 1 0\n"), "m.off:1: unsupported OFF variant '4OFF' (only 3-D [ST][C][N]OFF is supported)");
  EXPECT_EQ(off_error("OFF BINARY\n"), "m.off:1: binary OFF is not supported");
  EXPECT_EQ(off_error("OFF\n3 0 0\n0 0 0\n1 0 0\n0 1 0\n"), "m.off: no faces");
  EXPECT_EQ(off_error("OFF\n-3 1 0\n0 0 0\n1 0 0\n0 1 0\n3 0 1 2\n"), "m.off:2: negative vertex or face count");
  EXPECT_EQ(off_error("OFF\n3 x 0\n"), "m.off:2: malformed integer 'x'");
  // The example of the header: vertex 1 on line 3 has two coordinates.
  EXPECT_EQ(off_error("OFF 3 1 0\n0 0 0\n1 0\n0 1 0\n3 0 1 2\n"), "m.off:3: expected 3 coordinates for vertex 1");
  EXPECT_EQ(off_error("OFF 3 1 0\n0 0 0\n1 0 0\n0 x 0\n3 0 1 2\n"), "m.off:4: malformed number 'x'");
  EXPECT_EQ(off_error("OFF 3 1 0\n0 0 0\n1 NaN 0\n0 1 0\n3 0 1 2\n"), "m.off:3: non-finite coordinate in vertex 1 (nan)");
  EXPECT_EQ(off_error("OFF 3 1 0\n0 0 0\n1 0 0\n0 1 0\n3 0 1 3\n"), "m.off:5: face index 3 out of range (file has 3 vertices)");
  EXPECT_EQ(off_error("OFF 3 1 0\n0 0 0\n1 0 0\n0 1 0\n3 0 -1 2\n"), "m.off:5: face index -1 out of range (file has 3 vertices)");
  EXPECT_EQ(off_error("OFF 3 1 0\n0 0 0\n1 0 0\n0 1 0\n2 0 1\n"), "m.off:5: face 0 has 2 corners (at least 3 needed)");
  EXPECT_EQ(off_error("OFF 3 1 0\n0 0 0\n1 0 0\n0 1 0\n4 0 1 2\n"), "m.off:5: face 0 announces 4 corners but lists 3");
  EXPECT_EQ(off_error("OFF 3 1 0\n0 0 0\n1 0 0\n0 1 0\n3 0 1 1\n"), "m.off:5: face 0 has a repeated vertex (0, 1, 1)");
  EXPECT_EQ(off_error("OFF 3 1 0\n0 0 0\n1 0 0\n0 1 0\n3.0 0 1 2\n"), "m.off:5: malformed integer '3.0'");
  // Fewer lines than announced: the line where the file ends.
  EXPECT_EQ(off_error("OFF\n3 1 0\n0.000000000 0.000000000 0.000000000\n1.000000000 0.000000000 0.000000000\n"),
            "m.off:4: file ends after 2 of 3 vertices (truncated?)");
  EXPECT_EQ(off_error("OFF\n3 2 0\n0 0 0\n1 0 0\n0 1 0\n3 0 1 2\n\n# the end\n"), "m.off:8: file ends after 1 of 2 faces (truncated?)");
  // Counts that cannot fit in the file are rejected before anything is allocated for them.
  EXPECT_EQ(off_error("OFF\n1000000000000 1 0\n0 0 0\n3 0 0 0\n"),
            "m.off:2: header claims 1000000000000 vertices, but the file has only 14 bytes after the header (a vertex needs at least 6)");
  EXPECT_EQ(off_error("OFF\n3 2000000000 0\n0 0 0\n1 0 0\n0 1 0\n3 0 1 2\n"),
            "m.off:2: header claims 2000000000 faces, but the file has only 26 bytes after the header (a face needs at least 8)");
  EXPECT_EQ(off_error("OFF\n99999999999999999999 1 0\n"), "m.off:2: malformed integer '99999999999999999999'");
  // A bogus corner count is caught by the line running out, not by allocating for it.
  EXPECT_EQ(off_error("OFF\n3 1 0\n0 0 0\n1 0 0\n0 1 0\n2000000000 0 1 2\n"), "m.off:6: face 0 announces 2000000000 corners but lists 3");
}

// ------------------------------------------------------------------------------------------------
// PLY

const std::vector<std::array<double, 3>> kPlyVertices = {{0, 0, 0}, {1, 0, 0}, {1, 1, 0}, {0, 1, 0}, {0, 0, 2}, {2, 1, 0}};
const std::vector<std::array<double, 3>> kPlyFractionalVertices = {{0.1, -0.2, 0.3}, {1.5, 0, -7.25}, {1, 1e-3, 0},
                                                                   {-0.0, 1, 1e10},  {0, 0, 2},       {2, 1, 0}};

const char* const kAsciiPly = R"(ply
format ascii 1.0
comment made by hand
obj_info for a test
element material 1
property list uchar uchar name
element vertex 6
property float x
property uchar red
property float y
property list uchar float uv
property float z
property double confidence
element edge 2
property int vertex1
property int vertex2
element face 4
property uchar flags
property list uchar int vertex_indices
property list int float other
element camera 1
property float view_px
end_header
2 97 98
0.1 255 -0.2 2 0.25 0.75 0.3 1
1.5 0 0 0 -7.25 0.5
1 1 1e-3 1 0 0 1

-0 3 1 0 1e10 1
0 4 0 0 2 1
2 5 1 0 0 1
0 1
1 2
0 4 0 1 2 3 0
1 3 0 1 4 2 1.5 2.5
2 3 1 2 4 0
3 5 0 4 2 5 3 1 9
0.5
)";

TEST(ReadPly, AcceptsAscii) {
  for (const std::string& text : {std::string(kAsciiPly), to_crlf(kAsciiPly)}) {
    const MeshData mesh = trivcon::read_ply(text, "m.ply");
    EXPECT_EQ(mesh.format, "ply-ascii");
    // ASCII values are read as written (not rounded to float).
    EXPECT_TRUE(bitwise_equal(mesh.V, matrix_v(kPlyFractionalVertices)));
    EXPECT_EQ(mesh.F, kTriangles);
    EXPECT_EQ(mesh.polygon_of_triangle, kPolygonOfTriangle);
    EXPECT_EQ(mesh.polygon_count, 4);
  }
}

TEST(ReadPly, AcceptsBinaryOfEveryTypeAndByteOrder) {
  const std::vector<std::string> coordinate_types = {"float", "float32", "double", "float64", "int",   "int32",
                                                     "uint",  "short",   "int16",  "ushort",  "uchar", "int8"};
  const std::vector<std::string> count_types = {"uchar", "uint8", "char", "ushort", "short", "int", "uint", "int32", "uint32"};
  const std::vector<std::string> index_types = {"int", "uint", "int32", "uint32", "short", "int16", "ushort", "uint16", "uchar", "char"};
  int combination = 0;
  for (bool big_endian : {false, true}) {
    for (const std::string& coordinate_type : coordinate_types) {
      for (const std::string& count_type : count_types) {
        for (const std::string& index_type : index_types) {
          BinaryPlySpec spec;
          spec.big_endian = big_endian;
          spec.coordinate_type = coordinate_type;
          spec.count_type = count_type;
          spec.index_type = index_type;
          spec.extras = combination % 2 == 0;
          spec.crlf_header = combination % 3 == 0;
          spec.index_name = combination % 5 == 0 ? "vertex_index" : "vertex_indices";
          ++combination;
          const auto& vertices = is_float_type(coordinate_type) ? kPlyFractionalVertices : kPlyVertices;
          SCOPED_TRACE(coordinate_type + " " + count_type + " " + index_type + (big_endian ? " BE" : " LE") +
                       (spec.extras ? " extras" : ""));
          const MeshData mesh = trivcon::read_ply(make_binary_ply(spec, vertices, kPolygons), "m.ply");
          EXPECT_EQ(mesh.format, big_endian ? "ply-binary-be" : "ply-binary-le");
          ASSERT_EQ(mesh.V.rows(), 6);
          for (int v = 0; v < 6; ++v) {
            for (int axis = 0; axis < 3; ++axis) EXPECT_EQ(mesh.V(v, axis), stored_as(coordinate_type, vertices[v][axis]));
          }
          EXPECT_EQ(mesh.F, kTriangles);
          EXPECT_EQ(mesh.polygon_of_triangle, kPolygonOfTriangle);
          EXPECT_EQ(mesh.polygon_count, 4);
        }
      }
    }
  }
}

TEST(ReadPly, KeepsUnreferencedVertices) {
  BinaryPlySpec spec;
  const MeshData mesh = trivcon::read_ply(make_binary_ply(spec, kPlyVertices, {{5, 2, 1}}), "m.ply");
  EXPECT_EQ(mesh.V.rows(), 6);
  EXPECT_EQ(mesh.F, matrix_f({{5, 2, 1}}));
}

TEST(ReadPly, ReportsHeaderErrors) {
  const std::string vertices = "element vertex 3\nproperty float x\nproperty float y\nproperty float z\n";
  const std::string faces = "element face 1\nproperty list uchar int vertex_indices\n";
  const std::string data = "0 0 0\n1 0 0\n0 1 0\n3 0 1 2\n";
  EXPECT_EQ(ply_error(""), "m.ply: empty file");
  EXPECT_EQ(ply_error("plyx\n"), "m.ply: not a PLY file (the first line is not 'ply')");
  EXPECT_EQ(ply_error("\x89PNG\r\n\x1a\n"), "m.ply: not a PLY file (the first line is not 'ply')");
  // The example of the header: an unknown format on line 7.
  EXPECT_EQ(ply_error("ply\ncomment a\ncomment b\ncomment c\ncomment d\nobj_info e\nformat binary_middle_endian 1.0\n" + vertices + faces +
                      "end_header\n"),
            "m.ply:7: unsupported PLY format 'binary_middle_endian'");
  EXPECT_EQ(ply_error("ply\nformat ascii 1.0\n" + vertices + faces), "m.ply: PLY header has no 'end_header' line");
  EXPECT_EQ(ply_error("ply\n" + vertices + faces + "end_header\n" + data), "m.ply: PLY header has no 'format' line");
  EXPECT_EQ(ply_error("ply\nformat ascii 1.0\nproperty float x\n"), "m.ply:3: property before any element");
  EXPECT_EQ(ply_error("ply\nformat ascii 1.0\nelement vertex 3\nproperty float128 x\n"), "m.ply:4: unknown PLY type 'float128'");
  EXPECT_EQ(ply_error("ply\nformat ascii 1.0\nelement vertex 3\nproperty list float int x\n"),
            "m.ply:4: list count type must be an integer type");
  EXPECT_EQ(ply_error("ply\nformat ascii 1.0\nelement vertex -3\n"), "m.ply:3: element 'vertex' needs a count, found '-3'");
  EXPECT_EQ(ply_error("ply\nformat ascii 1.0\nbogus line\nend_header\n"), "m.ply:3: unexpected PLY header line starting with 'bogus'");
  EXPECT_EQ(ply_error("ply\nformat ascii 1.0\n" + faces + "end_header\n3 0 1 2\n"), "m.ply: PLY header declares no 'vertex' element");
  EXPECT_EQ(ply_error("ply\nformat ascii 1.0\n" + vertices + "end_header\n" + data), "m.ply: no faces");
  EXPECT_EQ(ply_error("ply\nformat ascii 1.0\n" + vertices +
                      "element face 0\nproperty list uchar int vertex_indices\nend_header\n0 0 0\n1 0 0\n0 1 0\n"),
            "m.ply: no faces");
  EXPECT_EQ(ply_error("ply\nformat ascii 1.0\nelement vertex 3\nproperty float x\nproperty float y\n" + faces + "end_header\n" + data),
            "m.ply:3: vertex element has no scalar property 'z'");
  EXPECT_EQ(ply_error("ply\nformat ascii 1.0\n" + vertices + "element face 1\nproperty list uchar int corners\nend_header\n" + data),
            "m.ply:7: face element has no list property 'vertex_indices'");
  EXPECT_EQ(
      ply_error("ply\nformat ascii 1.0\n" + vertices + "element face 1\nproperty list uchar float vertex_indices\nend_header\n" + data),
      "m.ply:7: face vertex_indices must have an integer item type");
  EXPECT_EQ(ply_error("ply\nformat ascii 1.0\n" + vertices + faces + "element empty 5\nend_header\n" + data),
            "m.ply:9: element 'empty' has no properties");
}

TEST(ReadPly, ReportsAsciiDataErrors) {
  const std::string header =
      "ply\nformat ascii 1.0\nelement vertex 3\nproperty float x\nproperty float y\nproperty float z\n"
      "element face 1\nproperty list uchar int vertex_indices\nend_header\n";  // data starts on line 10
  EXPECT_EQ(ply_error(header + "0 0 0\n1 0\n0 1 0\n3 0 1 2\n"), "m.ply:11: too few values for vertex 1 (the header lists more properties)");
  EXPECT_EQ(ply_error(header + "0 0 0\n1 0 0 7\n0 1 0\n3 0 1 2\n"), "m.ply:11: unexpected extra value '7' for vertex 1");
  EXPECT_EQ(ply_error(header + "0 0 0\n1 0 0\n0 one 0\n3 0 1 2\n"), "m.ply:12: malformed number 'one'");
  EXPECT_EQ(ply_error(header + "0 0 0\n1 0 0\n0 1 nan\n3 0 1 2\n"), "m.ply:12: non-finite coordinate in vertex 2 (nan)");
  EXPECT_EQ(ply_error(header + "0 0 0\n1 0 0\n0 1 0\n3 0 1 3\n"), "m.ply:13: face index 3 out of range (file has 3 vertices) in face 0");
  EXPECT_EQ(ply_error(header + "0 0 0\n1 0 0\n0 1 0\n3 0 1 0\n"), "m.ply:13: face 0 has a repeated vertex (0, 1, 0)");
  EXPECT_EQ(ply_error(header + "0 0 0\n1 0 0\n0 1 0\n2 0 1\n"), "m.ply:13: face 0 has 2 corners (at least 3 needed)");
  EXPECT_EQ(ply_error(header + "0 0 0\n1 0 0\n0 1 0\n-3 0 1 2\n"), "m.ply:13: negative list length -3 in face 0");
  EXPECT_EQ(ply_error(header + "0 0 0\n1 0 0\n0 1 0\n1000000000 0 1 2\n"),
            "m.ply:13: face 0 announces 1000000000 'vertex_indices' but lists 3");
  EXPECT_EQ(ply_error(header + "0 0 0\n1 0 0\n0 1 0\n3 0 1 2.5\n"), "m.ply:13: malformed integer '2.5'");
  EXPECT_EQ(ply_error(header + "0 0 0\n1 0 0\n0 1 0\n\n\n"), "m.ply:14: file ends after 0 of 1 'face' elements (truncated?)");
  EXPECT_EQ(ply_error("ply\nformat ascii 1.0\nelement vertex 1000000000000\nproperty float x\nproperty float y\nproperty float z\n"
                      "element face 1\nproperty list uchar int vertex_indices\nend_header\n0 0 0\n3 0 0 0\n"),
            "m.ply:3: header claims 1000000000000 vertices, but the file has only 14 bytes after the header (a vertex needs at least 6)");
}

TEST(ReadPly, ReportsBinaryDataErrorsWithByteOffsets) {
  BinaryPlySpec spec;
  const std::string good = make_binary_ply(spec, kPlyVertices, {{0, 1, 2}});
  const std::size_t data_start = good.find("end_header\n") + 11;
  ASSERT_EQ(good.size(), data_start + 6 * 12 + 13);

  // Cut inside the face: the first missing byte and the element are named.
  EXPECT_EQ(ply_error(good.substr(0, good.size() - 2)),
            "m.ply: truncated binary data at byte " + std::to_string(data_start + 72 + 9) +
                " (face 0 of 1; its 'vertex_indices' list claims 3 items of 4 bytes, but only 10 bytes follow the count)");
  // Cut inside a vertex whose size the header cannot bound (it has a list).
  spec.extras = true;
  const std::string with_lists = make_binary_ply(spec, kPlyVertices, {{0, 1, 2}});
  const std::size_t extras_start = with_lists.find("end_header\n") + 11;
  const std::size_t vertex_size = 4 + 1 + 4 + 1 + 8 + 4 + 8;
  const std::string cut = with_lists.substr(0, extras_start + 3 + 5 * vertex_size + 7);  // 3: the material
  EXPECT_EQ(ply_error(cut),
            "m.ply: truncated binary data at byte " + std::to_string(extras_start + 3 + 5 * vertex_size + 5) + " (vertex 5 of 6)");

  // Values that are wrong rather than missing.
  std::string bad_index = good;
  bad_index[data_start + 72 + 9] = 6;  // the third index (little-endian int) becomes 6
  EXPECT_EQ(ply_error(bad_index),
            "m.ply: face index 6 out of range (file has 6 vertices) in face 0 (at byte " + std::to_string(data_start + 72) + ")");
  std::string repeated = good;
  repeated[data_start + 72 + 9] = 1;
  EXPECT_EQ(ply_error(repeated), "m.ply: face 0 has a repeated vertex (0, 1, 1) (at byte " + std::to_string(data_start + 72) + ")");
  std::string nan = good;
  const float not_a_number = std::numeric_limits<float>::quiet_NaN();
  std::memcpy(&nan[data_start + 12 + 4], &not_a_number, 4);  // y of vertex 1
  EXPECT_EQ(ply_error(nan), "m.ply: non-finite coordinate in vertex 1 (nan) (at byte " + std::to_string(data_start + 12) + ")");
  spec = BinaryPlySpec();
  spec.count_type = "int";
  std::string negative = make_binary_ply(spec, kPlyVertices, {{0, 1, 2}});
  const std::size_t int_count_start = negative.find("end_header\n") + 11;
  const std::int32_t minus_one = -1;
  std::memcpy(&negative[int_count_start + 72], &minus_one, 4);
  EXPECT_EQ(ply_error(negative), "m.ply: negative list length -1 in face 0 (at byte " + std::to_string(int_count_start + 72) + ")");
  // A list count of four billion is compared with the data left instead of allocating.
  spec.count_type = "uint";
  std::string huge_list = make_binary_ply(spec, kPlyVertices, {{0, 1, 2}});
  const std::size_t uint_count_start = huge_list.find("end_header\n") + 11;
  const std::uint32_t four_billion = 4000000000u;
  std::memcpy(&huge_list[uint_count_start + 72], &four_billion, 4);
  EXPECT_EQ(ply_error(huge_list), "m.ply: truncated binary data at byte " + std::to_string(huge_list.size()) +
                                      " (face 0 of 1; its 'vertex_indices' list claims 4000000000 items of 4 bytes, but only 12 bytes "
                                      "follow the count)");

  // Counts beyond what the data can hold are rejected before anything is allocated.
  std::string huge = good;
  huge.replace(huge.find("element vertex 6"), 16, "element vertex 1000000000000");
  EXPECT_EQ(ply_error(huge),
            "m.ply:4: header claims 1000000000000 vertices, but the file has only 85 bytes after the header (a vertex needs at least 12)");
  huge = good;
  huge.replace(huge.find("element face 1"), 14, "element face 4000000000");
  EXPECT_THAT(ply_error(huge), HasSubstr("m.ply:8: header claims 4000000000 faces, but the file has only 85 bytes"));
}

// ------------------------------------------------------------------------------------------------
// Malformed input of every kind: always a trivcon::Error, never a crash (run under ASan/UBSan).

struct Sample {
  std::string name;
  std::string bytes;
  std::function<MeshData(const std::string&, const std::string&)> read;
  bool counted;  // the header announces counts, so a cut before the last line is always detected
};

std::vector<Sample> samples() {
  BinaryPlySpec little;
  little.extras = true;
  BinaryPlySpec big = little;
  big.big_endian = true;
  big.coordinate_type = "double";
  big.count_type = "int";
  return {
      {"m.obj", kObjVariants, trivcon::read_obj, false},
      {"m.off", "OFF\n# c\n5 2 0\n0 0 0\n1 0 0\n1 1 0\n0 1 0\n0.5 0.5 1.5\n4 0 1 2 3\n3 0 1 4\n", trivcon::read_off, true},
      {"m.ply", kAsciiPly, trivcon::read_ply, true},
      {"m.ply", make_binary_ply(little, kPlyFractionalVertices, kPolygons), trivcon::read_ply, true},
      {"m.ply", make_binary_ply(big, kPlyFractionalVertices, kPolygons), trivcon::read_ply, true},
  };
}

// Calls the reader; a success must give a consistent mesh, a failure must be a trivcon::Error that
// names the file. Returns whether it threw.
bool read_or_error(const Sample& sample, const std::string& bytes) {
  try {
    const MeshData mesh = sample.read(bytes, sample.name);
    expect_consistent(mesh);
    return false;
  } catch (const trivcon::Error& error) {
    EXPECT_THAT(error.what(), StartsWith(sample.name + ":"));
    return true;
  } catch (const std::exception& error) {
    ADD_FAILURE() << "not a trivcon::Error: " << error.what();
    return true;
  }
}

TEST(Malformed, TruncatedAtEveryByte) {
  for (const Sample& sample : samples()) {
    const bool binary = sample.bytes.find("binary_") != std::string::npos;
    const std::size_t last_line = sample.bytes.find_last_of('\n', sample.bytes.size() - 2) + 1;
    for (std::size_t cut = 0; cut < sample.bytes.size(); ++cut) {
      SCOPED_TRACE(sample.name + " cut at " + std::to_string(cut));
      const bool threw = read_or_error(sample, sample.bytes.substr(0, cut));
      if (binary || (sample.counted && cut < last_line)) {
        EXPECT_TRUE(threw);
      }
    }
  }
}

TEST(Malformed, RandomMutations) {
  std::mt19937 random(12345);
  const std::string interesting = "0123456789 -+.eE\n\r\t#/\\xnaif";
  for (const Sample& sample : samples()) {
    for (int trial = 0; trial < 3000; ++trial) {
      std::string bytes = sample.bytes;
      const int edits = 1 + static_cast<int>(random() % 4);
      for (int e = 0; e < edits && !bytes.empty(); ++e) {
        const std::size_t at = random() % bytes.size();
        const char c = random() % 3 ? interesting[random() % interesting.size()] : static_cast<char>(random() % 256);
        switch (random() % 3) {
          case 0:
            bytes[at] = c;
            break;
          case 1:
            bytes.insert(bytes.begin() + static_cast<std::ptrdiff_t>(at), c);
            break;
          default:
            bytes.erase(at, 1 + random() % 8);
            break;
        }
      }
      SCOPED_TRACE(sample.name + " trial " + std::to_string(trial));
      read_or_error(sample, bytes);
      if (HasFailure()) return;
    }
  }
}

TEST(Malformed, GarbageBytes) {
  std::mt19937 random(7);
  for (int trial = 0; trial < 200; ++trial) {
    std::string garbage(1 + random() % 2000, '\0');
    for (char& c : garbage) c = static_cast<char>(random() % 256);
    EXPECT_THAT(obj_error(garbage), StartsWith("m.obj"));
    EXPECT_THAT(off_error(garbage), StartsWith("m.off"));
    EXPECT_THAT(ply_error(garbage), StartsWith("m.ply"));
    EXPECT_THAT(ply_error("ply\nformat binary_little_endian 1.0\n" + garbage), StartsWith("m.ply"));
  }
}

// ------------------------------------------------------------------------------------------------
// Files, gzip and writers

TEST(Files, ReadFileBytesNamesTheFile) {
  const fs::path dir = test_dir();
  const std::string missing = (dir / "x.obj").string();
  EXPECT_EQ(error_of([&] { trivcon::read_file_bytes(missing); }), "cannot open '" + missing + "': No such file or directory");
  EXPECT_EQ(error_of([&] { trivcon::read_mesh(missing); }), "cannot open '" + missing + "': No such file or directory");
  EXPECT_EQ(error_of([&] { trivcon::read_file_bytes(dir.string()); }), "cannot read '" + dir.string() + "': Is a directory");
  write_bytes(dir / "bytes.bin", std::string("a\0b\r\n\xff", 6));
  EXPECT_EQ(trivcon::read_file_bytes((dir / "bytes.bin").string()), std::string("a\0b\r\n\xff", 6));
}

TEST(Files, ReadMeshDispatchesOnTheExtension) {
  const fs::path dir = test_dir();
  write_bytes(dir / "a.OBJ", "v 0 0 0\nv 1 0 0\nv 0 1 0\nf 1 2 3\n");
  write_bytes(dir / "a.Off", "OFF\n3 1 0\n0 0 0\n1 0 0\n0 1 0\n3 0 1 2\n");
  write_bytes(dir / "a.ply", kAsciiPly);
  EXPECT_EQ(trivcon::read_mesh((dir / "a.OBJ").string()).format, "obj");
  EXPECT_EQ(trivcon::read_mesh((dir / "a.Off").string()).format, "off");
  EXPECT_EQ(trivcon::read_mesh((dir / "a.ply").string()).format, "ply-ascii");
  const std::string vtk = (dir / "a.vtk").string();
  EXPECT_EQ(error_of([&] { trivcon::read_mesh(vtk); }),
            "cannot read '" + vtk + "': unknown mesh format (supported: .obj, .off, .ply, .stl, .gltf, .glb, each optionally followed by .gz)");
  EXPECT_THAT(error_of([&] { trivcon::read_mesh((dir / "a.gz").string()); }), HasSubstr("unknown mesh format"));
  // Errors inside a file name the path as given.
  write_bytes(dir / "bad.obj", "v 0 0 0\nv 1 0 0\nv 0 1 0\nf 1 2 4\n");
  EXPECT_EQ(error_of([&] { trivcon::read_mesh((dir / "bad.obj").string()); }),
            (dir / "bad.obj").string() + ":4: face index 4 out of range (file has 3 vertices)");
}

TEST(Files, ReadsGzip) {
  const fs::path dir = test_dir();
  write_gzip(dir / "a.obj.gz", {kObjVariants});
  const MeshData from_gzip = trivcon::read_mesh((dir / "a.obj.gz").string());
  const MeshData plain = trivcon::read_obj(kObjVariants, "a.obj");
  EXPECT_TRUE(bitwise_equal(from_gzip.V, plain.V));
  EXPECT_EQ(from_gzip.F, plain.F);
  EXPECT_EQ(from_gzip.polygon_of_triangle, plain.polygon_of_triangle);

  // Upper case suffix, binary PLY, several members back to back (cat a.gz b.gz), an empty member.
  const std::string binary = make_binary_ply(BinaryPlySpec(), kPlyVertices, kPolygons);
  write_gzip(dir / "b.PLY.GZ", {binary.substr(0, 100), "", binary.substr(100)});
  const MeshData ply = trivcon::read_mesh((dir / "b.PLY.GZ").string());
  EXPECT_EQ(ply.format, "ply-binary-le");
  EXPECT_EQ(ply.F, kTriangles);
  EXPECT_EQ(trivcon::read_file_bytes((dir / "b.PLY.GZ").string()), binary);

  write_gzip(dir / "c.off.gz", {"OFF\n3 1 0\n0 0 0\n1 0 0\n0 1 0\n3 0 1 2\n"});
  EXPECT_EQ(trivcon::read_mesh((dir / "c.off.gz").string()).F, matrix_f({{0, 1, 2}}));

  // Zero padding after the last member is ignored, as gzip does.
  std::string padded = read_bytes(dir / "c.off.gz") + std::string(16, '\0');
  write_bytes(dir / "d.off.gz", padded);
  EXPECT_EQ(trivcon::read_mesh((dir / "d.off.gz").string()).F, matrix_f({{0, 1, 2}}));
}

TEST(Files, RejectsBadGzip) {
  const fs::path dir = test_dir();
  std::string text;
  for (int v = 0; v < 200; ++v) text += "v " + std::to_string(v) + " " + std::to_string(v * v) + " 0.5\n";
  text += "f 1 2 3\n";
  write_gzip(dir / "good.obj.gz", {text});
  const std::string compressed = read_bytes(dir / "good.obj.gz");

  const std::string plain = (dir / "plain.obj.gz").string();
  write_bytes(plain, text);
  EXPECT_THAT(error_of([&] { trivcon::read_mesh(plain); }), StartsWith(plain + ": corrupt gzip data"));

  const std::string empty = (dir / "empty.obj.gz").string();
  write_bytes(empty, "");
  EXPECT_EQ(error_of([&] { trivcon::read_mesh(empty); }), empty + ": empty file");

  const std::string garbage_after = (dir / "garbage.obj.gz").string();
  write_bytes(garbage_after, compressed + "junk");
  EXPECT_THAT(error_of([&] { trivcon::read_mesh(garbage_after); }), StartsWith(garbage_after + ": corrupt gzip data"));

  // Every truncation and many corruptions are detected (the gzip trailer has a CRC and a length).
  const std::string cut = (dir / "cut.obj.gz").string();
  for (std::size_t size = 1; size < compressed.size(); ++size) {
    write_bytes(cut, compressed.substr(0, size));
    EXPECT_THAT(error_of([&] { trivcon::read_mesh(cut); }), StartsWith(cut + ": ")) << size;
  }
  const std::string flipped = (dir / "flipped.obj.gz").string();
  for (std::size_t at = 10; at < compressed.size(); at += 3) {
    std::string bytes = compressed;
    bytes[at] = static_cast<char>(bytes[at] ^ 0x5a);
    write_bytes(flipped, bytes);
    EXPECT_THAT(error_of([&] { trivcon::read_file_bytes(flipped); }), StartsWith(flipped + ": ")) << at;
  }
}

TEST(Writers, RoundTripExactly) {
  const fs::path dir = test_dir();
  std::mt19937_64 random(99);
  std::uniform_real_distribution<double> uniform(-10, 10);
  MatrixX3d V(300, 3);
  for (Eigen::Index v = 0; v < V.rows(); ++v) {
    for (int axis = 0; axis < 3; ++axis) V(v, axis) = uniform(random) * std::pow(10.0, static_cast<int>(random() % 40) - 20);
  }
  // Awkward values: signed zero, extremes, denormals, values that need all 17 digits.
  V.row(0) << -0.0, std::numeric_limits<double>::denorm_min(), -std::numeric_limits<double>::max();
  V.row(1) << std::numeric_limits<double>::min(), 0.1 + 0.2, 1.0 / 3.0;
  V.row(2) << std::nextafter(1.0, 2.0), -std::nextafter(0.0, 1.0) * 12345, 1e300;
  MatrixX3i F(500, 3);
  for (Eigen::Index f = 0; f < F.rows(); ++f) {
    const int a = static_cast<int>(random() % 300);
    F.row(f) << a, (a + 1 + static_cast<int>(random() % 298)) % 300, 0;
    do F(f, 2) = static_cast<int>(random() % 300);
    while (F(f, 2) == F(f, 0) || F(f, 2) == F(f, 1));
  }
  // V has an unreferenced vertex: it must survive.
  V.conservativeResize(301, 3);
  V.row(300) << 7, 8, 9;

  for (const char* file : {"round.obj", "round.ply"}) {
    const std::string path = (dir / file).string();
    if (std::string(file).find(".obj") != std::string::npos) {
      trivcon::write_obj(path, V, F);
    } else {
      trivcon::write_ply(path, V, F);
    }
    const MeshData mesh = trivcon::read_mesh(path);
    EXPECT_TRUE(bitwise_equal(mesh.V, V)) << file;
    EXPECT_EQ(mesh.F, F) << file;
    EXPECT_EQ(mesh.polygon_count, 500);
  }
  EXPECT_EQ(trivcon::read_mesh((dir / "round.ply").string()).format, "ply-binary-le");

  // The written PLY is exactly the documented layout.
  const std::string ply = read_bytes(dir / "round.ply");
  EXPECT_THAT(ply, HasSubstr("format binary_little_endian 1.0\n"));
  EXPECT_THAT(ply, HasSubstr("element vertex 301\nproperty double x\nproperty double y\nproperty double z\n"
                             "element face 500\nproperty list uchar int vertex_indices\nend_header\n"));
  EXPECT_EQ(ply.size(), ply.find("end_header\n") + 11 + 301 * 24 + 500 * 13);
  // The OBJ uses %.17g and 1-based faces.
  const std::string obj = read_bytes(dir / "round.obj");
  char expected_line[128];
  std::snprintf(expected_line, sizeof expected_line, "\nv %.17g %.17g %.17g\n", V(1, 0), V(1, 1), V(1, 2));
  EXPECT_THAT(obj, HasSubstr(expected_line));
  EXPECT_THAT(
      obj, HasSubstr("\nf " + std::to_string(F(0, 0) + 1) + " " + std::to_string(F(0, 1) + 1) + " " + std::to_string(F(0, 2) + 1) + "\n"));

  // Gzip of what was written reads back the same.
  write_gzip(dir / "round.obj.gz", {read_bytes(dir / "round.obj")});
  EXPECT_TRUE(bitwise_equal(trivcon::read_mesh((dir / "round.obj.gz").string()).V, V));
}

TEST(Writers, RefuseWhatCannotBeReadBack) {
  const fs::path dir = test_dir();
  const std::string path = (dir / "bad.obj").string();
  MatrixX3d V = matrix_v({{0, 0, 0}, {1, 0, 0}, {0, 1, 0}});
  const MatrixX3i F = matrix_f({{0, 1, 2}});
  EXPECT_EQ(error_of([&] {
              trivcon::write_obj(path, V, matrix_f({{0, 1, 3}}));
            }),
            "cannot write '" + path + "': face 0 has vertex index 3 out of range (mesh has 3 vertices)");
  // A face with a repeated vertex is written: the readers read it back (for repair to drop, trivcon/repair.h).
  const std::string repeated = (dir / "repeated.ply").string();
  trivcon::write_ply(repeated, V, matrix_f({{0, 1, 1}}));
  EXPECT_EQ(trivcon::read_mesh(repeated).F, matrix_f({{0, 1, 1}}));
  EXPECT_EQ(error_of([&] { trivcon::write_obj(path, V, MatrixX3i(0, 3)); }), "cannot write '" + path + "': mesh has no faces");
  V(1, 2) = std::numeric_limits<double>::quiet_NaN();
  EXPECT_EQ(error_of([&] { trivcon::write_ply(path, V, F); }), "cannot write '" + path + "': non-finite coordinate in vertex 1 (nan)");
  EXPECT_FALSE(fs::exists(path));
}

TEST(Writers, WriteAtomically) {
  const fs::path dir = test_dir();
  const std::string path = (dir / "out.txt").string();
  trivcon::write_file_atomically(path, [](std::ostream& out) { out << "first"; });
  EXPECT_EQ(read_bytes(path), "first");
  trivcon::write_file_atomically(path, [](std::ostream& out) { out << "second"; });
  EXPECT_EQ(read_bytes(path), "second");

  // A throwing fill leaves the old file and no temporary behind, and the exception passes through.
  EXPECT_THROW(trivcon::write_file_atomically(path,
                                              [](std::ostream& out) {
                                                out << "partial";
                                                throw std::runtime_error("fill failed");
                                              }),
               std::runtime_error);
  EXPECT_EQ(read_bytes(path), "second");
  // A failing stream is an error too.
  EXPECT_EQ(error_of([&] { trivcon::write_file_atomically(path, [](std::ostream& out) { out.setstate(std::ios::badbit); }); }),
            "cannot write '" + path + "': write failed");
  EXPECT_EQ(read_bytes(path), "second");
  std::vector<std::string> names;
  for (const auto& entry : fs::directory_iterator(dir)) names.push_back(entry.path().filename().string());
  EXPECT_EQ(names, std::vector<std::string>{"out.txt"});

  const std::string nowhere = (dir / "missing" / "out.obj").string();
  EXPECT_EQ(error_of([&] {
              trivcon::write_obj(nowhere, matrix_v({{0, 0, 0}, {1, 0, 0}, {0, 1, 0}}), matrix_f({{0, 1, 2}}));
            }),
            "cannot write '" + nowhere + "': No such file or directory");
  // Over a directory: the rename fails and the temporary is removed.
  fs::create_directories(dir / "adir" / "inner");
  EXPECT_THAT(error_of([&] { trivcon::write_file_atomically((dir / "adir").string(), [](std::ostream& out) { out << 1; }); }),
              StartsWith("cannot write '" + (dir / "adir").string() + "': "));
  names.clear();
  for (const auto& entry : fs::directory_iterator(dir)) names.push_back(entry.path().filename().string());
  std::sort(names.begin(), names.end());
  EXPECT_EQ(names, (std::vector<std::string>{"adir", "out.txt"}));
}

// ------------------------------------------------------------------------------------------------
// The shared real meshes

#ifdef TRIVCON_SHARED_MESHES
const char* const kSharedMeshes = TRIVCON_SHARED_MESHES;
#else
const char* const kSharedMeshes = nullptr;
#endif

fs::path shared_meshes_or_skip() {
  if (kSharedMeshes == nullptr) return {};
  if (!fs::is_directory(kSharedMeshes)) return {};
  return kSharedMeshes;
}

TEST(SharedMeshes, CountsMatchTheTable) {
  const fs::path dir = shared_meshes_or_skip();
  if (dir.empty())
    GTEST_SKIP() << "shared meshes not found (TRIVCON_SHARED_MESHES = " << (kSharedMeshes ? kSharedMeshes : "undefined") << ")";
  struct Expected {
    const char* file;
    int vertices;
    int faces;
  };
  const std::vector<Expected> table = {
      {"spot.obj", 2930, 5856},
      {"bunny_closed.obj", 1839, 3674},
      {"armadillo.obj", 43243, 86482},
      {"torus.obj", 2304, 4608},
      {"kitten.off", 2500, 5000},
      {"bob_small.ply", 250, 500},
      {"rocker-arm.obj", 10044, 20088},
      {"eight.off", 5544, 11092},
      {"fertility.off", 4494, 9000},
      {"Input_wheel.off", 27925, 55890},
      {"cheese.off", 8629, 17786},
      {"bun_zipper.ply", 35947, 69451},
      {"face.obj", 25905, 51712},
      {"camelhead.off", 11381, 22704},
      {"half-torus.obj", 300, 576},
      {"circle.obj", 5201, 10240},
      {"dragon_vrip.ply", 437645, 871414},
      {"truck.obj", 2956, 4770},
      {"mobius.obj", 9900, 19602},
      {"capsule.obj", 5252, 10200},
      {"teapot.obj", 3644, 6320},
      {"bones.off", 2154, 4204},
      {"dragon_vrip_res3.ply", 22998, 47794},
      {"blobby-shuffled.off", 2027, 4050},
      {"hourglass_ico.obj", 23, 40},
  };
  std::size_t checked = 0;
  for (const auto& entry : fs::directory_iterator(dir)) {
    const std::string file = entry.path().filename().string();
    const auto expected = std::find_if(table.begin(), table.end(), [&](const Expected& e) { return file == e.file; });
    if (expected == table.end()) {
      // Any other mesh in the folder must at least read.
      if (entry.path().extension() == ".obj" || entry.path().extension() == ".off" || entry.path().extension() == ".ply") {
        EXPECT_NO_THROW(trivcon::read_mesh(entry.path().string())) << file;
      }
      continue;
    }
    SCOPED_TRACE(file);
    const MeshData mesh = trivcon::read_mesh(entry.path().string());
    EXPECT_EQ(mesh.V.rows(), expected->vertices);
    EXPECT_EQ(mesh.F.rows(), expected->faces);
    EXPECT_EQ(mesh.polygon_count, expected->faces);  // all pure triangle meshes
    expect_consistent(mesh);
    ++checked;
  }
  EXPECT_EQ(checked, table.size()) << "some files of the table are missing from " << dir;

  // Spot checks of values against the files' text.
  const MeshData dragon = trivcon::read_mesh((dir / "dragon_vrip.ply").string());
  EXPECT_EQ(dragon.format, "ply-ascii");
  EXPECT_EQ(dragon.V.row(0), Eigen::RowVector3d(0.032027, 0.056575, -0.0503644));
  EXPECT_EQ(dragon.F.row(dragon.F.rows() - 1), Eigen::RowVector3i(435598, 435560, 435559));
  EXPECT_EQ(trivcon::read_mesh((dir / "bob_small.ply").string()).format, "ply-binary-le");
  EXPECT_EQ(trivcon::read_mesh((dir / "camelhead.off").string()).V.row(0), Eigen::RowVector3d(-0.105873, 0.121359, 0.0271172));
}

TEST(SharedMeshes, DragonConvertsToBinaryPlyIdentically) {
  const fs::path shared = shared_meshes_or_skip();
  if (shared.empty())
    GTEST_SKIP() << "shared meshes not found (TRIVCON_SHARED_MESHES = " << (kSharedMeshes ? kSharedMeshes : "undefined") << ")";
  const fs::path dir = test_dir();
  const MeshData ascii = trivcon::read_mesh((shared / "dragon_vrip.ply").string());
  const std::string binary_path = (dir / "dragon_binary.ply").string();
  trivcon::write_ply(binary_path, ascii.V, ascii.F);
  const MeshData binary = trivcon::read_mesh(binary_path);
  EXPECT_EQ(binary.format, "ply-binary-le");
  EXPECT_TRUE(bitwise_equal(binary.V, ascii.V));
  EXPECT_EQ(binary.F, ascii.F);
  EXPECT_EQ(binary.polygon_of_triangle, ascii.polygon_of_triangle);
  fs::remove(binary_path);
}

TEST(SharedMeshes, GzippedCopyReadsIdentically) {
  const fs::path shared = shared_meshes_or_skip();
  if (shared.empty())
    GTEST_SKIP() << "shared meshes not found (TRIVCON_SHARED_MESHES = " << (kSharedMeshes ? kSharedMeshes : "undefined") << ")";
  const fs::path dir = test_dir();
  for (const char* file : {"kitten.off", "bob_small.ply", "spot.obj"}) {
    const std::string original = read_bytes(shared / file);
    const fs::path gz = dir / (std::string(file) + ".gz");
    write_gzip(gz, {original.substr(0, original.size() / 3), original.substr(original.size() / 3)});
    const MeshData plain = trivcon::read_mesh((shared / file).string());
    const MeshData unzipped = trivcon::read_mesh(gz.string());
    EXPECT_TRUE(bitwise_equal(plain.V, unzipped.V)) << file;
    EXPECT_EQ(plain.F, unzipped.F) << file;
  }
}

}  // namespace

namespace trivcon {
namespace {

// A quad mesh written as OBJ or binary PLY reads back as its quads, each fanned into two triangles.
TEST(WriteQuadMesh, ObjAndPlyReadBackAsTheirQuads) {
  MatrixX3d V(6, 3);
  V << 0, 0, 0, 1, 0, 0, 2, 0, 0, 0, 1, 0, 1, 1, 0, 2, 1, 0.25;
  Eigen::MatrixX4i Q(2, 4);
  Q << 0, 1, 4, 3, 1, 2, 5, 4;
  for (const std::string name : {"quads.obj", "quads.ply"}) {
    const std::string path = test::temp_file(name);
    write_quad_mesh(path, V, Q);
    const MeshData m = read_mesh(path);
    EXPECT_EQ(m.V, V) << name;
    EXPECT_EQ(m.polygon_count, 2) << name;
    EXPECT_EQ(m.polygon_of_triangle, (std::vector<int>{0, 0, 1, 1})) << name;
    EXPECT_EQ(m.F.row(0), Eigen::RowVector3i(0, 1, 4)) << name;
    EXPECT_EQ(m.F.row(1), Eigen::RowVector3i(0, 4, 3)) << name;
    EXPECT_EQ(m.F.row(3), Eigen::RowVector3i(1, 5, 4)) << name;
  }
  Q(1, 2) = 6;
  EXPECT_NE(test::error_of([&] { write_quad_mesh(test::temp_file("bad.obj"), V, Q); }).find("face 1 has vertex index 6 out of range"),
            std::string::npos);
}

}  // namespace
}  // namespace trivcon
