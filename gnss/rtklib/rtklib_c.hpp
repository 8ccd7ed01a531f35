// SPDX-License-Identifier: BSD-2-Clause
// PRIVATE to gnss/rtklib/*.cpp: the one place that includes RTKLIB's C header and removes the macros it leaks
// (lock, unlock, initlock, thread_t, lock_t, PI) so they cannot collide with C++ code. Never include this from a
// public header.
#pragma once

extern "C" {
#include "rtklib.h"
}
#undef lock
#undef unlock
#undef initlock
#undef thread_t
#undef lock_t
#undef PI
