#include "nidevo/odometry/depth_alignment.hpp"

#include <gtest/gtest.h>

#include <cstdio>
#include <limits>
#include <random>

#include "map_frame.hpp"
#include "nidevo/odometry/odometry_config.hpp"
#include "nidevo/odometry/pose_check.hpp"
#include "nidevo/sim/sequence.hpp"
#include "painted_wall.hpp"

namespace nidevo {
namespace {

using Eigen::Isometry3d;
using test::MapFrame;
using test::mapOf;
using test::paintedWall;

Isometry3d motion(double angle, const Eigen::Vector3d& axis, const Eigen::Vector3d& t) {
  Isometry3d T = Isometry3d::Identity();
  T.linear() = Eigen::AngleAxisd(angle, axis.normalized()).toRotationMatrix();
  T.translation() = t;
  return T;
}

double angleDeg(const Isometry3d& T) {
  return Eigen::AngleAxisd(T.rotation()).angle() * 180.0 / M_PI;
}

class DepthAlignmentTest : public ::testing::Test {
 protected:
  void SetUp() override {
    synth::SequenceConfig sc;
    sc.frames = 1;
    seq_ = std::make_unique<synth::SyntheticSequence>(sc);
    camera_ = seq_->config().camera;
    T0_ = seq_->groundTruth(0);
    ref_ = mapOf(seq_->renderAt(T0_, 0.0, 0).frame, camera_, config_);
    sampleSurface(ref_.map, ref_.intensity, config_.verify_sample_step, &sample_);
  }
  AlignmentResult alignTo(const Isometry3d& T_ref_cur, const Isometry3d& hypothesis,
                          int iterations) {
    const MapFrame cur = mapOf(seq_->renderAt(T0_ * T_ref_cur, 0.033, 1).frame, camera_, config_);
    AlignmentParams p = alignmentParams(config_);
    p.iterations = iterations;
    return aligner_.align(sample_, cur.map, cur.intensity,
                          camera_.subsampled(config_.normal_stride), hypothesis, p);
  }
  // The current frame rendered at `truth` as the alignment reads it, with the config's params.
  struct Target {
    AlignmentTarget target;
    AlignmentParams params;
    Camera map_camera;
  };
  Target targetAt(const Isometry3d& truth) {
    Target w;
    const MapFrame cur = mapOf(seq_->renderAt(T0_ * truth, 0.033, 1).frame, camera_, config_);
    buildAlignmentTarget(cur.map, cur.intensity, &w.target);
    w.params = alignmentParams(config_);
    w.map_camera = camera_.subsampled(config_.normal_stride);
    return w;
  }
  // The same with a fallback joining an earlier result within 1 mm.
  Target joiningAt(const Isometry3d& truth) {
    Target w = targetAt(truth);
    w.params.join_m = 1e-3f;
    return w;
  }
  // The same with every direction declared too weak to update and any weak direction
  // confirmable.
  using AllWeak = Target;
  AllWeak allWeakAt(const Isometry3d& truth) {
    AllWeak w = targetAt(truth);
    w.params.min_eigenvalue = 1e3f;
    w.params.confirm_eigenvalue = 1e-6f;
    return w;
  }
  OdometryConfig config_;
  std::unique_ptr<synth::SyntheticSequence> seq_;
  Camera camera_;
  Isometry3d T0_;
  MapFrame ref_;
  SurfaceSample sample_;
  DepthAligner aligner_;
};

TEST_F(DepthAlignmentTest, SamplesOnlySmoothPixels) {
  ASSERT_GT(sample_.size(), 1000u);
  EXPECT_EQ(sample_.normal.size(), sample_.size());
  EXPECT_EQ(sample_.intensity.size(), sample_.size());
  for (size_t i = 0; i < sample_.size(); ++i) {
    EXPECT_GT(sample_.point[i].z(), 0.f);
    EXPECT_NEAR(sample_.normal[i].norm(), 1.f, 1e-4f);
  }
}

TEST_F(DepthAlignmentTest, TheTruePoseAgreesEverywhere) {
  const Isometry3d truth = motion(0.03, {0.2, 1, 0.1}, {0.03, -0.01, 0.02});
  const AlignmentResult a = alignTo(truth, truth, 0);
  EXPECT_GT(a.overlapFraction(), 0.8);
  EXPECT_GT(a.inlierFraction(), 0.95);
  EXPECT_LT(a.rms_m, 0.004);
  EXPECT_GT(a.ncc, 0.8);
}

TEST_F(DepthAlignmentTest, RefinementRecoversAKnownMotionFromTheIdentity) {
  const Isometry3d truth = motion(0.035, {0.3, 1, 0.2}, {0.04, -0.02, 0.03});
  const AlignmentResult a = alignTo(truth, Isometry3d::Identity(), 10);
  const Isometry3d err = truth.inverse() * a.T_ref_cur;
  EXPECT_EQ(a.constrained, 6);
  EXPECT_LT(angleDeg(err), 0.1);
  EXPECT_LT(err.translation().norm(), 0.003);
  EXPECT_GT(a.inlierFraction(), 0.95);
}

TEST_F(DepthAlignmentTest, ASmallStepEndsTheRefinementWhereRunningOnGainsNothing) {
  const Isometry3d truth = motion(0.035, {0.3, 1, 0.2}, {0.04, -0.02, 0.03});
  const AlignmentResult early = alignTo(truth, Isometry3d::Identity(), 10);
  config_.align_converged_m = 0;  // every step runs
  const AlignmentResult full = alignTo(truth, Isometry3d::Identity(), 10);
  EXPECT_LT(early.steps, full.steps);
  const Isometry3d apart = full.T_ref_cur.inverse() * early.T_ref_cur;
  EXPECT_LT(apart.translation().norm(), 2 * OdometryConfig{}.align_converged_m);
  EXPECT_LT(angleDeg(apart), 0.01);
}

// Two starts in one basin: the second refinement stops where it reaches the first one's pose,
// with that result, and in fewer steps than refined to its own end.
TEST_F(DepthAlignmentTest, ARefinementThatReachesAnEarlierResultEndsWithIt) {
  const Isometry3d truth = motion(0.035, {0.3, 1, 0.2}, {0.04, -0.02, 0.03});
  const Target at = joiningAt(truth);
  const AlignmentParams& p = at.params;
  const AlignmentResult first =
      aligner_.align(sample_, at.target, at.map_camera, Isometry3d::Identity(), p);
  ASSERT_EQ(first.joined, -1);
  ASSERT_LT((truth.inverse() * first.T_ref_cur).translation().norm(), 0.003);
  const AlignmentResult* earlier[] = {&first};
  const Isometry3d second_start = truth * motion(0.01, {1, 0, 0}, {0.02, 0.01, 0});
  const AlignmentResult alone = aligner_.align(sample_, at.target, at.map_camera, second_start, p);
  const AlignmentResult joined =
      aligner_.align(sample_, at.target, at.map_camera, second_start, p, earlier, 1);
  EXPECT_EQ(joined.joined, 0);
  EXPECT_TRUE(joined.T_ref_cur.isApprox(first.T_ref_cur, 0));
  EXPECT_EQ(joined.inliers, first.inliers);
  // A plain align after it joins nothing: it refines to its own end, as before.
  const AlignmentResult again = aligner_.align(sample_, at.target, at.map_camera, second_start, p);
  EXPECT_EQ(again.joined, -1);
  EXPECT_TRUE(again.T_ref_cur.isApprox(alone.T_ref_cur, 0));
  EXPECT_EQ(again.steps, alone.steps);
  // Refined alone it ends at the same minimum, within the join distance.
  const Isometry3d apart = alone.T_ref_cur.inverse() * first.T_ref_cur;
  EXPECT_LT(apart.translation().norm(), p.join_m);
  EXPECT_GT(alone.steps, 2);
}

// An earlier result elsewhere (here planted 5 cm off the minimum) is not joined: the refinement
// runs to its own end, as without it.
TEST_F(DepthAlignmentTest, ARefinementThatNeverReachesAnEarlierResultIsItsOwn) {
  const Isometry3d truth = motion(0.035, {0.3, 1, 0.2}, {0.04, -0.02, 0.03});
  const Target at = joiningAt(truth);
  const AlignmentParams& p = at.params;
  AlignmentResult elsewhere;
  elsewhere.T_ref_cur = truth * motion(0, {1, 0, 0}, {0.05, 0, 0});
  const AlignmentResult* earlier[] = {&elsewhere};
  const AlignmentResult alone =
      aligner_.align(sample_, at.target, at.map_camera, Isometry3d::Identity(), p);
  const AlignmentResult with =
      aligner_.align(sample_, at.target, at.map_camera, Isometry3d::Identity(), p, earlier, 1);
  EXPECT_EQ(with.joined, -1);
  EXPECT_TRUE(with.T_ref_cur.isApprox(alone.T_ref_cur, 0));
  EXPECT_EQ(with.steps, alone.steps);
  // And with joining off, even the earlier result's own pose is refined from.
  AlignmentParams off = p;
  off.join_m = 0;
  const AlignmentResult* same[] = {&alone};
  EXPECT_EQ(aligner_.align(sample_, at.target, at.map_camera, alone.T_ref_cur, off, same, 1).joined,
            -1);
}

TEST_F(DepthAlignmentTest, APlantedTenDegreeRotationErrorFailsTheCheck) {
  const Isometry3d truth = motion(0.02, {0, 1, 0}, {0.02, 0, 0.01});
  for (const Eigen::Vector3d& axis :
       {Eigen::Vector3d(0, 1, 0), Eigen::Vector3d(1, 0, 0), Eigen::Vector3d(0, 0, 1)}) {
    const Isometry3d wrong = truth * motion(10 * M_PI / 180, axis, Eigen::Vector3d::Zero());
    const AlignmentResult a = alignTo(truth, wrong, 0);
    EXPECT_LT(a.inlierFraction(), config_.verify_min_inliers) << axis.transpose();
  }
}

TEST_F(DepthAlignmentTest, DirectionsTheGeometryLeavesFreeKeepTheHypothesis) {
  // Only the largest plane in view (everything else cut away): motion along it is unobservable.
  MapFrame floor = ref_;
  Eigen::Vector3f down = Eigen::Vector3f::Zero();
  size_t most = 0;
  for (size_t c = 0; c < sample_.size(); c += sample_.size() / 50) {
    size_t n = 0;
    for (const auto& m : sample_.normal) n += m.dot(sample_.normal[c]) > 0.95f;
    if (n > most) most = n, down = sample_.normal[c];
  }
  for (size_t i = 0; i < floor.map.normal.size(); ++i)
    if (floor.map.valid[i] && std::abs(floor.map.normal[i].dot(down)) < 0.95f)
      floor.map.valid[i] = floor.map.smooth[i] = 0;
  SurfaceSample sample;
  sampleSurface(floor.map, floor.intensity, config_.verify_sample_step, &sample);
  ASSERT_GT(sample.size(), 100u);
  const Isometry3d hypothesis = motion(0, {0, 1, 0}, {0.05, 0, 0});
  AlignmentParams p = alignmentParams(config_);
  p.iterations = 5;
  p.photometric_weight = 0;  // geometry only: the texture would fix the in-plane motion
  const AlignmentResult a = aligner_.align(
      sample, floor.map, floor.intensity, camera_.subsampled(config_.normal_stride), hypothesis, p);
  EXPECT_LE(a.constrained, 3);
  // The in-plane part of the hypothesis survives; only the normal component may change.
  const Eigen::Vector3d moved = a.T_ref_cur.translation();
  const Eigen::Vector3d n = down.cast<double>();
  EXPECT_NEAR((moved - moved.dot(n) * n).norm(),
              (hypothesis.translation() - hypothesis.translation().dot(n) * n).norm(), 1e-3);
}

TEST_F(DepthAlignmentTest, APlantedTranslationIsSeenByTheGreyValuesAndUndone) {
  const Isometry3d truth = motion(0.0, {0, 1, 0}, {0.01, 0, 0.01});
  const AlignmentResult right = alignTo(truth, truth, 0);
  EXPECT_GT(right.ncc, 0.95);
  for (const Eigen::Vector3d& shift : {Eigen::Vector3d(0.04, 0, 0), Eigen::Vector3d(0, 0.04, 0)}) {
    const Isometry3d planted = truth * motion(0, {0, 1, 0}, shift);
    EXPECT_LT(alignTo(truth, planted, 0).ncc, right.ncc - 0.02) << shift.transpose();
    const AlignmentResult refined = alignTo(truth, planted, 10);
    EXPECT_LT((truth.inverse() * refined.T_ref_cur).translation().norm(), 0.005)
        << shift.transpose();
  }
}

// Tiled with a period of `period` metres in x and y.
RgbdFrame tiledWall(const Camera& cam, const RgbdFrame& like, const Eigen::Vector3d& t,
                    double period) {
  return paintedWall(cam, like, t, [period](double x, double y) {
    return 128 + 50 * std::cos(2 * M_PI * x / period) + 40 * std::cos(2 * M_PI * y / period);
  });
}

TEST_F(DepthAlignmentTest, APlantedOnePeriodTranslationErrorIsNotCalledOk) {
  const double period = 0.25;
  const Eigen::Vector3d t(0.02, 0.01, 0);
  const RgbdFrame like = seq_->renderFrame(0);
  const MapFrame ref =
      mapOf(tiledWall(camera_, like, Eigen::Vector3d::Zero(), period), camera_, config_);
  const MapFrame cur = mapOf(tiledWall(camera_, like, t, period), camera_, config_);
  SurfaceSample sample;
  sampleSurface(ref.map, ref.intensity, config_.verify_sample_step, &sample);
  const AlignmentParams p = alignmentParams(config_);
  const Camera map_camera = camera_.subsampled(config_.normal_stride);
  const Isometry3d truth = motion(0, {0, 1, 0}, t);
  const Isometry3d planted = motion(0, {0, 1, 0}, t + Eigen::Vector3d(period, 0, 0));
  const AlignmentResult right =
      aligner_.align(sample, cur.map, cur.intensity, map_camera, truth, p);
  const AlignmentResult wrong =
      aligner_.align(sample, cur.map, cur.intensity, map_camera, planted, p);
  // The wall fixes depth, tilt and pan only; the tiles fit as well one period away, so the
  // alignment alone cannot tell the two apart.
  EXPECT_LT(right.depth_constrained, 6);
  EXPECT_TRUE(judgeAlignment(right, config_).passed);
  EXPECT_TRUE(judgeAlignment(wrong, config_).passed);
  EXPECT_NEAR((truth.inverse() * wrong.T_ref_cur).translation().x(), period, 0.01);
  // Standing still was predicted: the true pose is near it, the planted one a period away.
  const HypothesisOrigin method{true, true, true};
  const Isometry3d still = Isometry3d::Identity();
  EXPECT_TRUE(directionsTrusted(right, still, method, config_));
  EXPECT_FALSE(directionsTrusted(wrong, still, method, config_));
  // Had depth fixed every direction, the jump would have been measured, not guessed.
  AlignmentResult measured = wrong;
  measured.depth_constrained = 6;
  EXPECT_TRUE(directionsTrusted(measured, still, method, config_));
}

// Depth off by a bowl that grows towards the image border (as a structured-light sensor's is):
// depth alone fixes all six directions, a little wrongly, and the grey values, unbiased, pull
// the pose back towards the truth. (Their weight keeps that pull small; the real clip and the
// stress suite measure what it is worth: docs/accuracy.md.)
TEST_F(DepthAlignmentTest, GreyValuesPolishAPoseThatBiasedDepthFixedAlone) {
  const Isometry3d truth = motion(0.02, {0.2, 1, 0}, {0.03, -0.01, 0.02});
  RgbdFrame frame = seq_->renderAt(T0_ * truth, 0.033, 1).frame;
  for (int v = 0; v < camera_.height; ++v) {
    for (int u = 0; u < camera_.width; ++u) {
      const double x = (u - camera_.cx) / camera_.fx, y = (v - camera_.cy) / camera_.fy;
      frame.depth.at(u, v) *= float(1 + 0.01 * (x * x + y * y));
    }
  }
  const MapFrame cur = mapOf(frame, camera_, config_);
  double error[2];
  for (int polish : {0, 1}) {
    AlignmentParams p = alignmentParams(config_);
    p.polish_iterations = polish ? config_.align_polish_iterations : 0;
    const AlignmentResult a = aligner_.align(sample_, cur.map, cur.intensity,
                                             camera_.subsampled(config_.normal_stride), truth, p);
    EXPECT_EQ(a.depth_constrained, 6);
    const Isometry3d err = truth.inverse() * a.T_ref_cur;
    error[polish] = err.translation().norm() + 0.5 * angleDeg(err) * M_PI / 180;
  }
  EXPECT_GT(error[0], 0.005);  // the bias is there
  EXPECT_LT(error[1], error[0] - 5e-5) << "depth alone " << error[0] << ", polished " << error[1];
}

// Every direction declared too weak to update: the data then only confirm or contradict the
// hypothesis along each, by the step they would take there.
TEST_F(DepthAlignmentTest, WeakDirectionsConfirmTheTruePoseAndNotAPlantedOffset) {
  const Isometry3d truth = motion(0.02, {0.2, 1, 0}, {0.03, -0.01, 0.02});
  const MapFrame cur = mapOf(seq_->renderAt(T0_ * truth, 0.033, 1).frame, camera_, config_);
  AlignmentParams p = alignmentParams(config_);
  p.min_eigenvalue = 1e3f;
  p.confirm_eigenvalue = 1e-6f;
  const Camera map_camera = camera_.subsampled(config_.normal_stride);
  const AlignmentResult right =
      aligner_.align(sample_, cur.map, cur.intensity, map_camera, truth, p);
  EXPECT_EQ(right.constrained, 0);
  EXPECT_EQ(right.confirmed, 6);
  EXPECT_EQ(right.weak_count, 6);
  EXPECT_TRUE((right.weak_axes.transpose() * right.weak_axes).isIdentity(1e-9))
      << "the weak axes are the eigenvectors, orthonormal";
  for (const Eigen::Vector3d& offset :
       {Eigen::Vector3d(0.03, 0, 0), Eigen::Vector3d(0, 0, 0.03), Eigen::Vector3d(0, 0.02, 0)}) {
    const Isometry3d planted = truth * motion(0, {0, 1, 0}, offset);
    const AlignmentResult a =
        aligner_.align(sample_, cur.map, cur.intensity, map_camera, planted, p);
    EXPECT_LT(a.confirmed, 6) << offset.transpose();
    EXPECT_TRUE(a.T_ref_cur.isApprox(planted)) << "nothing may move along a weak direction";
  }
  p.confirm_eigenvalue = 0;  // off
  EXPECT_EQ(aligner_.align(sample_, cur.map, cur.intensity, map_camera, truth, p).confirmed, 0);
}

// Every direction weak again: at the true pose the grey values fit worse 5 cm away along each,
// either way; at a pose planted 8 cm off along x (beyond their reach, where a would-be step can
// come out small) they fit one side at least as well, so that direction is untold.
TEST_F(DepthAlignmentTest, GreyValuesTellTheTruePoseFromOneMovedAlongEachWeakDirection) {
  const Isometry3d truth = motion(0.02, {0.2, 1, 0}, {0.03, -0.01, 0.02});
  const AllWeak w = allWeakAt(truth);
  const AlignmentTarget& target = w.target;
  const AlignmentParams& p = w.params;
  const Camera& map_camera = w.map_camera;
  ASSERT_EQ(p.confirm_shift_m, 0.05f);
  const AlignmentResult right = aligner_.align(sample_, target, map_camera, truth, p);
  ASSERT_EQ(right.weak_count, 6);
  const DepthAligner::Untold at_truth =
      aligner_.untoldWeakDirections(sample_, target, map_camera, right, p);
  EXPECT_EQ(at_truth.directions, 0);
  EXPECT_EQ(at_truth.confirmed, 0);
  const Isometry3d planted = truth * motion(0, {0, 1, 0}, {0.08, 0, 0});
  const AlignmentResult wrong = aligner_.align(sample_, target, map_camera, planted, p);
  const DepthAligner::Untold off =
      aligner_.untoldWeakDirections(sample_, target, map_camera, wrong, p);
  EXPECT_GE(off.directions, 1);
  EXPECT_LE(off.confirmed, off.directions);
  EXPECT_TRUE(wrong.T_ref_cur.isApprox(planted)) << "the test moves no pose";
}

// The same planted offsets, every direction weak: the further pass steps along them and finds the
// true pose, yet leaves them unconfirmed, since it moved the pose; asked not to, it moves nothing.
TEST_F(DepthAlignmentTest, RefiningAlongWeakDirectionsUndoesAPlantedOffsetButConfirmsNothing) {
  const Isometry3d truth = motion(0.02, {0.2, 1, 0}, {0.03, -0.01, 0.02});
  AllWeak w = allWeakAt(truth);
  const AlignmentTarget& target = w.target;
  AlignmentParams& p = w.params;
  const Camera& map_camera = w.map_camera;
  for (const Eigen::Vector3d& offset : {Eigen::Vector3d(0.03, 0, 0), Eigen::Vector3d(0, 0.02, 0)}) {
    const Isometry3d planted = truth * motion(0, {0, 1, 0}, offset);
    const AlignmentResult held = aligner_.align(sample_, target, map_camera, planted, p);
    ASSERT_TRUE(held.T_ref_cur.isApprox(planted));
    p.step_eigenvalue = 0;
    EXPECT_TRUE(aligner_.refineAlongWeakDirections(sample_, target, map_camera, held, p)
                    .T_ref_cur.isApprox(planted))
        << "off: " << offset.transpose();
    p.step_eigenvalue = 1e-6f;
    const AlignmentResult refined =
        aligner_.refineAlongWeakDirections(sample_, target, map_camera, held, p);
    const Isometry3d error = truth.inverse() * refined.T_ref_cur;
    EXPECT_LT(error.translation().norm(), 0.005) << offset.transpose();
    EXPECT_LT(angleDeg(error), 0.2) << offset.transpose();
    EXPECT_GT(refined.ncc, held.ncc);
    EXPECT_EQ(refined.constrained, 0);
    EXPECT_LT(refined.confirmed, 6) << offset.transpose();
  }
}

// A pose the check already passes with every direction fixed is left as it is.
TEST_F(DepthAlignmentTest, RefiningAlongWeakDirectionsLeavesAFullyConstrainedPose) {
  const Isometry3d truth = motion(0.02, {0.2, 1, 0}, {0.03, -0.01, 0.02});
  const MapFrame cur = mapOf(seq_->renderAt(T0_ * truth, 0.033, 1).frame, camera_, config_);
  AlignmentTarget target;
  buildAlignmentTarget(cur.map, cur.intensity, &target);
  const AlignmentParams p = alignmentParams(config_);
  ASSERT_GT(p.step_eigenvalue, 0.f);
  const Camera map_camera = camera_.subsampled(config_.normal_stride);
  const AlignmentResult a = aligner_.align(sample_, target, map_camera, truth, p);
  ASSERT_EQ(a.constrained, 6);
  EXPECT_TRUE(aligner_.refineAlongWeakDirections(sample_, target, map_camera, a, p)
                  .T_ref_cur.isApprox(a.T_ref_cur));
}

// The current frame's grey values seen from a camera turned by 0, 0.5 and 1 deg from the one its
// depth was seen from (colour and depth taken apart in time): the gap between the rotations
// depth alone and grey values alone fit best is that turn.
TEST_F(DepthAlignmentTest, GreyDepthGapMeasuresGreyValuesSeenFromATurnedCamera) {
  const Isometry3d truth = motion(0.02, {0.3, 1, 0.2}, {0.02, -0.01, 0.01});
  const Eigen::Vector3d axis = Eigen::Vector3d(0.2, 1, 0.3).normalized();
  const Camera map_camera = camera_.subsampled(config_.normal_stride);
  for (double turn_deg : {0.0, 0.5, 1.0}) {
    SCOPED_TRACE("grey values turned by " + std::to_string(turn_deg) + " deg");
    const Isometry3d T_depth = T0_ * truth;
    const Isometry3d T_grey =
        T_depth * motion(turn_deg * M_PI / 180, axis, Eigen::Vector3d::Zero());
    const MapFrame depth = mapOf(seq_->renderAt(T_depth, 0.033, 1).frame, camera_, config_);
    const MapFrame grey = mapOf(seq_->renderAt(T_grey, 0.033, 1).frame, camera_, config_);
    // Measured to its end: a bound whose quarter every turn here exceeds.
    AlignmentParams full = alignmentParams(config_);
    full.grey_depth_gap_rad = float(0.1 * M_PI / 180);
    const AlignmentResult a =
        aligner_.align(sample_, depth.map, grey.intensity, map_camera, truth, full);
    ASSERT_EQ(a.depth_constrained, 6);
    EXPECT_NEAR(a.grey_depth_gap_rad * 180 / M_PI, turn_deg, 0.15);
    // With the default bound (1 deg) the first step may end it: the same side of the bound.
    const AlignmentResult quick = aligner_.align(sample_, depth.map, grey.intensity, map_camera,
                                                 truth, alignmentParams(config_));
    const float bound = config_.verify_max_grey_depth_gap_rad;
    EXPECT_EQ(quick.grey_depth_gap_rad > bound, a.grey_depth_gap_rad > bound);
    // Not measured when the rule is off.
    full.grey_depth_gap_rad = 0;
    EXPECT_EQ(aligner_.align(sample_, depth.map, grey.intensity, map_camera, truth, full)
                  .grey_depth_gap_rad,
              0.0);
  }
}

// The spread the check reports (sigma^2 H^-1) against the spread of its estimates over draws of
// depth noise: the same within a factor of 1.5 (24 draws measure it to about 10 %), and twice the
// noise gives about twice the spread.
TEST_F(DepthAlignmentTest, ReportedSpreadMatchesTheEstimatesSpreadOverNoiseDraws) {
  const Isometry3d truth = motion(0.02, {0.3, 1, 0.2}, {0.02, -0.01, 0.015});
  const RgbdFrame clean = seq_->renderAt(T0_ * truth, 0.033, 1).frame;
  AlignmentParams p = alignmentParams(config_);
  p.photometric_weight = 0;  // depth alone: its noise is the one drawn
  const Camera map_camera = camera_.subsampled(config_.normal_stride);
  struct Spread {
    double reported_rad = 0, reported_m = 0, measured_rad = 0, measured_m = 0;
  };
  auto spreadAt = [&](double noise_m) {
    std::mt19937 rng(7);
    std::normal_distribution<float> gauss(0.f, float(noise_m));
    constexpr int kDraws = 24;
    Spread s;
    for (int k = 0; k < kDraws; ++k) {
      RgbdFrame noisy = clean;
      for (float& z : noisy.depth.data)
        if (z > 0) z += gauss(rng);
      const MapFrame cur = mapOf(noisy, camera_, config_);
      const AlignmentResult a =
          aligner_.align(sample_, cur.map, cur.intensity, map_camera, truth, p);
      EXPECT_EQ(a.constrained, 6);
      const Isometry3d err = truth.inverse() * a.T_ref_cur;
      s.reported_rad += a.sigma_rotation_rad / kDraws;
      s.reported_m += a.sigma_translation_m / kDraws;
      s.measured_rad += Eigen::AngleAxisd(err.rotation()).angle() *
                        Eigen::AngleAxisd(err.rotation()).angle() / kDraws;
      s.measured_m += err.translation().squaredNorm() / kDraws;
    }
    s.measured_rad = std::sqrt(s.measured_rad);
    s.measured_m = std::sqrt(s.measured_m);
    return s;
  };
  const Spread low = spreadAt(0.005), high = spreadAt(0.01);
  for (const Spread& s : {low, high}) {
    EXPECT_GT(s.reported_rad, s.measured_rad / 1.5);
    EXPECT_LT(s.reported_rad, 1.5 * s.measured_rad);
    EXPECT_GT(s.reported_m, s.measured_m / 1.5);
    EXPECT_LT(s.reported_m, 1.5 * s.measured_m);
  }
  EXPECT_NEAR(high.reported_rad / low.reported_rad, 2.0, 0.5);
  EXPECT_NEAR(high.reported_m / low.reported_m, 2.0, 0.5);
  std::printf(
      "spread at 5 and 10 mm: reported %.4f %.4f deg, %.5f %.5f m; measured %.4f %.4f deg, "
      "%.5f %.5f m\n",
      low.reported_rad * 180 / M_PI, high.reported_rad * 180 / M_PI, low.reported_m,
      high.reported_m, low.measured_rad * 180 / M_PI, high.measured_rad * 180 / M_PI,
      low.measured_m, high.measured_m);
}

// Normals turned by a known Gaussian noise (sigma per tangent component) in both the reference's
// sample and the current frame: the estimate is sigma^2 over the rendered normals' own mismatch.
TEST_F(DepthAlignmentTest, NormalNoiseEstimateRecoversAPlantedNoise) {
  const Isometry3d truth = motion(0.01, {0, 1, 0}, {0.01, 0, 0});
  const MapFrame cur = mapOf(seq_->renderAt(T0_ * truth, 0.033, 1).frame, camera_, config_);
  const Camera map_camera = camera_.subsampled(config_.normal_stride);
  AlignmentParams p = alignmentParams(config_);
  p.iterations = 0;  // judged at the true pose as it is
  auto noiseAt = [&](double sigma) {
    std::mt19937 rng(7);
    std::normal_distribution<float> gauss(0.f, float(sigma));
    auto turned = [&](const Eigen::Vector3f& n) {
      const Eigen::Vector3f t1 = n.unitOrthogonal(), t2 = n.cross(t1);
      const float a = gauss(rng), b = gauss(rng);
      Eigen::Vector3f m = n;
      m += a * t1;
      m += b * t2;
      return m.normalized();
    };
    SurfaceSample ref = sample_;
    for (auto& n : ref.normal) n = turned(n);
    AlignmentTarget target;
    buildAlignmentTarget(cur.map, cur.intensity, &target);
    for (size_t j = 0; j < target.plane.size(); ++j) {
      if (std::isnan(target.plane[j].w())) continue;
      const Eigen::Vector3f n = turned(target.plane[j].head<3>());
      target.plane[j] = Eigen::Vector4f(n.x(), n.y(), n.z(), n.dot(cur.map.points[j]));
    }
    return aligner_.align(ref, target, map_camera, truth, p);
  };
  const AlignmentResult clean = noiseAt(0.0);
  ASSERT_GT(clean.inliers, 1000);
  EXPECT_LT(clean.normal_noise_var, 1e-4) << "the rendered normals agree to well under a degree";
  for (const double sigma_deg : {1.0, 2.0, 4.0}) {
    const double sigma = sigma_deg * M_PI / 180.0;
    const AlignmentResult noisy = noiseAt(sigma);
    EXPECT_NEAR(noisy.normal_noise_var - clean.normal_noise_var, sigma * sigma, 0.1 * sigma * sigma)
        << sigma_deg << " deg";
  }
}

// The depth system's eigenvalues come ascending, and the directions depth fixed are those of them
// that reach the bound.
TEST_F(DepthAlignmentTest, DepthEigenvaluesAreReportedAscendingAndCountTheFixedDirections) {
  const AlignmentResult a = alignTo(motion(0.02, {1, 1, 0}, {0.02, 0, 0.01}),
                                    Isometry3d::Identity(), config_.align_iterations);
  ASSERT_GT(a.steps, 0);
  for (int k = 1; k < 6; ++k) EXPECT_LE(a.depth_eigenvalues[k - 1], a.depth_eigenvalues[k]);
  EXPECT_GT(a.depth_eigenvalues[5], 0.0);
  EXPECT_EQ(a.depth_constrained,
            int((a.depth_eigenvalues.array() >= double(config_.align_min_eigenvalue)).count()));
  // The last step solved depth and grey values together: adding the grey rows' positive
  // semidefinite system lifts every ordered eigenvalue (Weyl), and those reaching the bound are
  // the directions fixed.
  ASSERT_GT(config_.align_photometric_weight, 0.f);
  for (int k = 0; k < 6; ++k) EXPECT_GE(a.eigenvalues[k], a.depth_eigenvalues[k] * (1 - 1e-9));
  for (int k = 1; k < 6; ++k) EXPECT_LE(a.eigenvalues[k - 1], a.eigenvalues[k]);
  EXPECT_EQ(a.constrained,
            int((a.eigenvalues.array() >= double(config_.align_min_eigenvalue)).count()));
}

// A wall fixes depth, tilt and pan; bold stripes across y fix y and the roll; fine faint ones
// across x fix x least. Where their period is the 5 cm the check moves the pose by, the grey
// values fit the pose moved along x as well as the true one: untold. At 8 cm they tell it.
TEST_F(DepthAlignmentTest, GreyValuesRepeatingEveryShiftLeaveTheDirectionTheyFixLeastUntold) {
  const RgbdFrame like = seq_->renderFrame(0);
  const Camera map_camera = camera_.subsampled(config_.normal_stride);
  const Eigen::Vector3d t(0.01, 0.005, 0);
  const Isometry3d truth = motion(0, {0, 1, 0}, t);
  const AlignmentParams p = alignmentParams(config_);
  ASSERT_EQ(p.confirm_shift_m, 0.05f);
  auto untoldWithPeriod = [&](double x_period, Eigen::Matrix<double, 6, 1>* axis) {
    const auto paint = test::boldAndFaintStripes(x_period);
    const MapFrame ref =
        mapOf(paintedWall(camera_, like, Eigen::Vector3d::Zero(), paint), camera_, config_);
    const MapFrame cur = mapOf(paintedWall(camera_, like, t, paint), camera_, config_);
    SurfaceSample sample;
    sampleSurface(ref.map, ref.intensity, config_.verify_sample_step, &sample);
    AlignmentTarget target;
    buildAlignmentTarget(cur.map, cur.intensity, &target);
    const AlignmentResult a = aligner_.align(sample, target, map_camera, truth, p);
    EXPECT_EQ(a.depth_constrained, 3) << "the wall fixes depth, tilt and pan";
    EXPECT_EQ(a.constrained, 6) << "the grey values fix the rest";
    EXPECT_LT((truth.inverse() * a.T_ref_cur).translation().norm(), 0.002);
    return aligner_.greyFixedDirectionUntold(sample, target, map_camera, a, p, axis);
  };
  Eigen::Matrix<double, 6, 1> axis;
  EXPECT_TRUE(untoldWithPeriod(0.05, &axis));
  EXPECT_GT(std::abs(axis[3]), 0.9) << "along x: " << axis.transpose();
  EXPECT_FALSE(untoldWithPeriod(0.08, &axis));
  EXPECT_GT(std::abs(axis[3]), 0.9) << "along x: " << axis.transpose();
}

TEST(AlignmentTargetTest, HoldsEachPixelsPlaneAndGreyValue) {
  NormalMap map;
  map.resize(5, 4);
  std::vector<float> intensity(20);
  for (int j = 0; j < 20; ++j) {
    map.normal[size_t(j)] = Eigen::Vector3f(0.f, 0.6f, -0.8f);
    map.points[size_t(j)] = Eigen::Vector3f(0.1f * float(j), 0.2f, 1.5f);
    map.valid[size_t(j)] = j != 7;
    intensity[size_t(j)] = float(j * j) / 400.f;  // a different slope everywhere
  }
  AlignmentTarget t;
  buildAlignmentTarget(map, intensity, &t);
  ASSERT_EQ(t.width, 5);
  ASSERT_EQ(t.height, 4);
  EXPECT_TRUE(std::isnan(t.plane[7].w())) << "no surface where the map has no normal";
  EXPECT_FLOAT_EQ(t.plane[8].w(), 0.6f * 0.2f - 0.8f * 1.5f);  // n . q
  EXPECT_FLOAT_EQ(t.plane[8].x(), 0.f);
  EXPECT_FLOAT_EQ(t.plane[8].z(), -0.8f);
  EXPECT_EQ(t.grey, intensity);
}

TEST_F(DepthAlignmentTest, OneTargetServesEveryHypothesisAlike) {
  const Isometry3d truth = motion(0.03, {0.3, 1, 0.2}, {0.03, -0.02, 0.02});
  const MapFrame cur = mapOf(seq_->renderAt(T0_ * truth, 0.033, 1).frame, camera_, config_);
  const AlignmentParams p = alignmentParams(config_);
  const Camera map_camera = camera_.subsampled(config_.normal_stride);
  AlignmentTarget target;
  buildAlignmentTarget(cur.map, cur.intensity, &target);
  for (const Isometry3d& start : {Isometry3d::Identity(), truth}) {
    const AlignmentResult shared = aligner_.align(sample_, target, map_camera, start, p);
    const AlignmentResult own =
        aligner_.align(sample_, cur.map, cur.intensity, map_camera, start, p);
    EXPECT_TRUE(shared.T_ref_cur.isApprox(own.T_ref_cur, 1e-12));
    EXPECT_EQ(shared.inliers, own.inliers);
    EXPECT_EQ(shared.steps, own.steps);
    const Isometry3d err = truth.inverse() * shared.T_ref_cur;
    EXPECT_LT(angleDeg(err), 0.1);
    EXPECT_LT(err.translation().norm(), 0.003);
  }
}

// Through TUM fr1's lens (strong at the corners): the warp distorts every point, four at a time
// and one by one for the sample's remainder, and must land each on its own pixel.
TEST(DepthAlignmentLensTest, RefinementThroughALensRecoversAKnownMotion) {
  synth::SequenceConfig sc;
  sc.frames = 1;
  sc.camera.distortion = Distortion{0.2624, -0.9531, -0.0054, 0.0026, 1.1633};
  const synth::SyntheticSequence seq(sc);
  const OdometryConfig config;
  const Camera camera = seq.config().camera;
  const Isometry3d T0 = seq.groundTruth(0);
  const Isometry3d truth = motion(0.03, {0.3, 1, 0.2}, {0.03, -0.02, 0.02});
  const MapFrame ref = mapOf(seq.renderAt(T0, 0.0, 0).frame, camera, config);
  const MapFrame cur = mapOf(seq.renderAt(T0 * truth, 0.033, 1).frame, camera, config);
  SurfaceSample sample;
  sampleSurface(ref.map, ref.intensity, config.verify_sample_step, &sample);
  while (sample.size() % 4 != 3) {  // a remainder for the one-by-one path
    sample.point.pop_back();
    sample.normal.pop_back();
    sample.intensity.pop_back();
  }
  DepthAligner aligner;
  const AlignmentParams p = alignmentParams(config);
  Camera pinhole = camera.subsampled(config.normal_stride);
  pinhole.distortion = Distortion{};
  const AlignmentResult lens = aligner.align(sample, cur.map, cur.intensity,
                                             camera.subsampled(config.normal_stride), truth, p);
  const AlignmentResult no_lens = aligner.align(sample, cur.map, cur.intensity, pinhole, truth, p);
  const Isometry3d err = truth.inverse() * lens.T_ref_cur;
  EXPECT_LT(angleDeg(err), 0.1);
  EXPECT_LT(err.translation().norm(), 0.003);
  EXPECT_GT(lens.inlierFraction(), 0.95);
  EXPECT_LT(lens.rms_m, no_lens.rms_m) << "ignoring the lens must fit worse";
}

TEST(AlignmentTargetTest, HalvedTargetKeepsABlocksPlaneAndSmoothsTheGreyValues) {
  AlignmentTarget fine;
  fine.width = 6;
  fine.height = 4;
  const float nan = std::numeric_limits<float>::quiet_NaN();
  for (int j = 0; j < 24; ++j) {
    fine.plane.emplace_back(0.f, 0.f, -1.f, -float(j));  // each pixel's own plane
    fine.grey.push_back(float(j % 6) * 0.1f + float(j / 6) * 0.01f);
  }
  fine.plane[2] = Eigen::Vector4f::Constant(nan);  // block (1, 0): top-left has no surface
  for (const size_t j : {4, 5, 10, 11}) fine.plane[j] = Eigen::Vector4f::Constant(nan);
  AlignmentTarget half;
  halveAlignmentTarget(fine, &half);
  ASSERT_EQ(half.width, 3);
  ASSERT_EQ(half.height, 2);
  EXPECT_FLOAT_EQ(half.plane[0].w(), 0.f) << "the top-left pixel's plane";
  EXPECT_FLOAT_EQ(half.plane[1].w(), -3.f) << "the block's first valid plane";
  EXPECT_TRUE(std::isnan(half.plane[2].w())) << "a block without surface has none";
  EXPECT_FLOAT_EQ(half.plane[3].w(), -12.f);
  // Inside, [1 2 1] x [1 2 1] of a linear ramp is the ramp at the centre pixel (2u, 2v).
  EXPECT_NEAR(half.grey[4], fine.grey[2 * 6 + 2], 1e-6f);
  // At the border the ramp's missing side is the border pixel itself.
  EXPECT_NEAR(half.grey[0],
              (9 * fine.grey[0] + 3 * fine.grey[1] + 3 * fine.grey[6] + fine.grey[7]) / 16.f,
              1e-6f);
}

// A wall 2 m ahead tiled at two scales, 6 cm and 60 cm: from standing still, a sideways move of
// more than half the fine period lands a one-level alignment on the fine tiles' next period,
// where everything agrees; aligning the prediction coarse to fine first follows the broad tiles.
TEST_F(DepthAlignmentTest, CoarseToFineReachesAMoveThatOneLevelTakesForTheNextPeriod) {
  const RgbdFrame like = seq_->renderFrame(0);
  auto wall = [&](double shift) {
    RgbdFrame f = like;
    std::fill(f.depth.data.begin(), f.depth.data.end(), 2.f);
    for (int v = 0; v < camera_.height; ++v) {
      for (int u = 0; u < camera_.width; ++u) {
        const double x = (u - camera_.cx) / camera_.fx * 2 + shift;
        const double y = (v - camera_.cy) / camera_.fy * 2;
        f.gray.at(u, v) =
            uint8_t(128 + 25 * (std::cos(2 * M_PI * x / 0.06) + std::cos(2 * M_PI * y / 0.06)) +
                    30 * (std::cos(2 * M_PI * x / 0.6) + std::cos(2 * M_PI * y / 0.6)));
      }
    }
    return f;
  };
  const MapFrame ref = mapOf(wall(0), camera_, config_);
  SurfaceSample sample;
  sampleSurface(ref.map, ref.intensity, config_.verify_sample_step, &sample);
  const AlignmentParams p = alignmentParams(config_);
  const Camera map_camera = camera_.subsampled(config_.normal_stride);
  AlignmentPyramid pyramid;
  pyramid.reserve(config_.align_coarse_levels, map_camera);
  ASSERT_EQ(config_.align_coarse_levels, 2);
  for (const double shift : {0.04, 0.08, 0.12}) {
    const MapFrame cur = mapOf(wall(shift), camera_, config_);
    AlignmentTarget target;
    buildAlignmentTarget(cur.map, cur.intensity, &target);
    pyramid.build(target);
    const Isometry3d truth = motion(0, {0, 1, 0}, {shift, 0, 0});
    const AlignmentResult one =
        aligner_.align(sample, target, map_camera, Isometry3d::Identity(), p);
    const AlignmentResult both =
        aligner_.alignCoarseToFine(sample, target, map_camera, pyramid, Isometry3d::Identity(), p);
    EXPECT_GT((truth.inverse() * one.T_ref_cur).translation().norm(), 0.04) << shift;
    EXPECT_LT((truth.inverse() * both.T_ref_cur).translation().norm(), 0.001) << shift;
    EXPECT_LT(angleDeg(truth.inverse() * both.T_ref_cur), 0.05) << shift;
    EXPECT_TRUE(judgeAlignment(both, config_).passed) << shift;
  }
}

// A fast turn, 12 and 14 deg between the frames, from standing still: with the fine gate (8 cm)
// on every level the start keeps too few points to reach it (6-8 deg off, failing the check);
// with the gate growing with the coarse levels' pixels, coarse to fine lands on it.
TEST_F(DepthAlignmentTest, CoarseToFineWithAGrowingGateReachesAFastTurn) {
  const Camera map_camera = camera_.subsampled(config_.normal_stride);
  AlignmentPyramid pyramid;
  pyramid.reserve(config_.align_coarse_levels, map_camera);
  const AlignmentParams growing = alignmentParams(config_);
  ASSERT_EQ(growing.coarse_gate_growth, 2.f);
  AlignmentParams fixed_gate = growing;
  fixed_gate.coarse_gate_growth = 1;
  for (const double angle_deg : {12.0, 14.0}) {
    const Isometry3d truth = motion(angle_deg * M_PI / 180, {0.2, 1, 0.1}, {0.02, 0.01, 0.01});
    const MapFrame cur = mapOf(seq_->renderAt(T0_ * truth, 0.033, 1).frame, camera_, config_);
    AlignmentTarget target;
    buildAlignmentTarget(cur.map, cur.intensity, &target);
    pyramid.build(target);
    const Isometry3d start = Isometry3d::Identity();
    const AlignmentResult fixed =
        aligner_.alignCoarseToFine(sample_, target, map_camera, pyramid, start, fixed_gate);
    const AlignmentResult grown =
        aligner_.alignCoarseToFine(sample_, target, map_camera, pyramid, start, growing);
    EXPECT_GT(angleDeg(truth.inverse() * fixed.T_ref_cur), 3.0) << angle_deg;
    EXPECT_FALSE(judgeAlignment(fixed, config_).passed) << angle_deg;
    EXPECT_LT(angleDeg(truth.inverse() * grown.T_ref_cur), 0.05) << angle_deg;
    EXPECT_LT((truth.inverse() * grown.T_ref_cur).translation().norm(), 0.002) << angle_deg;
    EXPECT_TRUE(judgeAlignment(grown, config_).passed) << angle_deg;
  }
}

}  // namespace
}  // namespace nidevo
