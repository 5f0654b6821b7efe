// SPDX-License-Identifier: MIT
// trivcon/angles.h: bringing angles into range.
#include "trivcon/angles.h"

#include <cmath>

#include "trivcon/common.h"

namespace trivcon {

double wrap_angle(double a) {
  if (a > -kPi && a <= kPi) return a;                      // the usual case, exact
  a -= 2 * kPi * std::floor((a + kPi) * (1 / (2 * kPi)));  // floor, not fmod: several times faster
  if (a <= -kPi) a += 2 * kPi;
  if (a > kPi) a -= 2 * kPi;
  return a;
}

double wrap_two_pi(double a) {
  a = wrap_angle(a);
  if (a < 0) a += 2 * kPi;
  return a < 2 * kPi ? a : 0.0;  // a tiny negative angle plus 2π can round to 2π
}

double reduce_angle(double a, int N) {
  const double period = 2 * kPi / N;
  a -= period * std::round(a / period);
  if (a <= -period / 2) a += period;
  if (a > period / 2) a -= period;
  return a;
}

}  // namespace trivcon
