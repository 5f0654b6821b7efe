// SPDX-License-Identifier: MIT
// src/io/mesh_rules.h (internal): what every mesh reader checks (counts, finite coordinates, index
// ranges, polygons) with the messages it gives, and how it collects the faces. The writers check the
// same (src/io/write_mesh.cpp), so that everything they write reads back identically.
//
// Vertex ids in messages are 0-based like everywhere in trivcon; polygons ("face 4") are counted
// 0-based in file order; an index that is out of range is quoted as written in the file.
#pragma once
#include <cstddef>
#include <limits>
#include <string>
#include <utility>
#include <vector>

#include "trivcon/error.h"
#include "trivcon/io.h"

namespace trivcon::io {

inline constexpr long long kMaxCount = std::numeric_limits<int>::max();  // ids are int (MatrixX3i)

std::string out_of_range_message(long long index, long long vertex_count);
std::string non_finite_message(long long vertex, double value);

// What is wrong with polygon `face` (0-based, range-checked corners), or "" when nothing is: fewer than three
// corners, or (unless `allow_repeated`) a repeated vertex.
std::string polygon_problem(const std::vector<int>& corners, long long face, bool allow_repeated = false);
// "face F has a repeated vertex (a, b, a, ...)" when a corner repeats, else "".
std::string repeated_vertex_problem(const std::vector<int>& corners, long long face);

// Collects checked polygons and fan-triangulates them.
class FaceCollector {
 public:
  void reserve_triangles(std::size_t count) {
    triangles_.reserve(3 * count);
    polygon_of_triangle_.reserve(count);
  }

  // What is wrong with `corners` as the next polygon, or "" when nothing is; the caller adds where. A repeated
  // vertex is not: such a polygon is read (repair drops its degenerate triangles, trivcon/repair.h), and the
  // first one's message is kept (MeshData::repeated_vertex) through `fail`, which throws it with where it is.
  template <class Fail>
  std::string problem(const std::vector<int>& corners, Fail&& fail) {
    if (std::string p = polygon_problem(corners, polygon_count_, true); !p.empty()) return p;
    if (first_repeated_.empty()) {
      if (std::string p = repeated_vertex_problem(corners, polygon_count_); !p.empty()) {
        try {
          fail(p);
        } catch (const Error& e) {
          first_repeated_ = e.what();
        }
      }
    }
    return {};
  }

  // Adds a polygon that problem() accepted, as the fan (a,b,c), (a,c,d), ...
  void add(const std::vector<int>& corners) {
    for (std::size_t i = 1; i + 1 < corners.size(); ++i) {
      triangles_.insert(triangles_.end(), {corners[0], corners[i], corners[i + 1]});
      polygon_of_triangle_.push_back(polygon_count_);
    }
    ++polygon_count_;
  }

  int polygon_count() const { return polygon_count_; }

  void move_into(MeshData& mesh) {
    const Eigen::Index rows = static_cast<Eigen::Index>(polygon_of_triangle_.size());
    mesh.F = Eigen::Map<const MatrixX3i>(triangles_.data(), rows, 3);
    mesh.polygon_of_triangle = std::move(polygon_of_triangle_);
    mesh.polygon_count = polygon_count_;
    mesh.repeated_vertex = std::move(first_repeated_);
  }

 private:
  std::vector<int> triangles_;  // 3 ids per triangle
  std::vector<int> polygon_of_triangle_;
  int polygon_count_ = 0;
  std::string first_repeated_;
};

}  // namespace trivcon::io
