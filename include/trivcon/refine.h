// SPDX-License-Identifier: MIT
// trivcon/refine.h: the former name of trivcon/split_large_turns.h (refining a mesh where the connection
// turns by π/N or more), kept so that code written against trivcon 0.1 still compiles.
#pragma once
#include "trivcon/split_large_turns.h"
