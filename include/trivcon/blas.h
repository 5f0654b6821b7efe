// SPDX-License-Identifier: MIT
// trivcon/blas.h: which BLAS kernels the factorization runs on, and how many threads each BLAS call uses.
//
// The supernodal factorization (src/linalg/supernodal.h) spends most of its time in BLAS (dgemm, dsyrk, dtrsm). Debian 12's
// OpenBLAS 0.3.21 picks its kernels for the CPU when it is loaded, and does not recognise recent CPUs
// (e.g. Intel family 6 model 207, the machine of BENCHMARKS.md): it falls back to its generic "Prescott"
// (SSE3) kernels, which factor markedly slower there than its AVX-512 ("SkylakeX") ones (BENCHMARKS.md,
// "What changed since the first measurement"). OpenBLAS only
// reads its choice (OPENBLAS_CORETYPE) when it is loaded, so a program that wants the better kernels
// must be started with it set.
#pragma once
#include <string>

namespace trivcon {

// The kernels OpenBLAS uses ("SkylakeX", "Haswell", "Prescott", …), or "" if the BLAS is not OpenBLAS.
std::string blas_kernels();

// The kernels this CPU supports that OpenBLAS would use if it recognised the CPU: "SkylakeX" with
// AVX-512 (F, CD, BW, DQ, VL), "Haswell" with AVX2 and FMA, else "".
std::string native_blas_kernels();

// A program's main() gets the better kernels by calling use_tuned_process(argv) (trivcon/tuned_process.h), which
// re-executes it with OPENBLAS_CORETYPE set to native_blas_kernels() when OpenBLAS fell back to its generic ones.

// While an object of this class lives, OpenBLAS runs every call on the calling thread alone (its own
// thread count is set to 1, and restored when the last such object in the process is destroyed). For
// code that calls BLAS from several threads at once: OpenBLAS 0.3.21's pthread build would give each call
// its thread pool, and concurrent calls then wait for each other (the factorization's two threads took
// several times longer). Does nothing if the BLAS is not OpenBLAS.
class SingleThreadedBlas {
 public:
  SingleThreadedBlas();
  ~SingleThreadedBlas();
  SingleThreadedBlas(const SingleThreadedBlas&) = delete;
  SingleThreadedBlas& operator=(const SingleThreadedBlas&) = delete;
};

// OpenBLAS's own thread count, for the whole process (OpenBLAS has one setting per process): how many threads
// each BLAS call may use. blas_threads() is the count that holds outside SingleThreadedBlas objects (0 if
// the BLAS is not OpenBLAS); set_blas_threads(n), n >= 1, changes it (while a SingleThreadedBlas object
// lives, it takes effect when the last one is destroyed). Does nothing if the BLAS is not OpenBLAS.
int blas_threads();
void set_blas_threads(int threads);

}  // namespace trivcon
