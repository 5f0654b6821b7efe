// SPDX-License-Identifier: MIT
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

// Corners into vertices: at the same position (tolerance 0), or within `tolerance` of a vertex made before (the
// first one found in the 27 grid cells of that size around the corner; positions are the first corner's).
class Welder {
 public:
  explicit Welder(double tolerance = 0) : tolerance_(tolerance) {}
  int add(const std::array<double, 3>& p) {
    std::array<double, 3> key = p;
    for (double& c : key) c = c == 0 ? 0.0 : c;
    if (tolerance_ > 0) return add_near(key);
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
  int add_near(const std::array<double, 3>& p) {
    std::array<std::int64_t, 3> cell;
    for (int a = 0; a < 3; ++a) cell[a] = static_cast<std::int64_t>(std::floor(p[a] / tolerance_));
    int found = -1;
    for (int dx = -1; dx <= 1; ++dx)
      for (int dy = -1; dy <= 1; ++dy)
        for (int dz = -1; dz <= 1; ++dz) {
          const auto it = cells_.find({cell[0] + dx, cell[1] + dy, cell[2] + dz});
          if (it == cells_.end()) continue;
          for (int v : it->second) {
            const double d2 = (points_[v][0] - p[0]) * (points_[v][0] - p[0]) + (points_[v][1] - p[1]) * (points_[v][1] - p[1]) +
                              (points_[v][2] - p[2]) * (points_[v][2] - p[2]);
            if (d2 <= tolerance_ * tolerance_ && (found < 0 || v < found)) found = v;
          }
        }
    if (found >= 0) return found;
    points_.push_back(p);
    cells_[cell].push_back(static_cast<int>(points_.size()) - 1);
    return static_cast<int>(points_.size()) - 1;
  }
  struct CellHash {
    std::size_t operator()(const std::array<std::int64_t, 3>& c) const {
      return std::hash<std::int64_t>()(c[0] * 73856093 ^ c[1] * 19349663 ^ c[2] * 83492791);
    }
  };

  double tolerance_ = 0;
  std::unordered_map<std::array<double, 3>, int, PositionHash> index_;
  std::unordered_map<std::array<std::int64_t, 3>, std::vector<int>, CellHash> cells_;
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

MeshData read_binary_stl(const std::string& buffer, const std::string& name, std::uint32_t count, double tolerance) {
  MeshData mesh;
  mesh.format = "stl-binary";
  FaceCollector faces;
  faces.reserve_triangles(count);
  Welder welder(tolerance);
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

MeshData read_ascii_stl(const std::string& buffer, const std::string& name, double tolerance) {
  MeshData mesh;
  mesh.format = "stl-ascii";
  FaceCollector faces;
  Welder welder(tolerance);
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

MeshData read_stl(const std::string& buffer, const std::string& name, double weld_tolerance) {
  if (!(weld_tolerance >= 0) || !std::isfinite(weld_tolerance))
    throw Error(name + ": the weld tolerance must be a finite number >= 0, not " + std::to_string(weld_tolerance));
  if (buffer.empty()) fail(name, "empty file");
  // Binary when the size is exactly the header's triangle count's (a binary file may also begin with "solid").
  if (buffer.size() >= 84) {
    std::uint32_t count;
    std::memcpy(&count, buffer.data() + 80, 4);
    if (buffer.size() == 84 + 50ull * count) {
      if (count > static_cast<std::uint64_t>(kMaxCount) / 3) fail(name, "too many triangles (" + std::to_string(count) + ")");
      return with_faces(read_binary_stl(buffer, name, count, weld_tolerance), name);
    }
  }
  std::size_t start = buffer.find_first_not_of(" \t\r\n");
  if (start != std::string::npos && buffer.compare(start, 5, "solid") == 0) return with_faces(read_ascii_stl(buffer, name, weld_tolerance), name);
  if (buffer.size() >= 84) {
    std::uint32_t count;
    std::memcpy(&count, buffer.data() + 80, 4);
    fail(name, "binary STL of " + std::to_string(buffer.size()) + " bytes, but its header announces " + std::to_string(count) +
                   " triangles (" + std::to_string(84 + 50ull * count) + " bytes): the file is cut short or not STL");
  }
  fail(name, "not an STL file (neither 'solid' nor a binary header of 84 bytes)");
}

}  // namespace trivcon
