// SPDX-License-Identifier: MIT
// Cooperative cancellation of long calls (trivcon/cancel.h).
#include "trivcon/cancel.h"

#include <utility>

namespace trivcon {

namespace {
thread_local CancelFlag current_flag;
}  // namespace

CancelScope::CancelScope(CancelFlag flag) : previous_(std::move(current_flag)) { current_flag = std::move(flag); }

CancelScope::~CancelScope() { current_flag = std::move(previous_); }

const CancelFlag& cancel_flag() { return current_flag; }

}  // namespace trivcon
