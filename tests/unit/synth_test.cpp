#include <gtest/gtest.h>

#include "nidevo/io/camera_io.hpp"
#include "nidevo/sim/sequence.hpp"

namespace nidevo::synth {
namespace {

SequenceConfig quarterConfig(const std::string& scene) {
  SequenceConfig c;
  c.scene = scene;
  c.camera = cameraPreset("icl")->subsampled(2);  // 320x240
  c.frames = 60;
  return c;
}

class SynthScenes : public ::testing::TestWithParam<std::string> {};

TEST_P(SynthScenes, BackProjectedDepthLiesOnTheSceneAndReprojects) {
  const SyntheticSequence seq(quarterConfig(GetParam()));
  const Camera& cam = seq.config().camera;
  for (int i : {0, 20, 45}) {
    const int j = i + 10;
    const Eigen::Isometry3d Ti = seq.groundTruth(i), Tj = seq.groundTruth(j);
    const RgbdFrame f = seq.renderFrame(i);
    int valid = 0, visible = 0;
    double worst_px = 0;
    for (int v = 3; v < cam.height; v += 7) {
      for (int u = 5; u < cam.width; u += 7) {
        const float z = f.depth.at(u, v);
        if (z <= 0) continue;
        ++valid;
        const Eigen::Vector3d p = Ti * cam.backproject(float(u), float(v), z).cast<double>();
        ASSERT_LT(seq.distanceToScene(p), 1e-4) << "frame " << i << " pixel " << u << "," << v;
        const Eigen::Vector3d pj = Tj.inverse() * p;
        if (pj.z() <= 0.05) continue;
        const Eigen::Vector2d uv = cam.project(pj);
        if (uv.x() < 0 || uv.y() < 0 || uv.x() > cam.width - 1 || uv.y() > cam.height - 1) continue;
        const double dj = seq.depthAt(Tj, uv.x(), uv.y());
        if (std::abs(dj - pj.z()) > 1e-3 * pj.z()) continue;  // occluded in frame j
        ++visible;
        // Back into frame i through frame j's own depth.
        const Eigen::Vector3d q =
            Ti.inverse() *
            (Tj *
             (Eigen::Vector3d((uv.x() - cam.cx) / cam.fx, (uv.y() - cam.cy) / cam.fy, 1) * dj));
        const Eigen::Vector2d back = cam.project(q);
        worst_px = std::max(worst_px, (back - Eigen::Vector2d(u, v)).norm());
      }
    }
    EXPECT_GT(valid, 1000) << "frame " << i;
    EXPECT_GT(visible, valid / 3) << "frame " << i;
    EXPECT_LT(worst_px, 0.5) << "frame " << i;
  }
}

INSTANTIATE_TEST_SUITE_P(AllScenes, SynthScenes,
                         ::testing::Values("office", "corridor", "corner", "gap"));

TEST(Synth, RenderedDepthEqualsRayDepthAtPixelCentres) {
  const SyntheticSequence seq(quarterConfig("office"));
  const RgbdFrame f = seq.renderFrame(5);
  for (int v = 0; v < 240; v += 31)
    for (int u = 0; u < 320; u += 29)
      EXPECT_NEAR(f.depth.at(u, v), seq.depthAt(seq.groundTruth(5), u, v), 1e-5);
}

TEST(Synth, DeterministicForASeedAndSeedChangesMotion) {
  SequenceConfig c = quarterConfig("office");
  c.noise = SensorNoise::kIclLike;
  const SyntheticSequence a(c), b(c);
  EXPECT_EQ(a.renderFrame(7).depth.data, b.renderFrame(7).depth.data);
  EXPECT_EQ(a.renderFrame(7).gray.data, b.renderFrame(7).gray.data);
  c.seed = 2;
  const SyntheticSequence d(c);
  EXPECT_FALSE(a.groundTruth(7).isApprox(d.groundTruth(7), 1e-6));
}

TEST(Synth, MotionIsSmooth) {
  const SyntheticSequence seq(quarterConfig("office"));
  for (int i = 1; i < 600; ++i) {
    const Eigen::Isometry3d d = seq.groundTruth(i - 1).inverse() * seq.groundTruth(i);
    EXPECT_LT(d.translation().norm(), 0.03) << i;  // < 0.9 m/s at 30 Hz
    EXPECT_LT(Eigen::AngleAxisd(d.rotation()).angle(), 0.06) << i;
  }
}

TEST(Synth, IclNoiseIsBoundedAndDropsGrazingAndFarDepth) {
  SequenceConfig c = quarterConfig("corridor");
  const SyntheticSequence clean(c);
  c.noise = SensorNoise::kIclLike;
  const SyntheticSequence noisy(c);
  const RgbdFrame a = clean.renderFrame(10), b = noisy.renderFrame(10);
  int both = 0, dropped = 0, differ = 0;
  double sum_rel = 0;
  for (size_t k = 0; k < a.depth.size(); ++k) {
    if (a.depth.data[k] > 0 && b.depth.data[k] == 0) ++dropped;
    if (a.depth.data[k] > 0 && b.depth.data[k] > 0) {
      ++both;
      differ += a.depth.data[k] != b.depth.data[k];
      sum_rel += std::abs(a.depth.data[k] - b.depth.data[k]) / a.depth.data[k];
    }
    EXPECT_LE(b.depth.data[k], c.max_range_m + 1e-3);
  }
  EXPECT_GT(dropped, 0);  // the corridor's far end is beyond the range
  EXPECT_GT(differ, both / 2);
  EXPECT_LT(sum_rel / both, 0.03);  // mean relative error a few mm per metre, not garbage
}

TEST(Synth, BadConfigIsRejected) {
  SequenceConfig c;
  c.frames = 0;
  EXPECT_THROW(SyntheticSequence{c}, std::invalid_argument);
  c = SequenceConfig{};
  c.scene = "moon";
  EXPECT_THROW(SyntheticSequence{c}, std::invalid_argument);
  EXPECT_THROW(parseTextureRichness("shiny"), std::invalid_argument);
}

}  // namespace
}  // namespace nidevo::synth
