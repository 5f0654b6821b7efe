// SPDX-License-Identifier: MIT
// trivcon/angles.h: the three ways trivcon brings an angle (radians) into a range, each written once.
//   wrap_angle(a)      into (−π, π]            a rotation (transport ρ_e, a connection's turn, a jump)
//   wrap_two_pi(a)     into [0, 2π)            a field's stored angle (trivcon/field.h)
//   reduce_angle(a, N) into (−π/N, π/N]        a difference of N-directions: the closest of the N choices
// Each is exact for arguments already in its range, and never returns the excluded end (a tiny negative
// angle plus 2π that rounds to 2π becomes 0).
#pragma once

namespace trivcon {

double wrap_angle(double a);
double wrap_two_pi(double a);
double reduce_angle(double a, int N);

}  // namespace trivcon
