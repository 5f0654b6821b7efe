// SPDX-License-Identifier: MIT
// trivcon/common.h: the types and constants every part of the library shares.
//
// - Meshes are libigl-style plain arrays: V is n×3 double (one row per vertex), F is m×3 int (one row
//   per triangle, corners counter-clockwise about the outward normal once oriented, see topology.h).
//   Both are row-major so that a row is three contiguous numbers, as in the files.
// - Ids are 0-based and the caller's own (the file's): nothing in trivcon renumbers them.
// - Angles are in radians.
#pragma once
#include <Eigen/Core>

namespace trivcon {

using MatrixX3d = Eigen::Matrix<double, Eigen::Dynamic, 3, Eigen::RowMajor>;
using MatrixX3i = Eigen::Matrix<int, Eigen::Dynamic, 3, Eigen::RowMajor>;
using MatrixX2i = Eigen::Matrix<int, Eigen::Dynamic, 2, Eigen::RowMajor>;

// A triangle mesh as plain arrays (see above).
struct Mesh {
  MatrixX3d V;
  MatrixX3i F;
};

constexpr double kPi = 3.14159265358979323846;
constexpr double kTwoPi = 2 * kPi;

}  // namespace trivcon
