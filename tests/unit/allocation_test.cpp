// Steady state allocates nothing: counts global operator new calls over 100 frames after warm-up.
#include <gtest/gtest.h>

#include "counting_new.hpp"
#include "map_frame.hpp"
#include "nidevo/io/camera_io.hpp"
#include "nidevo/odometry/depth_alignment.hpp"
#include "nidevo/odometry/odometry.hpp"
#include "nidevo/sim/sequence.hpp"

using nidevo::test::allocations;
using nidevo::test::counting;

namespace nidevo {
namespace {

TEST(Allocation, SteadyStateTrackingAllocatesNothing) {
  synth::SequenceConfig c;
  c.frames = 30;
  c.camera = cameraPreset("icl")->subsampled(2);  // 320x240 keeps the sanitizer run short
  const synth::SyntheticSequence seq(c);
  std::vector<RgbdFrame> frames;
  for (int i = 0; i < seq.size(); ++i) frames.push_back(seq.renderFrame(i));
  Odometry odometry(c.camera, OdometryConfig{});
  auto frame = [&](int k) -> RgbdFrame& {  // back and forth through the sequence
    const int period = 2 * (seq.size() - 1);
    const int i = k % period;
    return frames[size_t(i < seq.size() ? i : period - i)];
  };
  int k = 0;
  for (; k < 60; ++k) odometry.track(frame(k));  // warm-up: buffers reach their sizes
  allocations = 0;
  counting = true;
  int keyframes = 0;
  for (int end = k + 100; k < end; ++k) {
    const PoseEstimate p = odometry.track(frame(k));
    keyframes += p.rotation_keyframe + p.translation_keyframe;
  }
  counting = false;
  EXPECT_EQ(allocations.load(), 0);
  EXPECT_GT(keyframes, 0);  // the keyframe paths were exercised too
}

// The pose check's coarse-to-fine hypothesis, run only when every other one failed, so rarely
// that the tracking loop above may never reach it: its pyramid and alignments on their own.
TEST(Allocation, CoarseToFineAlignmentAllocatesNothingOnceReserved) {
  synth::SequenceConfig c;
  c.frames = 10;
  c.camera = cameraPreset("icl")->subsampled(2);
  const synth::SyntheticSequence seq(c);
  const OdometryConfig config;
  const test::MapFrame ref = test::mapOf(seq.renderFrame(0), c.camera, config);
  const test::MapFrame cur = test::mapOf(seq.renderFrame(9), c.camera, config);
  const Camera map_camera = c.camera.subsampled(config.normal_stride);
  SurfaceSample sample;
  sampleSurface(ref.map, ref.intensity, config.verify_sample_step, &sample);
  AlignmentTarget target;
  buildAlignmentTarget(cur.map, cur.intensity, &target);
  AlignmentPyramid pyramid;
  pyramid.reserve(config.align_coarse_levels, map_camera);
  DepthAligner aligner;
  aligner.reserve(sample.size());
  const AlignmentParams params = alignmentParams(config);
  allocations = 0;
  counting = true;
  pyramid.build(target);
  const AlignmentResult a = aligner.alignCoarseToFine(sample, target, map_camera, pyramid,
                                                      Eigen::Isometry3d::Identity(), params);
  counting = false;
  EXPECT_EQ(allocations.load(), 0);
  EXPECT_GT(a.steps, 0);  // it aligned
}

// The check of the direction the grey values fix least where depth leaves it weak, with the pose
// moved either way and fitted again: on the real clip it runs on most frames.
TEST(Allocation, GreyFixedDirectionCheckAllocatesNothing) {
  synth::SequenceConfig c;
  c.frames = 3;
  c.camera = cameraPreset("icl")->subsampled(2);
  const synth::SyntheticSequence seq(c);
  const OdometryConfig config;
  const test::MapFrame ref = test::mapOf(seq.renderFrame(0), c.camera, config);
  const test::MapFrame cur = test::mapOf(seq.renderFrame(2), c.camera, config);
  const Camera map_camera = c.camera.subsampled(config.normal_stride);
  SurfaceSample sample;
  sampleSurface(ref.map, ref.intensity, config.verify_sample_step, &sample);
  AlignmentTarget target;
  buildAlignmentTarget(cur.map, cur.intensity, &target);
  DepthAligner aligner;
  aligner.reserve(sample.size());
  AlignmentParams params = alignmentParams(config);
  AlignmentResult a = aligner.align(sample, target, map_camera,
                                    seq.groundTruth(0).inverse() * seq.groundTruth(2), params);
  // Depth's weakest direction declared weak, and the grey values counted as fixing it.
  params.min_eigenvalue = float(a.depth_eigenvalues[0] * 1.01);
  a.depth_constrained = 5;
  a.constrained = 6;
  Eigen::Matrix<double, 6, 1> axis = Eigen::Matrix<double, 6, 1>::Zero();
  allocations = 0;
  counting = true;
  aligner.greyFixedDirectionUntold(sample, target, map_camera, a, params, &axis);
  counting = false;
  EXPECT_EQ(allocations.load(), 0);
  EXPECT_NEAR(axis.norm(), 1.0, 1e-9);  // it chose a direction and moved the pose along it
}

}  // namespace
}  // namespace nidevo
