#include <gtest/gtest.h>

#include <Eigen/Geometry>
#include <algorithm>
#include <cmath>
#include <limits>
#include <random>
#include <string>
#include <utility>
#include <vector>

#include "nidevo/odometry/depth_shift.hpp"
#include "nidevo/odometry/odometry_config.hpp"
#include "nidevo/odometry/ortho_projection.hpp"

namespace nidevo {
namespace {

constexpr int kW = 120, kH = 90;

// A smooth depth and grey field sampled at (u - su, v - sv), depth offset by dz.
OrthoImage field(double su, double sv, double dz) {
  OrthoImage img;
  img.resize(kW, kH);
  for (int v = 0; v < kH; ++v) {
    for (int u = 0; u < kW; ++u) {
      const double x = u - su, y = v - sv;
      const size_t i = size_t(v) * kW + u;
      img.depth[i] = float(2.0 + 0.004 * x + 0.002 * y + 0.02 * std::sin(x / 9.0) + dz);
      img.gray[i] = float(0.5 + 0.2 * std::sin(x / 7.0) * std::cos(y / 5.0));
      img.weight[i] = 1.f;
    }
  }
  return img;
}

// The depth-shift parameters of the default config, over every cell.
OdometryConfig oneCellStep() {
  OdometryConfig c;
  c.depth_sample_step = 1;
  return c;
}

TEST(DepthShift, RecoversAKnownDzWithinAMillimetre) {
  DepthShiftEstimator estimator;
  DepthShiftParams params = depthShiftParams(oneCellStep());
  params.resolution = 0.01;
  const OrthoImage key = field(0, 0, 0);
  for (auto [su, sv, dz] :
       {std::tuple{0.0, 0.0, 0.05}, {3.0, -2.0, -0.037}, {2.5, 1.25, 0.081}, {-6.3, 4.7, 0.004}}) {
    // cur(u) = key(u - s) seen from dz nearer: depth_key - depth_cur = dz.
    const OrthoImage cur = field(su, sv, -dz);
    const DepthShift r = estimator.estimate(key, cur, su, sv, params);
    EXPECT_GT(r.inliers, kW * kH / 2);
    EXPECT_NEAR(r.dz, dz, 1e-3) << su << "," << sv;
  }
}

TEST(DepthShift, IgnoresOutliersAndReportsNoMatchOnEmptyImages) {
  DepthShiftEstimator estimator;
  DepthShiftParams params = depthShiftParams(oneCellStep());
  params.resolution = 0.01;
  const OrthoImage key = field(0, 0, 0);
  OrthoImage cur = field(0, 0, -0.02);
  for (int v = 0; v < kH; v += 3)
    for (int u = 0; u < kW; u += 2) cur.depth[size_t(v) * kW + u] += 0.5f;  // far outliers
  EXPECT_NEAR(estimator.estimate(key, cur, 0, 0, params).dz, 0.02, 1e-3);
  OrthoImage empty = field(0, 0, 0);
  std::fill(empty.depth.begin(), empty.depth.end(), 0.f);
  EXPECT_EQ(estimator.estimate(key, empty, 0, 0, params).inliers, 0);
}

// Eq. 18's collection as first written, a branch per test and cell, then the median and the
// inlier means: the estimator's branch-free collection must give the same bits.
DepthShift referenceDepthShift(const OrthoImage& key, const OrthoImage& cur, double du, double dv,
                               const DepthShiftParams& p) {
  const int W = key.width, H = key.height;
  std::vector<float> diffs;
  const int iu = int(std::floor(du)), iv = int(std::floor(dv));
  const float fu = float(du - iu), fv = float(dv - iv);
  const float slope_limit = p.max_slope > 0 ? float(2.0 * p.resolution * p.max_slope) : 0.f;
  const float w00 = (1 - fu) * (1 - fv), w10 = fu * (1 - fv), w01 = (1 - fu) * fv, w11 = fu * fv;
  const int step = std::max(1, p.sample_step);
  for (int v = std::max(0, -iv); v < std::min(H, H - iv - 1); v += step) {
    for (int u = std::max(0, -iu); u < std::min(W, W - iu - 1); u += step) {
      const size_t k = size_t(v) * size_t(W) + size_t(u);
      const float zk = key.depth[k];
      if (zk <= 0.f) continue;
      if (slope_limit > 0.f) {
        if (u == 0 || v == 0 || u == W - 1 || v == H - 1) continue;
        const float zl = key.depth[k - 1], zr = key.depth[k + 1], zt = key.depth[k - size_t(W)],
                    zb = key.depth[k + size_t(W)];
        if (zl <= 0.f || zr <= 0.f || zt <= 0.f || zb <= 0.f) continue;
        if (std::abs(zr - zl) > slope_limit || std::abs(zb - zt) > slope_limit) continue;
      }
      const size_t c = size_t(v + iv) * size_t(W) + size_t(u + iu);
      const float z00 = cur.depth[c], z10 = cur.depth[c + 1], z01 = cur.depth[c + size_t(W)],
                  z11 = cur.depth[c + size_t(W) + 1];
      if (z00 <= 0.f || z10 <= 0.f || z01 <= 0.f || z11 <= 0.f) continue;
      const float zc = w00 * z00 + w10 * z10 + w01 * z01 + w11 * z11;
      const float gc = w00 * cur.gray[c] + w10 * cur.gray[c + 1] + w01 * cur.gray[c + size_t(W)] +
                       w11 * cur.gray[c + size_t(W) + 1];
      if (std::abs(gc - key.gray[k]) >= p.gray_tolerance) continue;
      diffs.push_back(zk - zc);
    }
  }
  DepthShift r;
  if (diffs.empty()) return r;
  std::vector<float> sorted = diffs;
  std::nth_element(sorted.begin(), sorted.begin() + long(diffs.size() / 2), sorted.end());
  double dz = sorted[diffs.size() / 2];
  for (int it = 0; it < p.iterations; ++it) {
    double sum = 0;
    int count = 0;
    for (float d : diffs) {
      if (std::abs(d - dz) < p.inlier_m) {
        sum += d;
        ++count;
      }
    }
    if (count == 0) break;
    dz = sum / count;
    r.inliers = count;
  }
  r.dz = dz;
  return r;
}

TEST(DepthShift, EqualsThePlainPerCellComputationBitForBit) {
  std::mt19937 rng(11);
  std::uniform_real_distribution<float> unit(0.f, 1.f);
  DepthShiftEstimator estimator;
  for (int sample_step : {1, 2}) {
    OdometryConfig config;
    config.depth_sample_step = sample_step;
    DepthShiftParams params = depthShiftParams(config);
    params.resolution = 0.01;
    for (auto [su, sv] : {std::pair{0.0, 0.0}, {2.3, -1.6}, {-4.7, 3.2}, {119.5, 0.0}}) {
      const OrthoImage key = field(0, 0, 0);
      OrthoImage cur = field(su, sv, -0.03);
      OrthoImage holed_key = key;
      // Holes, steps, outliers and grey changes: every test of Eq. 18 decides somewhere.
      for (size_t i = 0; i < cur.depth.size(); ++i) {
        const float a = unit(rng), b = unit(rng);
        if (a < 0.08f) holed_key.depth[i] = 0.f;
        if (a > 0.95f) holed_key.depth[i] += 0.3f;
        if (b < 0.06f) cur.depth[i] = 0.f;
        if (b > 0.9f) cur.depth[i] += 0.2f * unit(rng);
        if (b > 0.5f && b < 0.55f) cur.gray[i] += 0.3f;
      }
      const DepthShift fast = estimator.estimate(holed_key, cur, su, sv, params);
      const DepthShift plain = referenceDepthShift(holed_key, cur, su, sv, params);
      EXPECT_EQ(fast.inliers, plain.inliers) << su << "," << sv << " step " << sample_step;
      EXPECT_EQ(fast.dz, plain.dz) << su << "," << sv << " step " << sample_step;
      if (su < 100) {
        EXPECT_GT(plain.inliers, 100);
      }
    }
  }
}

// A cloud held as the projector takes it: one array per coordinate.
struct TestCloud {
  std::vector<float> x, y, z, gray;
  void add(float px, float py, float pz, float g) {
    x.push_back(px), y.push_back(py), z.push_back(pz), gray.push_back(g);
  }
  CloudView view() const { return {x.data(), y.data(), z.data(), gray.data(), z.size()}; }
};

TEST(OrthoProjection, ResolutionKeepsTheRequestedFractionInside) {
  TestCloud cloud;
  for (int i = -50; i <= 50; ++i)
    for (int j = -50; j <= 50; ++j) cloud.add(float(i) * 0.02f, float(j) * 0.01f, 2.f, 0.3f);
  OrthoProjector projector;
  const double r = projector.resolutionFor(cloud.view(), Eigen::Matrix3f::Identity(), 80, 60, 0.8);
  OrthoImage img;
  projector.project(cloud.view(), Eigen::Matrix3f::Identity(), r, 80, 60, &img);
  size_t inside = 0;
  for (size_t i = 0; i < cloud.z.size(); ++i) {
    const double u = cloud.x[i] / r + 40, v = cloud.y[i] / r + 30;
    inside += u >= 0 && u < 80 && v >= 0 && v < 60;
  }
  EXPECT_NEAR(double(inside) / double(cloud.z.size()), 0.8, 0.03);
}

TEST(OrthoProjection, NearestPointWinsAndEmptyCellsAreMarked) {
  TestCloud cloud;
  cloud.add(0.f, 0.f, 3.f, 0.1f);
  cloud.add(0.f, 0.f, 2.f, 0.7f);
  cloud.add(0.f, 0.f, 4.f, 0.9f);
  OrthoImage img;
  OrthoProjector projector;
  projector.project(cloud.view(), Eigen::Matrix3f::Identity(), 0.01, 20, 20, &img);
  const size_t centre = 10 * 20 + 10;
  EXPECT_FLOAT_EQ(img.depth[centre], 2.f);
  EXPECT_FLOAT_EQ(img.gray[centre], 0.7f);
  EXPECT_EQ(img.filledCount(), 1);
  EXPECT_FLOAT_EQ(img.gray[0], 0.5f);
  EXPECT_FLOAT_EQ(img.depth[0], 0.f);
}

// The projector's loops are written for the vectoriser; this is Eq. 3 and the resolution
// quantile written plainly with Eigen and std::nth_element. The two must agree bit for bit.
TEST(OrthoProjection, EqualsThePlainPerPointComputationBitForBit) {
  TestCloud cloud;
  std::mt19937 rng(7);
  std::uniform_real_distribution<float> xy(-2.f, 2.f), depth(0.3f, 5.f), unit(0.f, 1.f);
  for (int i = 0; i < 20000; ++i) {
    const float z = i % 17 == 0 ? 0.f : depth(rng);  // some points without depth
    cloud.add(xy(rng) * z, xy(rng) * z, z, unit(rng));
  }
  const Eigen::Matrix3f R =
      Eigen::AngleAxisf(0.4f, Eigen::Vector3f(0.3f, -1.f, 0.2f).normalized()).toRotationMatrix();
  const int W = 64, H = 48;
  OrthoProjector projector;
  const double r = projector.resolutionFor(cloud.view(), R, W, H, 0.8);
  OrthoImage fast;
  projector.project(cloud.view(), R, r, W, H, &fast);

  std::vector<float> extent;
  for (size_t i = 0; i < cloud.z.size(); ++i) {
    if (cloud.z[i] <= 0.f) continue;
    const Eigen::Vector3f p = R * Eigen::Vector3f(cloud.x[i], cloud.y[i], cloud.z[i]);
    extent.push_back(std::max(std::abs(p.x()) * (2.f / W), std::abs(p.y()) * (2.f / H)));
  }
  const size_t q = size_t(std::ceil(0.8 * double(extent.size()))) - 1;
  std::nth_element(extent.begin(), extent.begin() + long(q), extent.end());
  EXPECT_EQ(r, double(extent[q]));

  std::vector<float> depth_buffer(size_t(W * H), std::numeric_limits<float>::infinity());
  std::vector<float> gray(size_t(W * H), 0.5f);
  const float inv_r = float(1.0 / r);
  for (size_t i = 0; i < cloud.z.size(); ++i) {
    if (cloud.z[i] <= 0.f) continue;
    const Eigen::Vector3f p = R * Eigen::Vector3f(cloud.x[i], cloud.y[i], cloud.z[i]);
    const int u = int(std::floor(p.x() * inv_r + W / 2.f)),
              v = int(std::floor(p.y() * inv_r + H / 2.f));
    if (u < 0 || v < 0 || u >= W || v >= H || p.z() <= 0.f) continue;
    if (p.z() < depth_buffer[size_t(v * W + u)]) {
      depth_buffer[size_t(v * W + u)] = p.z();
      gray[size_t(v * W + u)] = cloud.gray[i];
    }
  }
  int differing = 0, filled = 0;
  for (size_t c = 0; c < depth_buffer.size(); ++c) {
    const float d = std::isinf(depth_buffer[c]) ? 0.f : depth_buffer[c];
    filled += d > 0.f;
    differing += fast.depth[c] != d || fast.gray[c] != gray[c];
  }
  EXPECT_GT(filled, W * H / 2);
  EXPECT_EQ(differing, 0);
}

// Gap filling as first written: every cell in turn along rows, then along columns, remembering
// the last filled cell. The projector's run-by-run version must give the same image.
void referenceFillGaps(OrthoImage* img, int max_gap, float jump) {
  const int W = img->width, H = img->height;
  auto line = [&](size_t start, size_t stride, int count) {
    int last = -1;
    for (int i = 0; i < count; ++i) {
      const size_t c = start + size_t(i) * stride;
      if (img->depth[c] <= 0.f) continue;
      const int gap = i - last - 1;
      if (last >= 0 && gap > 0 && gap <= max_gap) {
        const size_t c0 = start + size_t(last) * stride;
        const float z0 = img->depth[c0], z1 = img->depth[c];
        if (std::abs(z1 - z0) <= jump * std::min(z0, z1)) {
          for (int k = last + 1; k < i; ++k) {
            const float t = float(k - last) / float(i - last);
            const size_t ck = start + size_t(k) * stride;
            img->depth[ck] = z0 + t * (z1 - z0);
            img->gray[ck] = img->gray[c0] + t * (img->gray[c] - img->gray[c0]);
            img->weight[ck] = img->weight[c0] + t * (img->weight[c] - img->weight[c0]);
          }
        }
      }
      last = i;
    }
  };
  for (int v = 0; v < H; ++v) line(size_t(v) * W, 1, W);
  for (int u = 0; u < W; ++u) line(size_t(u), size_t(W), H);
}

TEST(OrthoProjection, GapFillingEqualsTheCellByCellComputation) {
  // Widths on, under and over the row mask's 64-cell words; gaps up to twice the longest filled.
  for (const int W : {1, 5, 63, 64, 67, 129, 320}) {
    for (const int max_gap : {1, 2, 4}) {
      SCOPED_TRACE("width " + std::to_string(W) + ", max_gap " + std::to_string(max_gap));
      std::mt19937 rng(11 + unsigned(W) * 7 + unsigned(max_gap));
      std::uniform_real_distribution<float> unit(0.f, 1.f);
      OrthoImage img;
      img.resize(W, 41);
      for (size_t c = 0; c < img.depth.size(); ++c) {
        // Two surfaces (a depth step at u = 30), with holes of every length up to about 8.
        const int u = int(c % size_t(W));
        img.depth[c] = unit(rng) < 0.35f ? 0.f : (u < 30 ? 2.f : 2.5f) + 0.01f * unit(rng);
        img.gray[c] = unit(rng);
        img.weight[c] = unit(rng);
      }
      OrthoImage expected = img;
      const int filled_before = img.filledCount();
      OrthoProjector projector;
      projector.fillGaps(&img, max_gap, 0.05f);
      referenceFillGaps(&expected, max_gap, 0.05f);
      if (W >= 64) {
        EXPECT_GT(img.filledCount(), filled_before + W);
      }
      EXPECT_EQ(img.depth, expected.depth);
      EXPECT_EQ(img.gray, expected.gray);
      EXPECT_EQ(img.weight, expected.weight);
    }
  }
}

TEST(OrthoProjection, GapsAreFilledWithinASurfaceOnly) {
  OrthoImage img;
  img.resize(10, 1);
  std::fill(img.depth.begin(), img.depth.end(), 0.f);
  std::fill(img.gray.begin(), img.gray.end(), 0.5f);
  std::fill(img.weight.begin(), img.weight.end(), 1.f);
  img.depth[0] = 2.0f, img.gray[0] = 0.2f;
  img.depth[3] = 2.03f, img.gray[3] = 0.8f;  // two-cell gap within one surface
  img.depth[5] = 3.0f;                       // one-cell gap across a depth jump
  OrthoImage column = img;                   // the same cells as one column
  column.width = 1;
  column.height = 10;
  OrthoProjector projector;
  projector.fillGaps(&img, 2, 0.05f);
  EXPECT_NEAR(img.depth[1], 2.01f, 1e-5);
  EXPECT_NEAR(img.gray[2], 0.6f, 1e-5);
  EXPECT_EQ(img.depth[4], 0.f);
  projector.fillGaps(&column, 2, 0.05f);
  EXPECT_EQ(column.depth, img.depth);
  EXPECT_EQ(column.gray, img.gray);
}

}  // namespace
}  // namespace nidevo
