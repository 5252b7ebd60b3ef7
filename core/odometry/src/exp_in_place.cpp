#include "exp_in_place.hpp"

#include <cmath>
#include <cstdint>

// The vector path reproduces glibc's expf, so it is only taken where std::exp is glibc's.
#if defined(__x86_64__) && defined(__GLIBC__) && (defined(__GNUC__) || defined(__clang__))
#include <immintrin.h>
#define NIDEVO_EXP_AVX2 1
#endif

namespace nidevo {

namespace {

void scalarExp(float* values, size_t n) {
  for (size_t i = 0; i < n; ++i) values[i] = std::exp(values[i]);
}

#ifdef NIDEVO_EXP_AVX2

// glibc's expf (sysdeps/ieee754/flt-32/e_expf.c with exp2f_data.c, EXP2F_TABLE_BITS 5, as its
// FMA variant computes it): x / ln2 * 32 = k + r, exp(x) = 2^(k/32) * 2^(r/32), the first from
// the table with k's integer part added to the exponent, the second a cubic in r.
constexpr uint64_t kTable[32] = {
    0x3ff0000000000000, 0x3fefd9b0d3158574, 0x3fefb5586cf9890f, 0x3fef9301d0125b51,
    0x3fef72b83c7d517b, 0x3fef54873168b9aa, 0x3fef387a6e756238, 0x3fef1e9df51fdee1,
    0x3fef06fe0a31b715, 0x3feef1a7373aa9cb, 0x3feedea64c123422, 0x3feece086061892d,
    0x3feebfdad5362a27, 0x3feeb42b569d4f82, 0x3feeab07dd485429, 0x3feea47eb03a5585,
    0x3feea09e667f3bcd, 0x3fee9f75e8ec5f74, 0x3feea11473eb0187, 0x3feea589994cce13,
    0x3feeace5422aa0db, 0x3feeb737b0cdc5e5, 0x3feec49182a3f090, 0x3feed503b23e255d,
    0x3feee89f995ad3ad, 0x3feeff76f2fb5e47, 0x3fef199bdd85529c, 0x3fef3720dcef9069,
    0x3fef5818dcfba487, 0x3fef7c97337b9b5f, 0x3fefa4afa2a490da, 0x3fefd0765b6e4540,
};
constexpr double kInvLn2Scaled = 0x1.71547652b82fep+0 * 32;
constexpr double kShift = 0x1.8p+52;
constexpr double kPoly0 = 0x1.c6af84b912394p-5 / 32 / 32 / 32;
constexpr double kPoly1 = 0x1.ebfce50fac4f3p-3 / 32 / 32;
constexpr double kPoly2 = 0x1.62e42ff0c52d6p-1 / 32;
constexpr uint32_t kSpecialTop12 = 0x42b;  // top 12 bits of 88.0f: glibc's own branch from here

// Each step rounds once where glibc's FMA build does (its fused steps are the _fmadd/_fmsub ones);
// the file is built with -ffp-contract=off so the compiler fuses nothing else.
__attribute__((target("avx2,fma"))) __m128 expFour(__m128 x) {
  const __m256d xd = _mm256_cvtps_pd(x);
  const __m256d inv_ln2 = _mm256_set1_pd(kInvLn2Scaled), shift = _mm256_set1_pd(kShift);
  __m256d kd = _mm256_fmadd_pd(inv_ln2, xd, shift);
  const __m256i ki = _mm256_castpd_si256(kd);
  kd = _mm256_sub_pd(kd, shift);
  const __m256d r = _mm256_fmsub_pd(inv_ln2, xd, kd);
  const __m256i index = _mm256_and_si256(ki, _mm256_set1_epi64x(31));
  const __m256i t =
      _mm256_add_epi64(_mm256_i64gather_epi64(reinterpret_cast<const long long*>(kTable), index, 8),
                       _mm256_slli_epi64(ki, 47));
  const __m256d s = _mm256_castsi256_pd(t);
  const __m256d z = _mm256_fmadd_pd(r, _mm256_set1_pd(kPoly0), _mm256_set1_pd(kPoly1));
  const __m256d r2 = _mm256_mul_pd(r, r);
  __m256d y = _mm256_fmadd_pd(r, _mm256_set1_pd(kPoly2), _mm256_set1_pd(1.0));
  y = _mm256_fmadd_pd(z, r2, y);
  return _mm256_cvtpd_ps(_mm256_mul_pd(y, s));
}

__attribute__((target("avx2,fma"))) void vectorExp(float* values, size_t n) {
  const __m256i top12_mask = _mm256_set1_epi32(0x7ff);
  const __m256i special_from = _mm256_set1_epi32(int(kSpecialTop12) - 1);
  size_t i = 0;
  for (; i + 8 <= n; i += 8) {
    const __m256 x = _mm256_loadu_ps(values + i);
    const __m256i top12 =
        _mm256_and_si256(_mm256_srli_epi32(_mm256_castps_si256(x), 20), top12_mask);
    if (!_mm256_testz_si256(_mm256_cmpgt_epi32(top12, special_from), _mm256_set1_epi32(-1))) {
      scalarExp(values + i, 8);  // |x| >= 88 or NaN: glibc's branches, exactly
      continue;
    }
    const __m128 lo = expFour(_mm256_castps256_ps128(x));
    const __m128 hi = expFour(_mm256_extractf128_ps(x, 1));
    _mm256_storeu_ps(values + i, _mm256_set_m128(hi, lo));
  }
  scalarExp(values + i, n - i);
}

// glibc picks its FMA expf when the CPU has FMA and AVX2 (sysdeps/x86_64/fpu/multiarch): only
// then does the vector path give its bits.
bool cpuRunsGlibcFmaExp() {
  static const bool yes = __builtin_cpu_supports("avx2") && __builtin_cpu_supports("fma");
  return yes;
}

#endif

}  // namespace

bool expInPlaceIsVectorised() {
#ifdef NIDEVO_EXP_AVX2
  return cpuRunsGlibcFmaExp();
#else
  return false;
#endif
}

void expInPlace(float* values, size_t n) {
#ifdef NIDEVO_EXP_AVX2
  if (expInPlaceIsVectorised()) return vectorExp(values, n);
#endif
  scalarExp(values, n);
}

}  // namespace nidevo
