// SPDX-License-Identifier: MIT
// trivcon/tuned_process.h: what a program's process must be started with to run trivcon at full speed.
//
// Four settings are read only when a process starts, so a program cannot change them once it runs:
//  - OPENBLAS_CORETYPE, the BLAS kernels (trivcon/blas.h: Debian 12's OpenBLAS falls back to generic SSE3
//    kernels on CPUs it does not know);
//  - glibc.malloc.hugetlb=1 in GLIBC_TUNABLES: malloc asks for transparent huge pages (madvise) for its
//    large blocks. On kernels that give huge pages only on request (/sys/kernel/mm/transparent_hugepage/
//    enabled says [madvise], Debian's default), every 4 KiB page of a new array otherwise costs a page
//    fault when first written; in a virtual machine that is expensive: a large set-up can spend much of
//    its time in page faults (BENCHMARKS.md, "Huge pages");
//  - OPENBLAS_THREAD_TIMEOUT=4: after a multithreaded BLAS call (the top of a factorization's elimination
//    tree), OpenBLAS's idle threads spin for 2^28 cycles (about 0.1 s) before they sleep, and take a core
//    from trivcon's own OpenMP threads meanwhile: the first parallel substitution after a factorization then
//    waited for them (the smoothest field's solves on a small mesh took many times longer now and then; an
//    edit right after a factorization likewise; BENCHMARKS.md, "Figures that were in code comments"). With
//    4 they spin 2^4 cycles; waking them for the next BLAS call costs microseconds.
//  - GOMP_SPINCOUNT=10000: after each parallel loop, libgomp's idle threads spin 300,000 times (about a
//    millisecond) before they sleep. A map or a quad mesh runs many short parallel loops between serial stretches,
//    and on a machine with few cores the spinning threads take the cores that the serial code, OpenBLAS's threads
//    and the next loop need. With 10,000 spins (microseconds) they sleep soon after a loop, and a loop that
//    follows at once still finds them awake (BENCHMARKS.md, "OpenMP's idle threads").
#pragma once

namespace trivcon {

// For a program's main(), first thing: if a setting above is missing and would help (OpenBLAS on its
// generic kernels while the CPU has better ones and OPENBLAS_CORETYPE is unset; the kernel's huge pages in
// [madvise] mode and GLIBC_TUNABLES not naming glibc.malloc.hugetlb; the BLAS is OpenBLAS and
// OPENBLAS_THREAD_TIMEOUT is unset; neither GOMP_SPINCOUNT nor OMP_WAIT_POLICY is set), re-executes the program once
// (/proc/self/exe, same arguments, same process id) with them set. Returns when there is nothing to do, or
// if the re-execution fails (the program then carries on as it is). A value you set yourself is kept:
// e.g. GLIBC_TUNABLES=glibc.malloc.hugetlb=0 turns the huge pages off.
void use_tuned_process(char** argv);

// The kernel's transparent huge page mode ("always", "madvise" or "never"; "" if unknown).
const char* transparent_huge_pages_mode();

}  // namespace trivcon
