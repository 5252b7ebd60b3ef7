#include "nidevo/odometry/kcc.hpp"

#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <optional>
#include <random>
#include <tuple>

namespace nidevo {
namespace {

constexpr int kW = 160, kH = 120;

// A band-limited textured patch sampled at (u - su, v - sv): sinusoids with wavelengths of 6 to
// 40 px, so that a sub-pixel shift is represented exactly (no aliasing).
std::vector<float> texture(double su, double sv, uint32_t seed = 5) {
  std::mt19937 rng(seed);
  std::uniform_real_distribution<double> angle(0, 2 * M_PI), wavelength(6, 40), phase(0, 2 * M_PI);
  struct Wave {
    double kx, ky, phase;
  };
  std::vector<Wave> waves;
  for (int i = 0; i < 24; ++i) {
    const double a = angle(rng), k = 2 * M_PI / wavelength(rng);
    waves.push_back({k * std::cos(a), k * std::sin(a), phase(rng)});
  }
  std::vector<float> img(size_t(kW) * kH);
  for (int v = 0; v < kH; ++v) {
    for (int u = 0; u < kW; ++u) {
      double value = 0;
      for (const auto& w : waves) value += std::sin(w.kx * (u - su) + w.ky * (v - sv) + w.phase);
      // The textured patch fades out towards a flat surround, as content does in the
      // orthographic projections, so that a shift moves the whole pattern.
      const double r = std::hypot(u - su - kW / 2.0, v - sv - kH / 2.0) / 55.0;
      const double fade = r < 1 ? 0.5 + 0.5 * std::cos(M_PI * r) : 0.0;
      img[size_t(v) * kW + u] = float(0.5 + 0.08 * fade * value);
    }
  }
  return img;
}

std::vector<float> circularShift(const std::vector<float>& x, int su, int sv) {
  std::vector<float> z(x.size());
  for (int v = 0; v < kH; ++v)
    for (int u = 0; u < kW; ++u)
      z[size_t(v) * kW + u] = x[size_t((v - sv + kH) % kH) * kW + size_t((u - su + kW) % kW)];
  return z;
}

TEST(Kcc, RecoversIntegerShiftsExactly) {
  KernelCrossCorrelator kcc(kW, kH, 1, 0.2, 0.1);
  const auto x = texture(0, 0);
  const float* key[] = {x.data()};
  kcc.train(key);
  for (auto [su, sv] : {std::pair{0, 0}, {3, -7}, {-20, 11}, {45, 30}, {-60, -50}}) {
    const auto z = circularShift(x, su, sv);
    const float* cur[] = {z.data()};
    const KccMatch m = kcc.match(cur, /*subpixel=*/false, 5);
    EXPECT_EQ(m.du, su);
    EXPECT_EQ(m.dv, sv);
    EXPECT_GT(m.psr, 20);
  }
}

class KccSubpixel : public ::testing::TestWithParam<double> {};

TEST_P(KccSubpixel, RecoversSubpixelShifts) {
  KernelCrossCorrelator kcc(kW, kH, 1, 0.2, 0.1, GetParam());
  const auto x = texture(0, 0);
  const float* key[] = {x.data()};
  kcc.train(key);
  for (auto [su, sv] : {std::pair{0.3, -0.4}, {2.5, 1.2}, {-7.7, 4.45}, {10.1, -3.6}}) {
    const auto z = texture(su, sv);
    const float* cur[] = {z.data()};
    const KccMatch m = kcc.match(cur, /*subpixel=*/true, 5);
    EXPECT_NEAR(m.du, su, 0.1);
    EXPECT_NEAR(m.dv, sv, 0.1);
  }
}

INSTANTIATE_TEST_SUITE_P(LabelSigma, KccSubpixel, ::testing::Values(0.0, 1.0, 2.0, 3.0));

TEST(Kcc, PsrIsHighOnAMatchAndLowOnUnrelatedImages) {
  KernelCrossCorrelator kcc(kW, kH, 1, 0.2, 0.1);
  const auto x = texture(0, 0, 5);
  const float* key[] = {x.data()};
  kcc.train(key);
  const auto same = texture(4, 2, 5);
  const auto other = texture(0, 0, 99);
  std::mt19937 rng(1);
  std::uniform_real_distribution<float> noise(0.f, 1.f);
  std::vector<float> random(x.size());
  for (float& r : random) r = noise(rng);
  const float* a[] = {same.data()};
  const float* b[] = {other.data()};
  const float* c[] = {random.data()};
  const double psr_match = kcc.match(a, true, 5).psr;
  const double psr_other = kcc.match(b, true, 5).psr;
  const double psr_random = kcc.match(c, true, 5).psr;
  EXPECT_GT(psr_match, 30);
  EXPECT_LT(psr_other, psr_match / 3);
  EXPECT_LT(psr_random, psr_match / 3);
}

// Eq. 17 by the book on the filter's response: every cell whose circular distance from the peak
// exceeds the exclusion in u or v is side lobe. The peak sits at the image's corner, so that the
// excluded window wraps around both borders.
TEST(Kcc, PsrIsEq17WithTheExcludedWindowWrappingAroundTheBorders) {
  KernelCrossCorrelator kcc(kW, kH, 1, 0.2, 0.1);
  const auto x = texture(0, 0);
  const float* key[] = {x.data()};
  kcc.train(key);
  for (auto [su, sv, exclusion] : {std::tuple{-2, 1, 5}, {3, -4, 5}, {40, 30, 2}, {0, 0, 7}}) {
    const auto z = circularShift(x, su, sv);
    const float* cur[] = {z.data()};
    const KccMatch m = kcc.match(cur, /*subpixel=*/false, exclusion);
    ASSERT_EQ(m.du, su);
    ASSERT_EQ(m.dv, sv);
    const int pu = (su + kW) % kW, pv = (sv + kH) % kH;
    const float* response = kcc.response();
    double sum = 0, sum2 = 0, count = 0;
    for (int v = 0; v < kH; ++v) {
      for (int u = 0; u < kW; ++u) {
        const int dx = std::min(std::abs(u - pu), kW - std::abs(u - pu));
        const int dy = std::min(std::abs(v - pv), kH - std::abs(v - pv));
        if (dx <= exclusion && dy <= exclusion) continue;
        const double r = response[size_t(v) * kW + size_t(u)];
        sum += r, sum2 += r * r, count += 1;
      }
    }
    EXPECT_EQ(count, kW * kH - (2 * exclusion + 1) * (2 * exclusion + 1));
    const double mean = sum / count, sd = std::sqrt(sum2 / count - mean * mean);
    EXPECT_NEAR(m.psr, (m.peak - mean) / sd, 1e-9 * std::abs(m.psr));
  }
}

TEST(Kcc, TwoChannelsRecoverTheShiftOfAFeaturelessGreyImage) {
  KernelCrossCorrelator kcc(kW, kH, 2, 0.2, 0.1);
  const std::vector<float> flat(size_t(kW) * kH, 0.5f);
  const auto depth = texture(0, 0, 11);
  const float* key[] = {flat.data(), depth.data()};
  kcc.train(key);
  const auto shifted = circularShift(depth, -9, 4);
  const float* cur[] = {flat.data(), shifted.data()};
  const KccMatch m = kcc.match(cur, false, 5);
  EXPECT_EQ(m.du, -9);
  EXPECT_EQ(m.dv, 4);
}

// A tiling of period 20 x 24 px that repeats exactly around the circular image (160 x 120), so
// that every shift by a whole period fits exactly as well.
// An image that varies along u only (the projection of a bare wall's vertical edge) fits every
// shift along v as well: the response is a ridge along v and stays sharp along u. A textured patch
// gives a sharp peak both ways; not asked for, nothing is measured.
TEST(Kcc, TheResponseIsARidgeAlongAnAxisTheImagesLeaveFree) {
  const auto patch = texture(0, 0);
  std::vector<float> columns(patch.size());
  for (int u = 0; u < kW; ++u) {
    double sum = 0;
    for (int v = 0; v < kH; ++v) sum += patch[size_t(v) * kW + u];
    for (int v = 0; v < kH; ++v) columns[size_t(v) * kW + u] = float(sum / kH);
  }
  for (const bool free_v : {true, false}) {
    const auto& x = free_v ? columns : patch;
    KernelCrossCorrelator kcc(kW, kH, 1, 0.2, 0.1);
    const float* key[] = {x.data()};
    kcc.train(key);
    const auto z = circularShift(x, 4, 3);
    const float* cur[] = {z.data()};
    const KccMatch m = kcc.match(cur, false, 5, nullptr, 8);
    EXPECT_LT(m.ridge_u, 0.5) << (free_v ? "columns" : "patch");
    if (free_v)
      EXPECT_GT(m.ridge_v, 0.9);
    else
      EXPECT_LT(m.ridge_v, 0.5);
    const KccMatch plain = kcc.match(cur, false, 5);
    EXPECT_EQ(plain.ridge_u, 0.0);
    EXPECT_EQ(plain.ridge_v, 0.0);
  }
}

std::vector<float> tiles() {
  std::vector<float> img(size_t(kW) * kH);
  for (int v = 0; v < kH; ++v)
    for (int u = 0; u < kW; ++u)
      img[size_t(v) * kW + u] =
          float(0.5 + 0.2 * std::cos(2 * M_PI * u / 20) + 0.1 * std::sin(2 * M_PI * v / 24) +
                0.05 * std::sin(2 * M_PI * u / 10) * std::cos(2 * M_PI * v / 24));
  return img;
}

TEST(Kcc, APeriodicTextureShiftedByLessThanHalfAPeriodIsNotAliased) {
  KernelCrossCorrelator kcc(kW, kH, 1, 0.2, 0.1);
  const auto x = tiles();
  const float* key[] = {x.data()};
  kcc.train(key);
  const auto z = circularShift(x, 7, -9);  // under half of the 20 x 24 period
  const float* cur[] = {z.data()};
  // Standing still predicted: the true shift is the nearest of the equal peaks.
  const KccShiftPrior still{0, 0, 0.9};
  const KccMatch m = kcc.match(cur, false, 5, &still);
  EXPECT_EQ(m.du, 7);
  EXPECT_EQ(m.dv, -9);
  EXPECT_GT(m.rival_peaks, 0);  // the other periods are reported as rivals
  // A prediction one period away picks that period: the prior, not rounding, decides.
  const KccShiftPrior next{-12, 14, 0.9};
  const KccMatch aliased = kcc.match(cur, false, 5, &next);
  EXPECT_EQ(aliased.du, 7 - 20);
  EXPECT_EQ(aliased.dv, -9 + 24);
}

TEST(Kcc, AClearlyHigherPeakWinsWhereverThePriorIs) {
  KernelCrossCorrelator kcc(kW, kH, 1, 0.2, 0.1);
  const auto x = texture(0, 0);
  const float* key[] = {x.data()};
  kcc.train(key);
  const auto z = circularShift(x, 3, -7);
  const float* cur[] = {z.data()};
  const KccShiftPrior far_off{40, 30, 0.9};
  const KccMatch m = kcc.match(cur, false, 5, &far_off);
  EXPECT_EQ(m.du, 3);
  EXPECT_EQ(m.dv, -7);
  EXPECT_EQ(m.rival_peaks, 0);
}

// The peak the match reports is the first largest cell of its response, as a plain walk finds
// it; with a prior, the nearest of the strong local maxima and the rivals a plain walk counts.
TEST(Kcc, PeakAndRivalsAreThoseOfAPlainWalkOverTheResponse) {
  KernelCrossCorrelator kcc(kW, kH, 1, 0.2, 0.1);
  const auto x = tiles();
  const float* key[] = {x.data()};
  kcc.train(key);
  const auto z = circularShift(x, 4, -3);
  const float* cur[] = {z.data()};
  const int exclusion = 5;
  for (const std::optional<KccShiftPrior>& prior :
       {std::optional<KccShiftPrior>(), std::optional(KccShiftPrior{-15, 20, 0.9}),
        std::optional(KccShiftPrior{30, -40, 0.2})}) {  // 0.2: side lobes count too
    const KccMatch m = kcc.match(cur, false, exclusion, prior ? &*prior : nullptr);
    const float* r = kcc.response();
    const size_t n = size_t(kW) * kH;
    size_t best = 0;
    for (size_t i = 1; i < n; ++i)
      if (r[i] > r[best]) best = i;
    auto at = [&](int u, int v) { return r[size_t((v + kH) % kH) * kW + size_t((u + kW) % kW)]; };
    auto localMax = [&](int u, int v) {
      for (int y = -1; y <= 1; ++y)
        for (int x2 = -1; x2 <= 1; ++x2)
          if ((x2 || y) && at(u + x2, v + y) > at(u, v)) return false;
      return true;
    };
    auto shift = [](int c, int size) { return c > size / 2 ? c - size : c; };
    auto d2 = [&](size_t i, double du, double dv) {
      double dx = std::abs(shift(int(i % kW), kW) - du), dy = std::abs(shift(int(i / kW), kH) - dv);
      dx = std::min(dx, kW - dx), dy = std::min(dy, kH - dy);
      return dx * dx + dy * dy;
    };
    int rivals = 0;
    if (prior) {
      const float floor = float(prior->ratio) * r[best];
      size_t chosen = best;
      for (size_t i = 0; i < n; ++i)
        if (!(r[i] < floor) && localMax(int(i % kW), int(i / kW)) &&
            d2(i, prior->du, prior->dv) < d2(chosen, prior->du, prior->dv))
          chosen = i;
      const double cu = shift(int(chosen % kW), kW), cv = shift(int(chosen / kW), kH);
      for (size_t i = 0; i < n; ++i)
        if (!(r[i] < floor) && localMax(int(i % kW), int(i / kW)) &&
            d2(i, cu, cv) > double(exclusion) * exclusion)
          ++rivals;
      best = chosen;
    }
    EXPECT_EQ(m.du, shift(int(best % kW), kW));
    EXPECT_EQ(m.dv, shift(int(best / kW), kH));
    EXPECT_EQ(m.rival_peaks, rivals);
  }
}

}  // namespace
}  // namespace nidevo
