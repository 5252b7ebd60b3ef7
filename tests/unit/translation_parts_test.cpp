#include <gtest/gtest.h>

#include <cmath>

#include "nidevo/depth_shift.hpp"
#include "nidevo/ortho_projection.hpp"

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

TEST(DepthShift, RecoversAKnownDzWithinAMillimetre) {
  DepthShiftEstimator estimator;
  DepthShiftParams params;
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
  DepthShiftParams params;
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

TEST(OrthoProjection, ResolutionKeepsTheRequestedFractionInside) {
  std::vector<Eigen::Vector3f> points;
  std::vector<float> gray;
  for (int i = -50; i <= 50; ++i)
    for (int j = -50; j <= 50; ++j) {
      points.emplace_back(i * 0.02f, j * 0.01f, 2.f);
      gray.push_back(0.3f);
    }
  OrthoProjector projector;
  const CloudView cloud{points.data(), gray.data(), points.size()};
  const double r = projector.resolutionFor(cloud, Eigen::Matrix3f::Identity(), 80, 60, 0.8);
  OrthoImage img;
  OrthoProjector::project(cloud, Eigen::Matrix3f::Identity(), r, 80, 60, &img);
  size_t inside = 0;
  for (const auto& p : points) {
    const double u = p.x() / r + 40, v = p.y() / r + 30;
    inside += u >= 0 && u < 80 && v >= 0 && v < 60;
  }
  EXPECT_NEAR(double(inside) / double(points.size()), 0.8, 0.03);
}

TEST(OrthoProjection, NearestPointWinsAndEmptyCellsAreMarked) {
  const std::vector<Eigen::Vector3f> points = {{0.f, 0.f, 3.f}, {0.f, 0.f, 2.f}, {0.f, 0.f, 4.f}};
  const std::vector<float> gray = {0.1f, 0.7f, 0.9f};
  OrthoImage img;
  OrthoProjector::project({points.data(), gray.data(), points.size()}, Eigen::Matrix3f::Identity(),
                          0.01, 20, 20, &img);
  const size_t centre = 10 * 20 + 10;
  EXPECT_FLOAT_EQ(img.depth[centre], 2.f);
  EXPECT_FLOAT_EQ(img.gray[centre], 0.7f);
  EXPECT_EQ(img.filledCount(), 1);
  EXPECT_FLOAT_EQ(img.gray[0], 0.5f);
  EXPECT_FLOAT_EQ(img.depth[0], 0.f);
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
