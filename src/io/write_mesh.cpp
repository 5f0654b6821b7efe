// SPDX-License-Identifier: MIT
// src/io/write_mesh.cpp: the mesh writers of trivcon/io.h, OBJ (text, 17 significant digits) and binary
// little-endian PLY (doubles). They refuse what the readers would reject (src/io/mesh_rules.h), so that
// everything written reads back identically, and write through write_file_atomically.
#include "trivcon/io.h"

#include <algorithm>
#include <charconv>
#include <cmath>
#include <cstdint>
#include <cstring>
#include <ostream>
#include <type_traits>
#include <vector>

#include "io/mesh_rules.h"
#include "trivcon/error.h"

namespace trivcon {
namespace {

using io::kMaxCount;
using io::non_finite_message;
using io::polygon_problem;

// Refuses what the readers would reject, so that everything written reads back identically. Faces: triangles or quads.
template <class Faces>
void check_writable(const std::string& path, const MatrixX3d& V, const Faces& F) {
  const auto refuse = [&](const std::string& why) { throw Error("cannot write '" + path + "': " + why); };
  if (V.rows() > kMaxCount) refuse("too many vertices");
  if (F.rows() == 0) refuse("mesh has no faces");
  for (Eigen::Index v = 0; v < V.rows(); ++v) {
    for (int axis = 0; axis < 3; ++axis) {
      if (!std::isfinite(V(v, axis))) refuse(non_finite_message(v, V(v, axis)));
    }
  }
  const int n = static_cast<int>(F.cols());
  std::vector<int> corners(n);
  for (Eigen::Index f = 0; f < F.rows(); ++f) {
    for (int c = 0; c < n; ++c) {
      corners[c] = F(f, c);
      if (corners[c] < 0 || corners[c] >= V.rows()) {
        refuse("face " + std::to_string(f) + " has vertex index " + std::to_string(corners[c]) + " out of range (mesh has " +
               std::to_string(V.rows()) + " vertices)");
      }
    }
    const std::string problem = polygon_problem(corners, f, true);  // a repeated vertex reads back (for repair to drop)
    if (!problem.empty()) refuse(problem);
  }
}

template <class T>
void append_number(std::string& out, T value) {
  char digits[32];
  const auto result = std::to_chars(digits, digits + sizeof digits, value);
  out.append(digits, result.ptr);
}

// %.17g: 17 significant digits always read back to the same double.
void append_coordinate(std::string& out, double value) {
  char digits[32];
  const auto result = std::to_chars(digits, digits + sizeof digits, value, std::chars_format::general, 17);
  out.append(digits, result.ptr);
}

template <class T>
void append_little_endian(std::string& out, T value) {
  static_assert(std::is_integral_v<T> || std::is_floating_point_v<T>);
  unsigned char bytes[sizeof(T)];
  std::memcpy(bytes, &value, sizeof bytes);
  const std::uint16_t probe = 1;
  unsigned char first;
  std::memcpy(&first, &probe, 1);
  if (first == 0) std::reverse(bytes, bytes + sizeof bytes);  // big-endian host
  out.append(reinterpret_cast<const char*>(bytes), sizeof bytes);
}

// The `v x y z` lines of an OBJ.
void append_obj_vertices(std::string& text, const MatrixX3d& V) {
  for (Eigen::Index v = 0; v < V.rows(); ++v) {
    text += 'v';
    for (int axis = 0; axis < 3; ++axis) {
      text += ' ';
      append_coordinate(text, V(v, axis));
    }
    text += '\n';
  }
}

template <class Faces>
void write_obj_faces(const std::string& path, const MatrixX3d& V, const Faces& F) {
  check_writable(path, V, F);
  std::string text = "# trivcon mesh: " + std::to_string(V.rows()) + " vertices, " + std::to_string(F.rows()) + " faces\n";
  text.reserve(text.size() + 64 * V.rows() + 8 * F.cols() * F.rows());
  append_obj_vertices(text, V);
  for (Eigen::Index f = 0; f < F.rows(); ++f) {
    text += 'f';
    for (int c = 0; c < F.cols(); ++c) {
      text += ' ';
      append_number(text, F(f, c) + 1);
    }
    text += '\n';
  }
  write_file_atomically(path, [&](std::ostream& out) { out.write(text.data(), static_cast<std::streamsize>(text.size())); });
}

template <class Faces>
void write_ply_faces(const std::string& path, const MatrixX3d& V, const Faces& F) {
  check_writable(path, V, F);
  std::string data = "ply\nformat binary_little_endian 1.0\ncomment written by trivcon\nelement vertex " + std::to_string(V.rows()) +
                     "\nproperty double x\nproperty double y\nproperty double z\nelement face " + std::to_string(F.rows()) +
                     "\nproperty list uchar int vertex_indices\nend_header\n";
  data.reserve(data.size() + 24 * V.rows() + (1 + 4 * F.cols()) * F.rows());
  for (Eigen::Index v = 0; v < V.rows(); ++v) {
    for (int axis = 0; axis < 3; ++axis) append_little_endian(data, V(v, axis));
  }
  for (Eigen::Index f = 0; f < F.rows(); ++f) {
    data += static_cast<char>(F.cols());
    for (int c = 0; c < F.cols(); ++c) append_little_endian<std::int32_t>(data, F(f, c));
  }
  write_file_atomically(path, [&](std::ostream& out) { out.write(data.data(), static_cast<std::streamsize>(data.size())); });
}

}  // namespace

void write_obj(const std::string& path, const MatrixX3d& V, const MatrixX3i& F) { write_obj_faces(path, V, F); }
void write_ply(const std::string& path, const MatrixX3d& V, const MatrixX3i& F) { write_ply_faces(path, V, F); }

void write_quad_mesh(const std::string& path, const MatrixX3d& V, const Eigen::MatrixX4i& Q) {
  const bool ply = path.size() >= 4 && path.compare(path.size() - 4, 4, ".ply") == 0;
  if (ply)
    write_ply_faces(path, V, Q);
  else
    write_obj_faces(path, V, Q);
}

void write_uv_obj(const std::string& path, const MatrixX3d& V, const MatrixX3i& F, const Eigen::MatrixXd& corner_uv) {
  check_writable(path, V, F);
  if (corner_uv.rows() != F.rows() || corner_uv.cols() != 6)
    throw Error("cannot write " + path + ": the texture coordinates are not one (u, v) per corner of every face");
  if (!corner_uv.allFinite()) throw Error("cannot write " + path + ": a texture coordinate is not finite");
  std::string text = "# trivcon seamless parametrization: " + std::to_string(V.rows()) + " vertices, " + std::to_string(F.rows()) +
                     " faces, one vt per corner\n";
  text.reserve(text.size() + 64 * V.rows() + 90 * F.rows());
  append_obj_vertices(text, V);
  for (Eigen::Index f = 0; f < F.rows(); ++f)
    for (int c = 0; c < 3; ++c) {
      text += "vt ";
      append_coordinate(text, corner_uv(f, 2 * c));
      text += ' ';
      append_coordinate(text, corner_uv(f, 2 * c + 1));
      text += '\n';
    }
  for (Eigen::Index f = 0; f < F.rows(); ++f) {
    text += 'f';
    for (int c = 0; c < 3; ++c) {
      text += ' ';
      append_number(text, F(f, c) + 1);
      text += '/';
      append_number(text, 3 * f + c + 1);
    }
    text += '\n';
  }
  write_file_atomically(path, [&](std::ostream& out) { out.write(text.data(), static_cast<std::streamsize>(text.size())); });
}

}  // namespace trivcon
