// SPDX-License-Identifier: MIT
#include "trivcon/blas.h"

#include <dlfcn.h>
#include <unistd.h>

#include <algorithm>
#include <cstdlib>
#include <cstring>
#include <mutex>

namespace trivcon {

std::string blas_kernels() {
  // Looked up at run time: the BLAS is whatever libblas.so.3 CHOLMOD was loaded with.
  using CoreName = char* (*)();
  const auto corename = reinterpret_cast<CoreName>(dlsym(RTLD_DEFAULT, "openblas_get_corename"));
  if (!corename) return "";
  const char* name = corename();
  return name ? name : "";
}

std::string native_blas_kernels() {
#if defined(__x86_64__)
  __builtin_cpu_init();
  if (__builtin_cpu_supports("avx512f") && __builtin_cpu_supports("avx512cd") && __builtin_cpu_supports("avx512bw") &&
      __builtin_cpu_supports("avx512dq") && __builtin_cpu_supports("avx512vl"))
    return "SkylakeX";
  if (__builtin_cpu_supports("avx2") && __builtin_cpu_supports("fma")) return "Haswell";
#endif
  return "";
}

namespace {
std::mutex blas_threads_mutex;
int single_threaded_users = 0;  // live SingleThreadedBlas objects
int saved_blas_threads = 0;     // OpenBLAS's thread count before the first of them
using SetThreads = void (*)(int);
using GetThreads = int (*)();
}  // namespace

SingleThreadedBlas::SingleThreadedBlas() {
  const auto set = reinterpret_cast<SetThreads>(dlsym(RTLD_DEFAULT, "openblas_set_num_threads"));
  const auto get = reinterpret_cast<GetThreads>(dlsym(RTLD_DEFAULT, "openblas_get_num_threads"));
  if (!set || !get) return;
  std::lock_guard<std::mutex> lock(blas_threads_mutex);
  if (single_threaded_users++ == 0) {
    saved_blas_threads = get();
    if (saved_blas_threads > 1) set(1);
  }
}

SingleThreadedBlas::~SingleThreadedBlas() {
  const auto set = reinterpret_cast<SetThreads>(dlsym(RTLD_DEFAULT, "openblas_set_num_threads"));
  if (!set || !dlsym(RTLD_DEFAULT, "openblas_get_num_threads")) return;
  std::lock_guard<std::mutex> lock(blas_threads_mutex);
  if (--single_threaded_users == 0 && saved_blas_threads > 1) set(saved_blas_threads);
}

int blas_threads() {
  const auto get = reinterpret_cast<GetThreads>(dlsym(RTLD_DEFAULT, "openblas_get_num_threads"));
  if (!get) return 0;
  std::lock_guard<std::mutex> lock(blas_threads_mutex);
  return single_threaded_users > 0 ? std::max(1, saved_blas_threads) : get();
}

void set_blas_threads(int threads) {
  const auto set = reinterpret_cast<SetThreads>(dlsym(RTLD_DEFAULT, "openblas_set_num_threads"));
  if (!set || !dlsym(RTLD_DEFAULT, "openblas_get_num_threads") || threads < 1) return;
  std::lock_guard<std::mutex> lock(blas_threads_mutex);
  if (single_threaded_users > 0)
    saved_blas_threads = threads;  // restored by the last SingleThreadedBlas
  else
    set(threads);
}

}  // namespace trivcon
