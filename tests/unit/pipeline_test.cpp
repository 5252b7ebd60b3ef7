// The offline three-thread pipeline (its own file: the ThreadSanitizer build runs it).
#include "nidevo/odometry/pipeline.hpp"

#include <gtest/gtest.h>

#include <vector>

#include "nidevo/io/camera_io.hpp"
#include "nidevo/sim/sequence.hpp"

namespace nidevo {
namespace {

TEST(Pipeline, ThreeThreadsGiveTheSequentialPoses) {
  synth::SequenceConfig c;
  c.frames = 40;
  c.camera = cameraPreset("icl")->subsampled(2);  // 320x240 keeps the sanitizer run short
  const synth::SyntheticSequence seq(c);
  std::vector<RgbdFrame> frames;
  for (int i = 0; i < seq.size(); ++i) frames.push_back(seq.renderFrame(i));
  auto source = [&](size_t i) -> const RgbdFrame& { return frames[i]; };
  Odometry a(seq.config().camera, OdometryConfig{}), b(seq.config().camera, OdometryConfig{});
  const auto sequential = runSequential(a, frames.size(), source);
  const auto pipelined = runPipelined(b, frames.size(), source);
  ASSERT_EQ(sequential.size(), pipelined.size());
  for (size_t i = 0; i < frames.size(); ++i) {
    EXPECT_EQ(pipelined[i].frame_index, i);
    EXPECT_TRUE(sequential[i].T_world_cam.isApprox(pipelined[i].T_world_cam, 1e-12)) << i;
  }
}

}  // namespace
}  // namespace nidevo
