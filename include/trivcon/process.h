// SPDX-License-Identifier: MIT
// trivcon/process.h: the former name of trivcon/tuned_process.h (re-executing with BLAS and huge-page
// settings), kept so that code written against trivcon 0.1 still compiles.
#pragma once
#include "trivcon/tuned_process.h"
