// SPDX-License-Identifier: BSD-2-Clause
// The innermost loops of the filter's covariance algebra (core/row_transition.hpp, fusion/kalman.hpp): short sums
// of scaled columns over contiguous memory. Compiled twice (GCC/Clang target_clones: AVX2 and the baseline x86-64
// SSE2) and chosen once at load time by the CPU; neither clone uses FMA, so both give bit-identical results on
// every machine — only the vector width differs (issue 39, docs/performance.md §5).
#pragma once

#include <cstddef>

namespace pednav::kernels {

/// u[i] += (v[0] a0[i] + v[1] a1[i]) + (v[2] a2[i] + v[3] a3[i]), i < n.
void axpy4(std::ptrdiff_t n, const double* v, const double* a0, const double* a1, const double* a2, const double* a3,
           double* u);
/// u[i] += v[0] a0[i] + v[1] a1[i], i < n.
void axpy2(std::ptrdiff_t n, const double* v, const double* a0, const double* a1, double* u);
/// u[i] += v a[i], i < n.
void axpy1(std::ptrdiff_t n, double v, const double* a, double* u);
/// p[i] *= d[i] dj, i < n.
void scale_by_outer(std::ptrdiff_t n, double dj, const double* d, double* p);
/// p[i] += q[i], i < n.
void add(std::ptrdiff_t n, const double* q, double* p);
/// p[i] = d[i] u[i], i < n.
void multiply(std::ptrdiff_t n, const double* d, const double* u, double* p);
/// x[i] −= a k[i] + b w[i], i < n (one gain column of the symmetric rank-2 downdate, fusion::gain_downdate).
void rank2_downdate(std::ptrdiff_t n, double a, const double* k, double b, const double* w, double* x);

}  // namespace pednav::kernels
