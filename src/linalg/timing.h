// SPDX-License-Identifier: MIT
// src/linalg/timing.h (internal): wall-clock seconds for the per-stage timings the library reports.
#pragma once
#include <chrono>

namespace trivcon::linalg {

using Clock = std::chrono::steady_clock;

inline double seconds_since(Clock::time_point t0) { return std::chrono::duration<double>(Clock::now() - t0).count(); }

}  // namespace trivcon::linalg
