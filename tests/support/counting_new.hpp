// SPDX-License-Identifier: BSD-2-Clause
// A counting replacement of the global operator new/delete (malloc-backed) for the allocation checks of issue 10:
// include it in exactly ONE translation unit of an executable (a replacement must be defined once); read
// g_allocs before and after the code under test.
#pragma once

#include <atomic>
#include <cstdlib>
#include <new>

namespace {
std::atomic<long> g_allocs{0};
}  // namespace

// GCC's -Wmismatched-new-delete cannot see that operator new below is the replaced global one (malloc-backed),
// so it flags every matching free(); the pairing is correct by construction.
#if defined(__GNUC__) && !defined(__clang__)
#pragma GCC diagnostic ignored "-Wmismatched-new-delete"
#endif
void* operator new(std::size_t n) {
  g_allocs.fetch_add(1, std::memory_order_relaxed);
  if (void* p = std::malloc(n == 0 ? 1 : n)) return p;
  throw std::bad_alloc();
}
void* operator new[](std::size_t n) { return operator new(n); }
void operator delete(void* p) noexcept { std::free(p); }
void operator delete[](void* p) noexcept { std::free(p); }
void operator delete(void* p, std::size_t) noexcept { std::free(p); }
void operator delete[](void* p, std::size_t) noexcept { std::free(p); }
