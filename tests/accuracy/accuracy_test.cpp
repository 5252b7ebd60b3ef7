// Accuracy of the whole odometry on the project's synthetic sequences (300 frames at 30 Hz), with
// the targets of the core issue. Release build only: rendering 1500 frames takes a minute.
#include <gtest/gtest.h>

#include <algorithm>
#include <atomic>
#include <thread>

#include "nidevo/eval/metrics.hpp"
#include "nidevo/odometry/odometry.hpp"
#include "nidevo/sim/sequence.hpp"
#include "nidevo/sim/stress_suite.hpp"

namespace nidevo {
namespace {

struct SequenceRun {
  std::vector<PoseEstimate> poses;
  Trajectory estimate;
  std::vector<FrameError> errors;  // frame to frame, against the ground truth
  double ate_rmse = 0;
  int counts[3] = {0, 0, 0};
  int silent_failures = 0;  // OK, but over 2 deg or 5 cm off since the previous frame
};

struct RenderedSequence {
  synth::SequenceConfig config;
  std::vector<RgbdFrame> frames;
  Trajectory ground_truth;
};

// The upper median (of an even count, the larger middle value).
double median(std::vector<double> v) {
  std::nth_element(v.begin(), v.begin() + long(v.size() / 2), v.end());
  return v[v.size() / 2];
}

// The first `first_frames` frames only (0: all); the ground truth whole.
RenderedSequence render(const synth::SequenceConfig& config, int first_frames = 0) {
  RenderedSequence r;
  r.config = config;
  const synth::SyntheticSequence seq(r.config);
  const int count = first_frames > 0 ? std::min(first_frames, seq.size()) : seq.size();
  r.frames.resize(size_t(count));
  std::atomic<int> next{0};
  std::vector<std::thread> workers;
  for (unsigned w = 0; w < std::max(1u, std::thread::hardware_concurrency()); ++w) {
    workers.emplace_back([&] {
      for (int i = next++; i < count; i = next++) r.frames[size_t(i)] = seq.renderFrame(i);
    });
  }
  for (auto& t : workers) t.join();
  r.ground_truth = seq.groundTruthTrajectory();
  return r;
}

RenderedSequence render(const std::string& scene, synth::TextureRichness texture,
                        synth::SensorNoise noise) {
  synth::SequenceConfig config;
  config.scene = scene;
  config.texture = texture;
  config.noise = noise;
  return render(config);
}

SequenceRun track(const RenderedSequence& sequence, const OdometryConfig& config = {}) {
  Odometry odometry(sequence.config.camera, config);
  SequenceRun run;
  for (const auto& f : sequence.frames) {
    run.poses.push_back(odometry.track(f));
    const PoseEstimate& p = run.poses.back();
    ++run.counts[int(p.state)];
    run.estimate.push_back(StampedPose::fromPose(p.timestamp, p.T_world_cam));
  }
  run.ate_rmse = computeAte(matchByTimestamp(run.estimate, sequence.ground_truth)).translation.rmse;
  run.errors = frameToFrameErrors(run.estimate, sequence.ground_truth);
  std::vector<bool> ok;
  for (const auto& p : run.poses) ok.push_back(p.state == TrackingState::kOk);
  run.silent_failures =
      countSilentFailures(run.estimate, ok, sequence.ground_truth, 2.0, 0.05, 0.005).count;
  std::printf("%s: ATE RMSE %.4f m; %d OK, %d DEGRADED, %d LOST; %d silent failures\n",
              sequence.config.scene.c_str(), run.ate_rmse, run.counts[0], run.counts[1],
              run.counts[2], run.silent_failures);
  return run;
}

SequenceRun runSequence(const std::string& scene, synth::TextureRichness texture,
                        synth::SensorNoise noise) {
  return track(render(scene, texture, noise));
}

using synth::SensorNoise;
using synth::TextureRichness;

TEST(Accuracy, OfficeRichTextureCleanDepthWithinOneCentimetre) {
  const SequenceRun r = runSequence("office", TextureRichness::kRich, SensorNoise::kNone);
  EXPECT_LE(r.ate_rmse, 0.01);
  EXPECT_EQ(r.counts[int(TrackingState::kLost)], 0);
  EXPECT_EQ(r.silent_failures, 0);
}

TEST(Accuracy, OfficeLowTextureIclNoiseWithinThreeCentimetresNeverLost) {
  const SequenceRun r = runSequence("office", TextureRichness::kLow, SensorNoise::kIclLike);
  EXPECT_LE(r.ate_rmse, 0.03);
  EXPECT_EQ(r.counts[int(TrackingState::kLost)], 0);
  EXPECT_EQ(r.silent_failures, 0);
}

TEST(Accuracy, CorridorLowTextureIclNoiseWithinThreeCentimetresNeverLost) {
  const SequenceRun r = runSequence("corridor", TextureRichness::kLow, SensorNoise::kIclLike);
  EXPECT_LE(r.ate_rmse, 0.03);
  EXPECT_EQ(r.counts[int(TrackingState::kLost)], 0);
  EXPECT_EQ(r.silent_failures, 0);
}

TEST(Accuracy, CornerWithTwoPlanesIsTrackedThroughout) {
  const SequenceRun r = runSequence("corner", TextureRichness::kRich, SensorNoise::kNone);
  EXPECT_EQ(r.counts[int(TrackingState::kOk)], 300);
  for (const auto& p : r.poses) {
    if (p.frame_index > 0) {
      EXPECT_EQ(p.rotation_source, RotationSource::kPlanes);
    }
  }
  EXPECT_LE(r.ate_rmse, 0.01);
}

// A large hall whose walls and ceiling are beyond the sensor's range: the floor is the only large
// plane, and a Kinect-like camera circles a group of objects at 1.2 m/s (about 35 deg/s), as on
// a real recording where this odometry was once lost on most frames.
TEST(Accuracy, HallWithTheFloorAsTheOnlyLargePlaneIsTrackedRoundItsObjects) {
  synth::SequenceConfig config;
  config.scene = "hall";
  config.texture = TextureRichness::kLow;
  config.noise = SensorNoise::kStructuredLight;
  config.speed = 1.2;
  const SequenceRun r = track(render(config));
  EXPECT_LE(r.ate_rmse, 0.03);
  EXPECT_EQ(r.counts[int(TrackingState::kLost)], 0);
  // 95 % until two hypotheses that fit alike further apart than OK allows were not OK: one frame
  // fewer (docs/accuracy.md "Hypotheses that stay apart"). The count moves with the FFT's
  // rounding: 275 with one host's FFTW_ESTIMATE plan, 276-284 with others (11 runs with
  // --fft_measure; docs/accuracy.md "How far the FFT's rounding moves the figures").
  EXPECT_GE(r.counts[int(TrackingState::kOk)], 272);
  EXPECT_EQ(r.silent_failures, 0);
}

TEST(Accuracy, FewerThanTwoPlanesIsFlaggedAndTrackingRecovers) {
  const RenderedSequence gap = render("gap", TextureRichness::kRich, SensorNoise::kNone);
  const SequenceRun r = track(gap);
  int flagged = 0, last_flagged = -1;
  for (const auto& p : r.poses) {
    ASSERT_TRUE(p.T_world_cam.matrix().allFinite()) << p.frame_index;
    ASSERT_TRUE(std::isfinite(p.psr));
    const bool planes = p.rotation_source == RotationSource::kPlanes ||
                        p.rotation_source == RotationSource::kInitial;
    if (planes) continue;
    // Without two planes a frame is OK only when the pose check passed and fixed every rotation,
    // or the data confirmed the predicted value of a rotation too weak to update, or a
    // prediction right on the recent verified frames gave it (a translation left free is the
    // KCC's, measured); silent_failures below says those were right.
    if (p.state == TrackingState::kOk) {
      EXPECT_TRUE(p.verification.passed) << p.frame_index;
      if (p.verification.free_rotation) {
        EXPECT_TRUE(p.verification.confirmed_directions >= 1 || p.verification.predicted_directions)
            << p.frame_index;
      }
    } else {
      EXPECT_NE(std::string(p.reason), "");
      ++flagged;
      last_flagged = int(p.frame_index);
    }
  }
  EXPECT_GT(flagged, 30);  // the single-wall stretch exists and is flagged
  ASSERT_LT(last_flagged, 280);
  for (size_t i = size_t(last_flagged) + 5; i < r.poses.size(); ++i) {
    EXPECT_EQ(r.poses[i].state, TrackingState::kOk) << i;  // recovered once planes return
  }
  EXPECT_EQ(r.silent_failures, 0);
  EXPECT_LE(r.ate_rmse, 0.1);  // bounded drift through the stretch
}

// On the single-wall stretch of the gap scene (sensor noise on) some frames leave a direction
// to the prediction: those called OK for it must be as right as OK promises (0.3 deg, 1.5 cm
// frame to frame), and without the rule they are the same poses, DEGRADED.
TEST(Accuracy, ADirectionLeftToARecentlyRightPredictionIsOkAndRight) {
  const RenderedSequence gap = render("gap", TextureRichness::kRich, SensorNoise::kIclLike);
  // A DEGRADED pose is refined along its weak directions, an OK one is not: off in both runs, so
  // that the rule's own effect is what differs; so is the rule for hypotheses that stay apart,
  // which may demote a frame whatever the prediction says.
  OdometryConfig with_rule;
  with_rule.align_step_eigenvalue = 0;
  with_rule.ok_needs_hypotheses_to_agree = false;
  const SequenceRun r = track(gap, with_rule);
  OdometryConfig never = with_rule;
  never.prediction_trust_frames = 0;
  const SequenceRun without = track(gap, never);
  int predicted = 0;
  for (size_t i = 0; i < r.poses.size(); ++i) {
    const PoseEstimate& p = r.poses[i];
    ASSERT_TRUE(p.T_world_cam.isApprox(without.poses[i].T_world_cam, 1e-12)) << i;
    EXPECT_FALSE(without.poses[i].verification.predicted_directions) << i;
    if (!p.verification.predicted_directions) {
      EXPECT_EQ(p.state, without.poses[i].state) << i;
      continue;
    }
    ++predicted;
    EXPECT_EQ(p.state, TrackingState::kOk) << i;
    EXPECT_EQ(without.poses[i].state, TrackingState::kDegraded) << i;
    ASSERT_TRUE(r.errors[i].judged) << i;
    EXPECT_LT(r.errors[i].rotation_deg, 0.3) << i;
    EXPECT_LT(r.errors[i].translation_m, 0.015) << i;
  }
  EXPECT_GE(predicted, 5);
  EXPECT_EQ(r.silent_failures, 0);
}

// Stress sequence 1 has a periodic pattern where two poses fit alike, or a better fit far away
// rests on grey values alone: the pose nearer the prediction is kept. Where the prediction has
// been right on the recent verified frames and the kept pose lies within its bounds, the frame is
// OK, and right; without the rule the same poses are DEGRADED (the rule changes no pose).
TEST(Accuracy, APeriodicTieSettledByARecentlyRightPredictionIsOkAndRight) {
  const RenderedSequence s = render(synth::stressSequenceConfig(1));
  OdometryConfig unsettled;
  unsettled.prediction_settles_ties = false;
  const SequenceRun r = track(s);
  const SequenceRun without = track(s, unsettled);
  int settled = 0;
  for (size_t i = 0; i < r.poses.size(); ++i) {
    const PoseEstimate& p = r.poses[i];
    ASSERT_TRUE(p.T_world_cam.isApprox(without.poses[i].T_world_cam, 1e-12)) << i;
    if (p.state == without.poses[i].state) continue;
    ++settled;
    EXPECT_EQ(p.state, TrackingState::kOk) << i;
    EXPECT_TRUE(p.verification.predicted_directions) << i;
    EXPECT_NE(std::string(without.poses[i].reason).find("periodic pattern"), std::string::npos)
        << i << ": " << without.poses[i].reason;
    ASSERT_TRUE(r.errors[i].judged) << i;
    EXPECT_LT(r.errors[i].rotation_deg, 0.5) << i;
    EXPECT_LT(r.errors[i].translation_m, 0.03) << i;
  }
  EXPECT_GE(settled, 3);
  EXPECT_EQ(r.silent_failures, 0);
}

// Stress sequence 172 slides over one plane without texture: depth fixes three directions and
// the grey values, at an NCC near 0, the rest by noise, so each hypothesis stays near its start
// and all fit alike, further apart than OK allows. Those frames are DEGRADED, their poses
// unchanged, and they are the ones far off: their motion's error is the camera's step.
TEST(Accuracy, HypothesesThatFitAlikeFarApartAreNotOkAndTheyAreTheWrongOnes) {
  const RenderedSequence s = render(synth::stressSequenceConfig(172));
  OdometryConfig off;
  off.ok_needs_hypotheses_to_agree = false;
  const SequenceRun r = track(s);
  const SequenceRun without = track(s, off);
  std::vector<double> demoted_m, ok_m;
  for (size_t i = 0; i < r.poses.size(); ++i) {
    const PoseEstimate& p = r.poses[i];
    ASSERT_TRUE(p.T_world_cam.isApprox(without.poses[i].T_world_cam, 1e-12)) << i;
    if (p.state == TrackingState::kOk && r.errors[i].judged)
      ok_m.push_back(r.errors[i].translation_m);
    if (p.state == without.poses[i].state) continue;
    EXPECT_EQ(without.poses[i].state, TrackingState::kOk) << i;
    EXPECT_EQ(p.state, TrackingState::kDegraded) << i;
    EXPECT_NE(std::string(p.reason).find("ended further apart than OK allows"), std::string::npos)
        << i << ": " << p.reason;
    if (r.errors[i].judged) demoted_m.push_back(r.errors[i].translation_m);
  }
  ASSERT_GE(demoted_m.size(), 20u);
  ASSERT_FALSE(ok_m.empty());
  // Measured: 35 frames demoted, 2.96 cm against the OK frames' 0.79 cm at the median.
  EXPECT_GT(median(demoted_m), 2 * median(ok_m));
  EXPECT_LE(r.silent_failures, without.silent_failures);
}

// Stress sequence 51 loses track for a stretch; back from it, the pose check's minimum, found
// from hypotheses the stretch left far off, is a wrong one on some frames (its PNG folder: 3.8 deg,
// 2.6 deg, 5 cm)
// that depth and grey values agree on, with depth leaving a direction free. Until the prediction
// has been right again, such frames are DEGRADED; the rule changes no pose, and only demotes
// frames that follow a LOST one.
TEST(Accuracy, BackFromLostOnlyAPoseDepthFixesEverywhereIsOk) {
  const RenderedSequence s = render(synth::stressSequenceConfig(51));
  OdometryConfig never;
  never.recovery_min_depth_directions = 0;
  const SequenceRun r = track(s);
  const SequenceRun without = track(s, never);
  EXPECT_GT(without.silent_failures, 0);
  EXPECT_EQ(r.silent_failures, 0);
  int demoted = 0;
  bool lost_before = false;
  for (size_t i = 0; i < r.poses.size(); ++i) {
    const PoseEstimate& p = r.poses[i];
    ASSERT_TRUE(p.T_world_cam.isApprox(without.poses[i].T_world_cam, 1e-12)) << i;
    if (p.state != without.poses[i].state) {
      ++demoted;
      EXPECT_TRUE(lost_before) << i;
      EXPECT_EQ(p.state, TrackingState::kDegraded) << i;
      EXPECT_EQ(without.poses[i].state, TrackingState::kOk) << i;
      EXPECT_LT(p.verification.depth_constrained_directions, 6) << i;
      EXPECT_NE(std::string(p.reason).find("recovering from LOST"), std::string::npos) << i;
    }
    lost_before = lost_before || p.state == TrackingState::kLost;
  }
  EXPECT_GE(demoted, 3);
}

// Stress sequence 166 starts at about 10 m/s over one plane: on its first frames every
// hypothesis but the method's is "standing still", and the grey values fit a wrong pose near it
// (in its PNG folder frames 1, 4 and 9, 8-36 cm off, were OK). Until a frame has measured the
// motion without the prediction, such poses are DEGRADED; the rule changes no pose, and from
// that frame on the statuses are the same as without it.
TEST(Accuracy, AtTheStartAPoseRestingOnStandingStillIsNotOk) {
  const RenderedSequence s = render(synth::stressSequenceConfig(166), 40);
  OdometryConfig never;
  never.start_requires_measured_motion = false;
  const SequenceRun r = track(s);
  const SequenceRun without = track(s, never);
  EXPECT_GT(without.silent_failures, 0);
  EXPECT_EQ(r.silent_failures, 0);
  int demoted = 0;
  bool measured = false;
  for (size_t i = 0; i < r.poses.size(); ++i) {
    const PoseEstimate& p = r.poses[i];
    ASSERT_TRUE(p.T_world_cam.isApprox(without.poses[i].T_world_cam, 1e-12)) << i;
    if (p.state != without.poses[i].state) {
      ++demoted;
      EXPECT_FALSE(measured) << i;
      EXPECT_EQ(p.state, TrackingState::kDegraded) << i;
      EXPECT_EQ(without.poses[i].state, TrackingState::kOk) << i;
      EXPECT_LT(p.verification.depth_constrained_directions, 6) << i;
      EXPECT_STRNE(p.verification.hypothesis, "method") << i;
      EXPECT_NE(std::string(p.reason).find("no motion measured yet"), std::string::npos) << i;
    }
    measured = measured || (i > 0 && p.state == TrackingState::kOk);
  }
  EXPECT_GE(demoted, 2);
}

// Stress sequence 193 turns away from its reference at frame 139 with one plane in view: the
// plane's pair matches two different planes (the fit through a strip of points), and that
// correction of the prediction turned the camera by 87 deg. No hypothesis keeps the reference
// in view, so the check measures nothing there; the pose kept is then the prediction's unless
// two planes measured the rotation or it agrees with the prediction (docs/accuracy.md, "One
// plane whose fitted normals disagree").
TEST(Accuracy, WithTheReferenceOutOfViewAnUnmeasuredRotationFarFromThePredictionIsNotKept) {
  const RenderedSequence s = render(synth::stressSequenceConfig(193), 150);
  OdometryConfig keep_method;
  keep_method.unseen_reference_needs_measured_rotation = false;
  const SequenceRun r = track(s);
  const SequenceRun without = track(s, keep_method);
  const double min_overlap = OdometryConfig{}.verify_min_overlap;
  int unseen = 0;
  double worst_with = 0, worst_without = 0;
  for (size_t i = 1; i < r.poses.size(); ++i) {
    const PoseEstimate& p = r.poses[i];
    if (p.verification.overlap_fraction >= min_overlap ||
        p.rotation_source != RotationSource::kOnePlane)
      continue;
    ++unseen;
    EXPECT_NE(p.state, TrackingState::kOk) << i;
    EXPECT_NE(without.poses[i].state, TrackingState::kOk) << i;
    worst_with = std::max(worst_with, r.errors[i].rotation_deg);
    worst_without = std::max(worst_without, without.errors[i].rotation_deg);
  }
  ASSERT_GE(unseen, 1);
  EXPECT_GT(worst_without, 20.0);
  EXPECT_LT(worst_with, 2.0);
  EXPECT_LT(r.ate_rmse, without.ate_rmse);
  EXPECT_EQ(r.silent_failures, 0);
}

// Stress sequence 17 turns with one plane in view for stretches, where a direction is left free
// and the frames are not verified. Refined from the prediction with five directions fixed by
// depth, they still measure the motion: without that, the velocity decays to standing still
// over the stretch while the camera turns, and every prediction lags the turn (docs/accuracy.md,
// "The pose check": 0.183 to 0.086 m on this sequence's PNG folder; rendered in memory here, 0.208
// to 0.147 m).
TEST(Accuracy, UnverifiedFramesThatDepthFixesKeepTheMotionModelMoving) {
  const RenderedSequence s = render(synth::stressSequenceConfig(17));
  OdometryConfig only_verified;
  only_verified.unverified_motion_min_directions = 7;
  const SequenceRun with_rule = track(s);
  const SequenceRun without = track(s, only_verified);
  EXPECT_EQ(with_rule.silent_failures, 0);
  // On the frames the data leave unverified (without the rule), the motion the rule kept shows
  // as smaller frame-to-frame errors, and in the trajectory.
  std::vector<double> rotation_with, rotation_without;
  for (size_t i = 0; i < s.frames.size(); ++i) {
    if (!with_rule.errors[i].judged || without.poses[i].state == TrackingState::kOk) continue;
    rotation_with.push_back(with_rule.errors[i].rotation_deg);
    rotation_without.push_back(without.errors[i].rotation_deg);
  }
  ASSERT_GE(rotation_with.size(), 10u);
  EXPECT_LT(median(rotation_with), median(rotation_without));
  EXPECT_LT(with_rule.ate_rmse, without.ate_rmse);
}

}  // namespace
}  // namespace nidevo
