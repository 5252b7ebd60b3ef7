// expInPlace gives std::exp's bits: the KCC's poses must not move when its kernel takes the
// vector path. Checked over the range the Gaussian kernel uses (exponents <= 0) and beyond, at
// glibc's special-case boundaries, for every length's tail, and on NaN and infinities.
#include "exp_in_place.hpp"

#include <gtest/gtest.h>

#include <cmath>
#include <cstdint>
#include <cstring>
#include <limits>
#include <vector>

namespace nidevo {
namespace {

uint32_t bitsOf(float x) {
  uint32_t u;
  std::memcpy(&u, &x, sizeof u);
  return u;
}

float floatOf(uint32_t u) {
  float x;
  std::memcpy(&x, &u, sizeof x);
  return x;
}

// Mismatches of expInPlace against std::exp over the bit patterns from..to (inclusive), every
// `step`-th one; the first one's input goes to *first.
size_t mismatches(uint32_t from, uint32_t to, uint32_t step, float* first) {
  std::vector<float> values;
  for (uint64_t b = from; b <= to; b += step) values.push_back(floatOf(uint32_t(b)));
  std::vector<float> got = values;
  expInPlace(got.data(), got.size());
  size_t bad = 0;
  for (size_t i = 0; i < values.size(); ++i) {
    if (bitsOf(got[i]) == bitsOf(std::exp(values[i]))) continue;
    if (bad++ == 0) *first = values[i];
  }
  return bad;
}

TEST(ExpInPlace, SameBitsAsStdExpOverTheKernelsRange) {
  RecordProperty("vectorised", expInPlaceIsVectorised() ? "yes" : "no");
  float first = 0;
  // 0 down to -120 (the kernel's exponents), every 61st float: about 18 million.
  EXPECT_EQ(mismatches(bitsOf(-0.f), bitsOf(-120.f), 61, &first), 0u) << "first at " << first;
  // Every float where glibc's special cases begin and end: |x| from 80 to 110.
  EXPECT_EQ(mismatches(bitsOf(-80.f), bitsOf(-110.f), 1, &first), 0u) << "first at " << first;
  EXPECT_EQ(mismatches(bitsOf(80.f), bitsOf(100.f), 1, &first), 0u) << "first at " << first;
  // Positive exponents, every 61st float up to 80.
  EXPECT_EQ(mismatches(bitsOf(0.f), bitsOf(80.f), 61, &first), 0u) << "first at " << first;
}

TEST(ExpInPlace, SpecialValuesAndEveryTailLength) {
  const float inf = std::numeric_limits<float>::infinity();
  std::vector<float> specials = {
      -inf,   inf, std::numeric_limits<float>::quiet_NaN(), -0.f, 0.f, -1e-30f, 1e-30f, -103.5f,
      -104.f, 89.f};
  for (size_t n = 0; n <= 2 * specials.size(); ++n) {
    std::vector<float> values(n);
    for (size_t i = 0; i < n; ++i)
      values[i] = i < specials.size() ? specials[i] : -0.37f * float(i);
    std::vector<float> got = values;
    expInPlace(got.data(), n);
    for (size_t i = 0; i < n; ++i) {
      const float want = std::exp(values[i]);
      if (std::isnan(want))
        EXPECT_TRUE(std::isnan(got[i])) << values[i];
      else
        EXPECT_EQ(bitsOf(got[i]), bitsOf(want))
            << "exp(" << values[i] << ") at " << i << " of " << n;
    }
  }
}

}  // namespace
}  // namespace nidevo
