// src/io/read_stl.cpp: the STL reader of trivcon/io.h, ASCII and binary. STL stores every triangle with its own
// three corners; they are welded into vertices by exact position (the same three doubles), numbered in the order
// of first appearance, so that a mesh that was one surface before it was written as STL is one again. A
// triangle whose corners weld into fewer than three vertices is refused with its number (repair it or drop it).
// Why hand-written: no maintained STL library is in Debian 12; the format is a few lines.
#include "trivcon/io.h"

#include <cmath>
#include <cstdint>
#include <cstring>
#include <string>
#include <string_view>
#include <unordered_map>
#include <vector>

#include "io/file_error.h"
#include "io/mesh_rules.h"
#include "io/text_scanner.h"

namespace trivcon {

using namespace io;

namespace {

struct PositionHash {
  std::size_t operator()(const std::array<double, 3>& p) const {
    std::size_t h = 0;
    for (double c : p) {
      std::uint64_t bits;
      const double z = c == 0 ? 0.0 : c;  // −0 welds with +0
      std::memcpy(&bits, &z, sizeof bits);
      h = h * 1000003u ^ std::hash<std::uint64_t>()(bits);
    }
    return h;
  }
};

class Welder {
 public:
  int add(const std::array<double, 3>& p) {
    std::array<double, 3> key = p;
    for (double& c : key) c = c == 0 ? 0.0 : c;
    const auto [it, inserted] = index_.emplace(key, static_cast<int>(points_.size()));
    if (inserted) points_.push_back(key);
    return it->second;
  }
  void move_into(MeshData& mesh) {
    mesh.V.resize(static_cast<Eigen::Index>(points_.size()), 3);
    for (std::size_t v = 0; v < points_.size(); ++v)
      for (int a = 0; a < 3; ++a) mesh.V(static_cast<Eigen::Index>(v), a) = points_[v][a];
  }

 private:
  std::unordered_map<std::array<double, 3>, int, PositionHash> index_;
  std::vector<std::array<double, 3>> points_;
};

// A triangle's welded corners, or the message for one that collapses.
void add_triangle(FaceCollector& faces, Welder& welder, const std::array<std::array<double, 3>, 3>& corner, long long triangle,
                  const std::string& where) {
  std::vector<int> ids(3);
  for (int k = 0; k < 3; ++k) {
    for (double c : corner[k])
      if (!std::isfinite(c)) fail(where, "triangle " + std::to_string(triangle) + " has a coordinate that is not finite");
    ids[k] = welder.add(corner[k]);
  }
  // Two corners at one position (common in STL exports) make a face with a repeated vertex: kept, like every
  // reader's, for repair to drop; the first is named for a front end that does not repair.
  faces.problem(ids, [&](const std::string&) {
    fail(where, "triangle " + std::to_string(triangle) + " has two corners at the same position (a degenerate triangle)");
  });
  faces.add(ids);
}

MeshData read_binary_stl(const std::string& buffer, const std::string& name, std::uint32_t count) {
  MeshData mesh;
  mesh.format = "stl-binary";
  FaceCollector faces;
  faces.reserve_triangles(count);
  Welder welder;
  for (std::uint32_t t = 0; t < count; ++t) {
    const char* record = buffer.data() + 84 + 50 * static_cast<std::size_t>(t) + 12;  // after the normal
    std::array<std::array<double, 3>, 3> corner;
    for (int k = 0; k < 3; ++k)
      for (int a = 0; a < 3; ++a) {
        float f;
        std::memcpy(&f, record + 12 * k + 4 * a, 4);  // little-endian, as every platform trivcon builds on
        corner[k][a] = f;
      }
    add_triangle(faces, welder, corner, t, name);
  }
  welder.move_into(mesh);
  faces.move_into(mesh);
  return mesh;
}

// Every reader refuses a mesh without faces.
MeshData with_faces(MeshData mesh, const std::string& name) {
  if (mesh.F.rows() == 0) fail(name, "no faces");
  return mesh;
}

MeshData read_ascii_stl(const std::string& buffer, const std::string& name) {
  MeshData mesh;
  mesh.format = "stl-ascii";
  FaceCollector faces;
  Welder welder;
  TextScanner in(buffer, name, /*hash_comments=*/false);
  std::string_view token;
  if (!in.next_content_line() || !in.next_token(token) || token != "solid") in.fail("not an STL file: expected 'solid'");
  auto expect = [&](std::string_view word) {
    if (!in.next_token(token)) {
      if (!in.next_content_line()) in.fail("file ends where '" + std::string(word) + "' was expected");
      in.next_token(token);
    }
    if (token != word) in.fail("expected '" + std::string(word) + "', found " + quoted(token));
  };
  long long triangle = 0;
  for (;;) {
    if (!in.next_content_line()) in.fail("file ends before 'endsolid'");
    in.next_token(token);
    if (token == "endsolid") break;
    if (token != "facet") in.fail("expected 'facet' or 'endsolid', found " + quoted(token));
    expect("normal");
    for (int a = 0; a < 3; ++a)
      if (!in.next_token(token)) in.fail("the facet normal needs three numbers");
    expect("outer");
    expect("loop");
    std::array<std::array<double, 3>, 3> corner;
    for (int k = 0; k < 3; ++k) {
      expect("vertex");
      for (int a = 0; a < 3; ++a) {
        if (!in.next_token(token)) in.fail("a vertex needs three numbers");
        corner[k][a] = in.number(token);
      }
    }
    expect("endloop");
    expect("endfacet");
    add_triangle(faces, welder, corner, triangle++, name + ":" + std::to_string(in.line_number()));
  }
  welder.move_into(mesh);
  faces.move_into(mesh);
  return mesh;
}

}  // namespace

MeshData read_stl(const std::string& buffer, const std::string& name) {
  if (buffer.empty()) fail(name, "empty file");
  // Binary when the size is exactly the header's triangle count's (a binary file may also begin with "solid").
  if (buffer.size() >= 84) {
    std::uint32_t count;
    std::memcpy(&count, buffer.data() + 80, 4);
    if (buffer.size() == 84 + 50ull * count) {
      if (count > static_cast<std::uint64_t>(kMaxCount) / 3) fail(name, "too many triangles (" + std::to_string(count) + ")");
      return with_faces(read_binary_stl(buffer, name, count), name);
    }
  }
  std::size_t start = buffer.find_first_not_of(" \t\r\n");
  if (start != std::string::npos && buffer.compare(start, 5, "solid") == 0) return with_faces(read_ascii_stl(buffer, name), name);
  if (buffer.size() >= 84) {
    std::uint32_t count;
    std::memcpy(&count, buffer.data() + 80, 4);
    fail(name, "binary STL of " + std::to_string(buffer.size()) + " bytes, but its header announces " + std::to_string(count) +
                   " triangles (" + std::to_string(84 + 50ull * count) + " bytes): the file is cut short or not STL");
  }
  fail(name, "not an STL file (neither 'solid' nor a binary header of 84 bytes)");
}

}  // namespace trivcon
