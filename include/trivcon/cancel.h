// SPDX-License-Identifier: MIT
// trivcon/cancel.h: stopping a long call from another thread (a front end's Ctrl-C).
//
// A front end that runs a long call (a FieldDesigner's set-up and factorization, automatic singularities,
// split_large_turns) on a thread of its own can ask it to stop: it gives the call a flag through a
// CancelScope on that thread, and sets the flag from anywhere. The library polls the flag at safe points
// (between the stages of a set-up and of the geometry, per supernode of the numeric factorization, per
// iteration of the smoothest field, per round of refinement) and throws trivcon::Cancelled there; everything
// the call built so far is released as for any other error. Parts that run inside another library (the AMD /
// CAMD orders of libamd / libcamd) finish first, so a call stops within about the longest such part (BENCHMARKS.md,
// "Figures that were in code comments", has how long that is). Without a scope nothing is polled. The Python
// module uses this for KeyboardInterrupt (python/src/module.cpp).
#pragma once
#include <atomic>
#include <memory>

#include "trivcon/error.h"

namespace trivcon {

// What a cancelled call throws (a trivcon::Error, so that every front end's handler of errors sees it).
class Cancelled : public Error {
 public:
  Cancelled() : Error("cancelled") {}
};

// A call's flag: shared, because work a call starts may outlive it (a FieldDesigner's analysis thread runs
// on after its constructor returns, until the first factorization).
using CancelFlag = std::shared_ptr<std::atomic<bool>>;

// While it lives, the library's long stages on the constructing thread poll `flag` (set it, from any thread,
// to stop them). Scopes nest; the innermost one counts. Threads the library starts itself (OpenMP's, the
// set-up's analysis thread) are given the flag of the thread that starts them.
class CancelScope {
 public:
  explicit CancelScope(CancelFlag flag);
  ~CancelScope();
  CancelScope(const CancelScope&) = delete;
  CancelScope& operator=(const CancelScope&) = delete;

 private:
  CancelFlag previous_;
};

// The flag of the calling thread's innermost CancelScope, or null.
const CancelFlag& cancel_flag();

// Throws Cancelled if `flag` (not null) is set.
inline void check_cancelled(const std::atomic<bool>* flag) {
  if (flag != nullptr && flag->load(std::memory_order_relaxed)) throw Cancelled();
}
// Throws Cancelled if the calling thread's flag is set.
inline void check_cancelled() { check_cancelled(cancel_flag().get()); }

}  // namespace trivcon
