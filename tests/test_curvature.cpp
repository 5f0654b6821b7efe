// SPDX-License-Identifier: MIT
// Tests of trivcon/curvature.h: the per-face curvature tensors behind --align curvature.
#include "trivcon/curvature.h"

#include <gtest/gtest.h>

#include <cmath>

#include "support.h"
#include "trivcon/generate.h"
#include "trivcon/topology.h"

namespace trivcon {
namespace {

// An open cylinder of radius 1 around the z axis: `segments` around, `stacks` rows of quads, each split into
// two triangles.
Mesh open_cylinder(int segments, int stacks) {
  Mesh m;
  m.V.resize(segments * (stacks + 1), 3);
  for (int k = 0; k <= stacks; ++k)
    for (int i = 0; i < segments; ++i) {
      const double a = 2 * kPi * i / segments;
      m.V.row(k * segments + i) << std::cos(a), std::sin(a), 0.3 * k;
    }
  m.F.resize(2 * segments * stacks, 3);
  int f = 0;
  for (int k = 0; k < stacks; ++k)
    for (int i = 0; i < segments; ++i) {
      const int a = k * segments + i, b = k * segments + (i + 1) % segments, c = a + segments, d = b + segments;
      m.F.row(f++) << a, b, d;
      m.F.row(f++) << a, d, c;
    }
  return m;
}

// On a cylinder only the edges along the axis bend, so every face's least-curving direction (arg(z_f)/2) is
// the axis, and its anisotropy is the same on every face of one shape.
TEST(Curvature, ACylindersLeastCurvingDirectionIsItsAxis) {
  const Mesh m = open_cylinder(24, 6);
  const Topology t = test::topo(m);
  const Geometry g = compute_geometry(m.V, t);
  const std::vector<std::complex<double>> z = curvature_tensors(m.V, t, g);
  ASSERT_EQ(z.size(), static_cast<size_t>(m.F.rows()));
  for (int f = 0; f < m.F.rows(); ++f) {
    ASSERT_GT(std::abs(z[f]), 0.0) << "face " << f;
    const Eigen::Vector3d d = g.direction_in_face(f, std::arg(z[f]) / 2);
    EXPECT_NEAR(std::abs(d.z()), 1.0, 1e-9) << "face " << f;
  }
}

// Units of a length: scaling the mesh by 2 doubles every |z_f| and keeps its direction.
TEST(Curvature, TensorsScaleWithTheMesh) {
  Mesh m = open_cylinder(16, 4);
  const Topology t = test::topo(m);
  const std::vector<std::complex<double>> z = curvature_tensors(m.V, t, compute_geometry(m.V, t));
  m.V *= 2.0;
  const std::vector<std::complex<double>> z2 = curvature_tensors(m.V, t, compute_geometry(m.V, t));
  for (size_t f = 0; f < z.size(); ++f) EXPECT_LT(std::abs(z2[f] - 2.0 * z[f]), 1e-12 * std::abs(z[f]) + 1e-15) << "face " << f;
}

// Flat surfaces have no curvature: every tensor of a flat disk is 0.
TEST(Curvature, AFlatDiskHasNone) {
  const Mesh m = make_disk(6, 8);
  const Topology t = test::topo(m);
  for (const std::complex<double>& z : curvature_tensors(m.V, t, compute_geometry(m.V, t))) EXPECT_EQ(std::abs(z), 0.0);
}

}  // namespace
}  // namespace trivcon
