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

// The alignment's inputs from frames 0 and `last` of a rendered sequence at 320x240, with an
// aligner reserved for them.
struct AlignmentPair {
  explicit AlignmentPair(int last) : seq(sequenceConfig(last + 1)) {
    const test::MapFrame ref = test::mapOf(seq.renderFrame(0), camera(), config);
    const test::MapFrame cur = test::mapOf(seq.renderFrame(last), camera(), config);
    sampleSurface(ref.map, ref.intensity, config.verify_sample_step, &sample);
    buildAlignmentTarget(cur.map, cur.intensity, &target);
    aligner.reserve(sample.size());
  }
  static synth::SequenceConfig sequenceConfig(int frames) {
    synth::SequenceConfig c;
    c.frames = frames;
    c.camera = cameraPreset("icl")->subsampled(2);
    return c;
  }
  const Camera& camera() const { return seq.config().camera; }
  Camera mapCamera() const { return camera().subsampled(config.normal_stride); }
  const synth::SyntheticSequence seq;
  const OdometryConfig config;
  SurfaceSample sample;
  AlignmentTarget target;
  DepthAligner aligner;
};

// The pose check's coarse-to-fine hypothesis, run only when every other one failed, so rarely
// that the tracking loop above may never reach it: its pyramid and alignments on their own.
TEST(Allocation, CoarseToFineAlignmentAllocatesNothingOnceReserved) {
  AlignmentPair pair(9);
  const Camera map_camera = pair.mapCamera();
  AlignmentPyramid pyramid;
  pyramid.reserve(pair.config.align_coarse_levels, map_camera);
  const AlignmentParams params = alignmentParams(pair.config);
  allocations = 0;
  counting = true;
  pyramid.build(pair.target);
  const AlignmentResult a = pair.aligner.alignCoarseToFine(
      pair.sample, pair.target, pair.mapCamera(), pyramid, Eigen::Isometry3d::Identity(), params);
  counting = false;
  EXPECT_EQ(allocations.load(), 0);
  EXPECT_GT(a.steps, 0);  // it aligned
}

// The check of the direction the grey values fix least where depth leaves it weak, with the pose
// moved either way and fitted again (--verify_grey_fixed_told).
TEST(Allocation, GreyFixedDirectionCheckAllocatesNothing) {
  AlignmentPair pair(2);
  const Camera map_camera = pair.mapCamera();
  AlignmentParams params = alignmentParams(pair.config);
  AlignmentResult a =
      pair.aligner.align(pair.sample, pair.target, map_camera,
                         pair.seq.groundTruth(0).inverse() * pair.seq.groundTruth(2), params);
  // Depth's weakest direction declared weak, and the grey values counted as fixing it.
  params.min_eigenvalue = float(a.depth_eigenvalues[0] * 1.01);
  a.depth_constrained = 5;
  a.constrained = 6;
  Eigen::Matrix<double, 6, 1> axis = Eigen::Matrix<double, 6, 1>::Zero();
  allocations = 0;
  counting = true;
  pair.aligner.greyFixedDirectionUntold(pair.sample, pair.target, map_camera, a, params, &axis);
  counting = false;
  EXPECT_EQ(allocations.load(), 0);
  EXPECT_NEAR(axis.norm(), 1.0, 1e-9);  // it chose a direction and moved the pose along it
}

// A fallback hypothesis joining an earlier result (--align_join): the result is copied, not built.
TEST(Allocation, AlignmentJoiningAnEarlierResultAllocatesNothing) {
  AlignmentPair pair(2);
  const Camera map_camera = pair.mapCamera();
  AlignmentParams params = alignmentParams(pair.config);
  params.join_m = 1e-3f;
  const Eigen::Isometry3d truth = pair.seq.groundTruth(0).inverse() * pair.seq.groundTruth(2);
  const AlignmentResult first = pair.aligner.align(pair.sample, pair.target, map_camera,
                                                   Eigen::Isometry3d::Identity(), params);
  const AlignmentResult* earlier[] = {&first};
  allocations = 0;
  counting = true;
  const AlignmentResult joined =
      pair.aligner.align(pair.sample, pair.target, map_camera, truth, params, earlier, 1);
  counting = false;
  EXPECT_EQ(allocations.load(), 0);
  EXPECT_EQ(joined.joined, 0);  // it joined
}

// The one-plane turn from the grey values (one_plane_image_yaw): its histograms and smoothing
// buffers keep their sizes once the estimator has seen a frame.
TEST(Allocation, PlaneYawAllocatesNothingAfterTheFirstFrame) {
  const AlignmentPair pair(3);
  const test::MapFrame key = test::mapOf(pair.seq.renderFrame(0), pair.camera(), pair.config);
  const test::MapFrame cur = test::mapOf(pair.seq.renderFrame(3), pair.camera(), pair.config);
  const PlaneView key_view{&key.map, key.intensity.data(), Eigen::Vector3f::UnitZ(),
                           Eigen::Matrix3f::Identity()};
  const PlaneView cur_view{&cur.map, cur.intensity.data(), Eigen::Vector3f::UnitZ(),
                           Eigen::Matrix3f::Identity()};
  const PlaneYawParams params = planeYawParams(pair.config);
  PlaneYawEstimator estimator;
  estimator.estimate(key_view, cur_view, pair.mapCamera(), params);
  allocations = 0;
  counting = true;
  for (int k = 0; k < 10; ++k) estimator.estimate(key_view, cur_view, pair.mapCamera(), params);
  counting = false;
  EXPECT_EQ(allocations.load(), 0);
}

}  // namespace
}  // namespace nidevo
