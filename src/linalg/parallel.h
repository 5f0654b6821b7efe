// SPDX-License-Identifier: MIT
// src/linalg/parallel.h (internal): when the library's loops and passes run on several threads.
//
// Thread counts come from OpenMP's setting (OMP_NUM_THREADS, omp_set_num_threads; by default the
// machine's cores), never from a literal. Below the size thresholds, starting threads costs more than
// it saves (measured on 2 cores, BENCHMARKS.md).
#pragma once
#include <omp.h>

#include <algorithm>

namespace trivcon::linalg {

// Meshes with more faces (or edges, for per-edge loops) than this run their per-element loops and
// independent passes on several threads.
constexpr int kParallelMinElements = 50000;
// An edit's per-edge and per-vertex loops (a few flops per element, run many times) start threads above
// this size.
constexpr int kParallelMinEditElements = 100000;

// The number of threads OpenMP would use for a parallel region here.
inline int max_threads() { return std::max(1, omp_get_max_threads()); }

// Threads for a region with at most `tasks` independent tasks (e.g. 2 passes, or 2 subtrees).
inline int threads_for(int tasks) { return std::max(1, std::min(tasks, max_threads())); }

}  // namespace trivcon::linalg
