// SPDX-License-Identifier: MIT
#include "trivcon/tuned_process.h"

#include <unistd.h>

#include <cstdlib>
#include <cstring>
#include <fstream>
#include <string>

#include "trivcon/blas.h"

namespace trivcon {

namespace {
constexpr const char* kBlasThreadTimeout = "4";  // OpenBLAS's smallest: its idle threads spin 2^4 cycles
constexpr const char* kOpenMpSpinCount = "10000";  // libgomp's idle threads: 10,000 spins (microseconds), then sleep
}  // namespace

const char* transparent_huge_pages_mode() {
  // Read once per process: every solve's report (the editor's too, per edit) asks for it.
  static const char* const mode = [] {
    std::ifstream in("/sys/kernel/mm/transparent_hugepage/enabled");
    std::string line;
    if (!std::getline(in, line)) return "";
    for (const char* m : {"always", "madvise", "never"})
      if (line.find(std::string("[") + m + "]") != std::string::npos) return m;
    return "";
  }();
  return mode;
}

void use_tuned_process(char** argv) {
  const char* old_tunables = std::getenv("GLIBC_TUNABLES");
  const std::string tunables = old_tunables ? old_tunables : "";
  bool set_coretype = false, set_tunables = false, set_timeout = false, set_spin = false;
  const std::string kernels = blas_kernels();  // "" when the BLAS is not OpenBLAS
  if (std::getenv("OPENBLAS_CORETYPE") == nullptr && kernels == "Prescott") {  // OpenBLAS's generic fallback
    const std::string native = native_blas_kernels();
    set_coretype = !native.empty() && setenv("OPENBLAS_CORETYPE", native.c_str(), 1) == 0;
  }
  if (tunables.find("glibc.malloc.hugetlb") == std::string::npos && std::strcmp(transparent_huge_pages_mode(), "madvise") == 0) {
    const std::string value = tunables.empty() ? "glibc.malloc.hugetlb=1" : tunables + ":glibc.malloc.hugetlb=1";
    set_tunables = setenv("GLIBC_TUNABLES", value.c_str(), 1) == 0;
  }
  // OpenBLAS's idle threads wait 2^4 cycles, not 2^28 (about 0.1 s), for more work (trivcon/tuned_process.h).
  if (std::getenv("OPENBLAS_THREAD_TIMEOUT") == nullptr && !kernels.empty())
    set_timeout = setenv("OPENBLAS_THREAD_TIMEOUT", kBlasThreadTimeout, 1) == 0;
  // OpenMP's idle threads spin for microseconds, not libgomp's default 300,000 spins, before they sleep (trivcon/tuned_process.h).
  if (std::getenv("GOMP_SPINCOUNT") == nullptr && std::getenv("OMP_WAIT_POLICY") == nullptr)
    set_spin = setenv("GOMP_SPINCOUNT", kOpenMpSpinCount, 1) == 0;
  if (!set_coretype && !set_tunables && !set_timeout && !set_spin) return;
  execv("/proc/self/exe", argv);
  // The re-execution failed: carry on as we are, with the environment as it was.
  if (set_coretype) unsetenv("OPENBLAS_CORETYPE");
  if (set_timeout) unsetenv("OPENBLAS_THREAD_TIMEOUT");
  if (set_spin) unsetenv("GOMP_SPINCOUNT");
  if (set_tunables) {
    if (old_tunables)
      setenv("GLIBC_TUNABLES", tunables.c_str(), 1);
    else
      unsetenv("GLIBC_TUNABLES");
  }
}

}  // namespace trivcon
