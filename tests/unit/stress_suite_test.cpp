#include "nidevo/sim/stress_suite.hpp"

#include <gtest/gtest.h>

#include <algorithm>
#include <random>

namespace nidevo::synth {
namespace {

TEST(StressSuite, ASequenceFromTheSameSeedRendersIdenticallyTwice) {
  const SequenceConfig a = stressSequenceConfig(5), b = stressSequenceConfig(5);
  EXPECT_EQ(describe(a), describe(b));
  const SyntheticSequence first(a), second(b);
  const RenderedFrame f1 = first.render(7), f2 = second.render(7);
  EXPECT_EQ(f1.rgb, f2.rgb);
  EXPECT_EQ(f1.frame.depth.data, f2.frame.depth.data);
  EXPECT_TRUE(first.groundTruth(40).isApprox(second.groundTruth(40), 0));
  // Another seed is another scene and motion.
  const SyntheticSequence other(stressSequenceConfig(6));
  EXPECT_NE(other.render(7).rgb, f1.rgb);
}

TEST(StressSuite, TwentySequencesCoverEverySensorLensAndExposureCase) {
  int noise[3] = {0, 0, 0}, distorted = 0, exposure = 0;
  for (uint64_t k = 0; k < 20; ++k) {
    const SequenceConfig c = stressSequenceConfig(k);
    EXPECT_GE(c.frames, 150);
    EXPECT_LE(c.frames, 300);
    ++noise[int(c.noise)];
    distorted += !c.camera.distortion.none();
    exposure += c.exposure_jumps_per_s > 0;
    EXPECT_TRUE(c.validate().empty()) << c.validate();
  }
  EXPECT_GT(noise[0] * noise[1] * noise[2], 0);
  EXPECT_GT(distorted, 0);
  EXPECT_LT(distorted, 20);
  EXPECT_GT(exposure, 0);
}

TEST(SurfacePatterns, PeriodicPatternsRepeatAtTheirPeriodAndVaryWithinIt) {
  std::mt19937 rng(3);
  std::uniform_real_distribution<double> coord(-5, 5);
  for (SurfacePattern p :
       {SurfacePattern::kTiles, SurfacePattern::kStripes, SurfacePattern::kGrid}) {
    const double period = 0.23;
    int differs_within = 0;
    for (int i = 0; i < 2000; ++i) {
      const double s = coord(rng), t = coord(rng);
      const double v = patternValue(p, TextureRichness::kRich, 1, period, s, t);
      EXPECT_EQ(v, patternValue(p, TextureRichness::kRich, 1, period, s + period, t))
          << toString(p);
      EXPECT_EQ(v, patternValue(p, TextureRichness::kRich, 1, period, s, t + 3 * period))
          << toString(p);
      differs_within +=
          v != patternValue(p, TextureRichness::kRich, 1, period, s + 0.37 * period, t);
    }
    EXPECT_GT(differs_within, 200) << toString(p) << " is not a pattern";
  }
}

// Distinct depths the model gives for true depths within 5 cm of z: their typical spacing.
double depthStepNear(double z, const SequenceConfig& c) {
  std::vector<double> values;
  for (int i = -5000; i <= 5000; ++i) values.push_back(structuredLightDepth(z + 1e-5 * i, 0, c));
  std::sort(values.begin(), values.end());
  values.erase(std::unique(values.begin(), values.end()), values.end());
  std::vector<double> gaps;
  for (size_t i = 1; i < values.size(); ++i) gaps.push_back(values[i] - values[i - 1]);
  std::nth_element(gaps.begin(), gaps.begin() + long(gaps.size() / 2), gaps.end());
  return gaps[gaps.size() / 2];
}

TEST(StructuredLight, DepthStepsGrowWithTheSquareOfDepth) {
  const SequenceConfig c;
  for (double z : {1.0, 2.0, 3.0}) {
    const double expected = z * z * c.sl_disparity_step_px / c.disparity_focal_baseline;
    EXPECT_NEAR(depthStepNear(z, c), expected, 0.1 * expected) << z << " m";
  }
  EXPECT_NEAR(depthStepNear(3.0, c) / depthStepNear(1.0, c), 9.0, 1.0);
}

TEST(StructuredLight, HasAMaximumRangeAndHolesWhereAKinectHasThem) {
  SequenceConfig c;
  c.scene = "corridor";  // 16 m long: far walls beyond the range
  c.frames = 1;
  c.camera = c.camera.subsampled(2);
  const RgbdFrame clean = SyntheticSequence(c).renderFrame(0);
  c.noise = SensorNoise::kStructuredLight;
  const RgbdFrame kinect = SyntheticSequence(c).renderFrame(0);
  int beyond_clean = 0, holes = 0;
  for (size_t i = 0; i < clean.depth.size(); ++i) {
    beyond_clean += clean.depth.data[i] > c.sl_max_range_m;
    EXPECT_LE(kinect.depth.data[i], c.sl_max_range_m + 0.01);
    holes += kinect.depth.data[i] == 0 && clean.depth.data[i] > 0 &&
             clean.depth.data[i] < c.sl_max_range_m;
  }
  EXPECT_GT(beyond_clean, 100);  // the far part of the corridor is out of range...
  EXPECT_GT(holes, 50);          // ...and edges and grazing walls lose depth within it
}

TEST(LensDistortion, DistortedRenderingReprojectsThroughTheModelWithinHalfAPixel) {
  SequenceConfig c;
  c.frames = 1;
  c.camera = c.camera.subsampled(2);
  c.camera.distortion = {0.2624, -0.9531, -0.0054, 0.0026, 1.1633};  // TUM fr1
  const SyntheticSequence seq(c);
  const Camera& cam = c.camera;
  const Eigen::Isometry3d T = seq.groundTruth(0);
  const DepthImageF depth = seq.renderFrame(0).depth;
  int checked = 0, bent = 0;
  for (int v = 2; v < cam.height; v += 9) {
    for (int u = 2; u < cam.width; u += 9) {
      const double d = depth.at(u, v);
      if (!(d > 0)) continue;
      // The ray the lens bent onto pixel (u, v), and where a pinhole camera would image it.
      const Eigen::Vector2d ray =
          cam.distortion.undistort({(u - cam.cx) / cam.fx, (v - cam.cy) / cam.fy});
      const double ui = cam.fx * ray.x() + cam.cx, vi = cam.fy * ray.y() + cam.cy;
      bent += std::hypot(ui - u, vi - v) > 2;
      // The renderer saw that ray: the pinhole depth there is the pixel's depth...
      EXPECT_NEAR(seq.depthAt(T, ui, vi), d, 1e-3 * d) << u << "," << v;
      // ...and the point projects back through the forward model onto the pixel.
      const Eigen::Vector3d X(ray.x() * d, ray.y() * d, d);
      const Eigen::Vector2d p = cam.distortion.distort({X.x() / X.z(), X.y() / X.z()});
      EXPECT_LT(std::hypot(cam.fx * p.x() + cam.cx - u, cam.fy * p.y() + cam.cy - v), 0.5);
      ++checked;
    }
  }
  EXPECT_GT(checked, 500);
  EXPECT_GT(bent, 50);  // the distortion is not negligible
}

TEST(Exposure, JumpsChangeTheImageByTenToThirtyPercentAndNotTheDepth) {
  SequenceConfig c;
  c.frames = 60;
  c.camera = c.camera.subsampled(4);
  const SyntheticSequence steady(c);
  c.exposure_jumps_per_s = 3;
  const SyntheticSequence jumping(c);
  double max_ratio = 1;
  for (int i = 0; i < c.frames; ++i) {
    const RgbdFrame a = steady.renderFrame(i), b = jumping.renderFrame(i);
    EXPECT_EQ(a.depth.data, b.depth.data);
    double sum_a = 0, sum_b = 0;
    for (size_t k = 0; k < a.gray.size(); ++k) sum_a += a.gray.data[k], sum_b += b.gray.data[k];
    max_ratio = std::max({max_ratio, sum_b / sum_a, sum_a / sum_b});
  }
  EXPECT_GT(max_ratio, 1.09);  // at least one jump of 10 % or more happened
}

}  // namespace
}  // namespace nidevo::synth
