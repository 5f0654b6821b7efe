// SPDX-License-Identifier: MIT
// The glTF reader (trivcon/io.h read_gltf, by extension in read_mesh): a .gltf with an embedded buffer and the
// same as .glb, node transforms applied, every triangle primitive its own block of vertices, strips and fans;
// errors name the file and the primitive.
#include <gtest/gtest.h>

#include <cstdint>
#include <cstring>
#include <string>
#include <vector>

#include "support.h"
#include "trivcon/error.h"
#include "trivcon/io.h"

namespace trivcon {
namespace {

using test::error_of;

std::string base64(const std::string& in) {
  static const char* table = "ABCDEFGHIJKLMNOPQRSTUVWXYZabcdefghijklmnopqrstuvwxyz0123456789+/";
  std::string out;
  size_t i = 0;
  for (; i + 2 < in.size(); i += 3) {
    const unsigned v = (static_cast<unsigned char>(in[i]) << 16) | (static_cast<unsigned char>(in[i + 1]) << 8) | static_cast<unsigned char>(in[i + 2]);
    for (int k = 3; k >= 0; --k) out += table[(v >> (6 * k)) & 63];
  }
  if (i + 1 == in.size()) {
    const unsigned v = static_cast<unsigned char>(in[i]) << 16;
    out += table[(v >> 18) & 63], out += table[(v >> 12) & 63], out += "==";
  } else if (i + 2 == in.size()) {
    const unsigned v = (static_cast<unsigned char>(in[i]) << 16) | (static_cast<unsigned char>(in[i + 1]) << 8);
    out += table[(v >> 18) & 63], out += table[(v >> 12) & 63], out += table[(v >> 6) & 63], out += '=';
  }
  return out;
}

// A unit square (4 positions, 2 triangles by 6 unsigned-short indices) in one buffer.
std::string square_buffer() {
  const float p[12] = {0, 0, 0, 1, 0, 0, 1, 1, 0, 0, 1, 0};
  const std::uint16_t idx[6] = {0, 1, 2, 0, 2, 3};
  std::string b(reinterpret_cast<const char*>(p), 48);
  b.append(reinterpret_cast<const char*>(idx), 12);
  return b;
}

std::string square_json(const std::string& buffer_entry, const std::string& nodes) {
  return R"({"asset":{"version":"2.0"},"scene":0,"scenes":[{"nodes":[0]}],"nodes":)" + nodes +
         R"(,"meshes":[{"primitives":[{"attributes":{"POSITION":0},"indices":1}]}],)"
         R"("accessors":[{"bufferView":0,"componentType":5126,"count":4,"type":"VEC3","min":[0,0,0],"max":[1,1,0]},)"
         R"({"bufferView":1,"componentType":5123,"count":6,"type":"SCALAR"}],)"
         R"("bufferViews":[{"buffer":0,"byteOffset":0,"byteLength":48},{"buffer":0,"byteOffset":48,"byteLength":12}],)"
         R"("buffers":[)" + buffer_entry + "]}";
}

std::string glb(const std::string& json, const std::string& bin) {
  std::string j = json;
  while (j.size() % 4) j += ' ';
  std::string b = bin;
  while (b.size() % 4) b += '\0';
  auto u32 = [](std::uint32_t v) { return std::string(reinterpret_cast<const char*>(&v), 4); };
  return "glTF" + u32(2) + u32(static_cast<std::uint32_t>(12 + 8 + j.size() + 8 + b.size())) + u32(static_cast<std::uint32_t>(j.size())) +
         "JSON" + j + u32(static_cast<std::uint32_t>(b.size())) + "BIN" + std::string(1, '\0') + b;
}

TEST(Gltf, EmbeddedSquareWithATransform) {
  const std::string buffer = square_buffer();
  const std::string json = square_json(R"({"byteLength":60,"uri":"data:application/octet-stream;base64,)" + base64(buffer) + R"("})",
                                       R"([{"mesh":0,"translation":[10,0,0],"children":[1]},{"mesh":0,"scale":[2,2,2]}])");
  const MeshData m = read_gltf(json, "square.gltf");
  EXPECT_EQ(m.format, "gltf");
  ASSERT_EQ(m.V.rows(), 8);  // two instances, each its own vertices
  ASSERT_EQ(m.F.rows(), 4);
  EXPECT_EQ(m.V.row(2), Eigen::RowVector3d(11, 1, 0));   // translated
  EXPECT_EQ(m.V.row(6), Eigen::RowVector3d(12, 2, 0));   // the child: scaled, then its parent's translation
  EXPECT_EQ(m.F.row(1), Eigen::RowVector3i(0, 2, 3));
  EXPECT_EQ(m.F.row(3), Eigen::RowVector3i(4, 6, 7));
}

TEST(Gltf, BinaryAndByExtension) {
  const std::string data = glb(square_json(R"({"byteLength":60})", R"([{"mesh":0}])"), square_buffer());
  const MeshData m = read_gltf(data, "square.glb");
  EXPECT_EQ(m.format, "glb");
  EXPECT_EQ(m.V.rows(), 4);
  EXPECT_EQ(m.F.rows(), 2);
  const std::string path = test::temp_file("square.glb");
  test::write_text(path, data);
  EXPECT_EQ(read_mesh(path).F, m.F);
}

TEST(Gltf, Errors) {
  EXPECT_EQ(error_of([&] { read_gltf("", "e.gltf"); }), "e.gltf: empty file");
  EXPECT_EQ(error_of([&] { read_gltf("{}", "x.gltf").F.rows(); }).rfind("x.gltf: not a readable glTF 2.0 file: ", 0), 0u);
  std::string bad = square_buffer();
  const std::uint16_t big[6] = {0, 1, 9, 0, 2, 3};
  std::memcpy(&bad[48], big, 12);
  EXPECT_EQ(error_of([&] { read_gltf(glb(square_json(R"({"byteLength":60})", R"([{"mesh":0}])"), bad), "b.glb"); }),
            "b.glb: mesh 0 primitive 0: index 9 out of range (the primitive has 4 vertices)");
  const std::string small = square_json(R"({"byteLength":60})", R"([{"mesh":0}])");
  EXPECT_NE(error_of([&] { read_gltf(glb(small, square_buffer().substr(0, 40)), "s.glb"); }).find("s.glb: "), std::string::npos);
}

}  // namespace
}  // namespace trivcon
