// SPDX-License-Identifier: MIT
// Cooperative cancellation (trivcon/cancel.h): a set flag stops a set-up, a factorization, the automatic
// placement and the refinement with trivcon::Cancelled; without a scope nothing is polled; a designer whose
// factorization was cancelled factors again on its next design.
#include <atomic>
#include <chrono>
#include <memory>
#include <thread>

#include "support.h"
#include "trivcon/auto.h"
#include "trivcon/cancel.h"
#include "trivcon/design.h"
#include "trivcon/generate.h"
#include "trivcon/split_large_turns.h"

namespace trivcon {
namespace {

TEST(Cancel, ScopesNestAndRestore) {
  EXPECT_EQ(cancel_flag(), nullptr);
  EXPECT_NO_THROW(check_cancelled());  // no scope: nothing to poll
  const CancelFlag outer = std::make_shared<std::atomic<bool>>(false), inner = std::make_shared<std::atomic<bool>>(true);
  {
    CancelScope a(outer);
    EXPECT_EQ(cancel_flag(), outer);
    EXPECT_NO_THROW(check_cancelled());
    {
      CancelScope b(inner);
      EXPECT_EQ(cancel_flag(), inner);
      EXPECT_THROW(check_cancelled(), Cancelled);
    }
    EXPECT_EQ(cancel_flag(), outer);
    // Per thread: another thread has no scope.
    CancelFlag seen = inner;
    std::thread([&] { seen = cancel_flag(); }).join();
    EXPECT_EQ(seen, nullptr);
  }
  EXPECT_EQ(cancel_flag(), nullptr);
  EXPECT_EQ(outer.use_count(), 1);  // the scopes gave their shares back
  try {
    throw Cancelled();
  } catch (const Error& e) {  // an Error like every other, for every front end's handler
    EXPECT_STREQ(e.what(), "cancelled");
  }
}

TEST(Cancel, SetFlagStopsEachLongCall) {
  const Mesh m = make_cube_sphere(40, true);
  const CancelFlag stop = std::make_shared<std::atomic<bool>>(true);
  {
    CancelScope scope(stop);
    EXPECT_THROW(FieldDesigner(m.V, m.F), Cancelled);
  }
  FieldDesigner designer(m.V, m.F);  // no scope: prepares as usual
  IndexPrescription p;
  p.N = 4;
  p.vertex[0] = 8;
  {
    CancelScope scope(stop);
    EXPECT_THROW(designer.set_fixed_faces({}), Cancelled);  // the factorization
    AutoOptions o;
    o.N = 4;
    EXPECT_THROW(auto_singularities(designer, o), Cancelled);
  }
  // The designer factors again on its next design, and designs as a fresh one does.
  const Design d = designer.design(p);
  EXPECT_TRUE(design_verified(d));
  const FieldDesigner fresh(m.V, m.F);
  EXPECT_EQ(d.connection.x, fresh.design(p).connection.x);
  {
    CancelScope scope(stop);
    EXPECT_THROW(split_large_turns(designer, m.F, p), Cancelled);
  }
}

TEST(Cancel, FlagSetFromAnotherThreadStopsTheFactorization) {
  // A set-up that takes far longer than the 20 ms after which another thread sets the flag.
  const Mesh m = make_cube_sphere(150, true);  // 270k faces
  const CancelFlag stop = std::make_shared<std::atomic<bool>>(false);
  std::thread setter([&] {
    std::this_thread::sleep_for(std::chrono::milliseconds(20));
    *stop = true;
  });
  const auto start = std::chrono::steady_clock::now();
  bool cancelled = false;
  try {
    CancelScope scope(stop);
    FieldDesigner designer(m.V, m.F);
    designer.set_fixed_faces({});
  } catch (const Cancelled&) {
    cancelled = true;
  }
  setter.join();
  EXPECT_TRUE(cancelled);
  // Generous: the whole set-up takes about a second here; it stopped at a safe point well before its end.
  EXPECT_LT(std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count(), 5.0);
}

TEST(Cancel, TheAnalysisThreadKeepsItsShareOfTheFlag) {
  // A designer prepared in a scope that ends before its first factorization: its analysis thread, still
  // running, holds a share of the flag (not a pointer into the ended call), and the designer factors later.
  const Mesh m = make_cube_sphere(60, true);
  std::unique_ptr<FieldDesigner> designer;
  std::weak_ptr<std::atomic<bool>> watch;
  {
    const CancelFlag flag = std::make_shared<std::atomic<bool>>(false);
    watch = flag;
    CancelScope scope(flag);
    designer = std::make_unique<FieldDesigner>(m.V, m.F);
  }
  IndexPrescription p;
  p.N = 1;
  p.vertex[0] = 2;
  EXPECT_TRUE(design_verified(designer->design(p)));
  designer.reset();
  EXPECT_TRUE(watch.expired());  // every share given back once the analysis thread is joined
}

}  // namespace
}  // namespace trivcon
