// SPDX-License-Identifier: BSD-2-Clause
// See core/vector_kernels.hpp. Restrict pointers: the loops vectorize without run-time alias checks (the callers
// never pass overlapping input and output ranges).
#include "core/vector_kernels.hpp"

#if defined(__x86_64__) && (defined(__GNUC__) || defined(__clang__)) && !defined(PEDNAV_NO_TARGET_CLONES)
#define PEDNAV_CLONES __attribute__((target_clones("avx2", "default")))
#else
#define PEDNAV_CLONES
#endif

namespace pednav::kernels {

PEDNAV_CLONES void axpy4(std::ptrdiff_t n, const double* v, const double* __restrict a0, const double* __restrict a1,
                         const double* __restrict a2, const double* __restrict a3, double* __restrict u) {
  const double v0 = v[0], v1 = v[1], v2 = v[2], v3 = v[3];
  for (std::ptrdiff_t i = 0; i < n; ++i) u[i] += (v0 * a0[i] + v1 * a1[i]) + (v2 * a2[i] + v3 * a3[i]);
}

PEDNAV_CLONES void axpy2(std::ptrdiff_t n, const double* v, const double* __restrict a0, const double* __restrict a1,
                         double* __restrict u) {
  const double v0 = v[0], v1 = v[1];
  for (std::ptrdiff_t i = 0; i < n; ++i) u[i] += v0 * a0[i] + v1 * a1[i];
}

PEDNAV_CLONES void axpy1(std::ptrdiff_t n, double v, const double* __restrict a, double* __restrict u) {
  for (std::ptrdiff_t i = 0; i < n; ++i) u[i] += v * a[i];
}

PEDNAV_CLONES void scale_by_outer(std::ptrdiff_t n, double dj, const double* __restrict d, double* __restrict p) {
  for (std::ptrdiff_t i = 0; i < n; ++i) p[i] *= d[i] * dj;
}

PEDNAV_CLONES void add(std::ptrdiff_t n, const double* __restrict q, double* __restrict p) {
  for (std::ptrdiff_t i = 0; i < n; ++i) p[i] += q[i];
}

PEDNAV_CLONES void multiply(std::ptrdiff_t n, const double* __restrict d, const double* __restrict u,
                            double* __restrict p) {
  for (std::ptrdiff_t i = 0; i < n; ++i) p[i] = d[i] * u[i];
}

PEDNAV_CLONES void rank2_downdate(std::ptrdiff_t n, double a, const double* __restrict k, double b,
                                  const double* __restrict w, double* __restrict x) {
  for (std::ptrdiff_t i = 0; i < n; ++i) x[i] -= a * k[i] + b * w[i];
}

}  // namespace pednav::kernels
