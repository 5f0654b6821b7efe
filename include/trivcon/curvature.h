// SPDX-License-Identifier: MIT
// trivcon/curvature.h: principal curvature directions per face, as guidance for fields (trivcon/auto.h).
//
// Conventions
// - The curvature tensor of a face is the edge-based one of Cohen-Steiner & Morvan (2003), summed over the
//   face's three edges with half of each interior edge's weight (the other half goes to the face across):
//   T_f = Σ_e ½ β_e |e| ê êᵀ, with β_e the signed dihedral angle of interior edge e (positive where the
//   surface is convex seen from the side the normals point to: the angle from n_L to n_R about the edge
//   direction p_i → p_j of trivcon/geometry.h's rho, e = (i, j), i < j); boundary edges contribute nothing.
//   ê êᵀ along an edge that bends means the direction *along* the edge curves least, so T_f's major
//   eigenvector is the direction of least normal curvature (κ_min) and the minor one that of κ_max; they are
//   perpendicular, so a cross field (N = 4) follows both.
// - Returned as one complex number per face in the face's frame (trivcon/geometry.h), the trace-free part
//   of T_f: z_f = Σ_e ½ β_e |e| e^{2iφ_e}, φ_e the edge's angle in the face's frame (Geometry::half_edge_angle).
//   arg(z_f)/2 is the κ_min direction's angle, |z_f| the anisotropy (κ_max − κ_min) times about the face's
//   area (so it is bounded on slivers and zero-area faces, and 0 on flat or umbilic faces). For an N-field
//   with N even, z_f^{N/2} / |z_f|^{N/2 − 1} has the argument N·arg(z_f)/2: the field's guidance.
// - Units: |z_f| has the units of a length (angle × length); only ratios between faces matter.
#pragma once
#include <Eigen/Core>
#include <complex>
#include <vector>

#include "trivcon/common.h"
#include "trivcon/geometry.h"
#include "trivcon/topology.h"

namespace trivcon {

std::vector<std::complex<double>> curvature_tensors(const MatrixX3d& V, const Topology& topology, const Geometry& geometry);

}  // namespace trivcon
