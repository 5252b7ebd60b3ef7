#include "nidevo/odometry/pose_check.hpp"

#include <gtest/gtest.h>

#include <string>

namespace nidevo {
namespace {

using Eigen::Isometry3d;

Isometry3d shifted(double x) {
  Isometry3d T = Isometry3d::Identity();
  T.translation().x() = x;
  return T;
}

// A passing alignment at `T`: `inliers` of 1000 associated points agree; depth fixed
// `depth_constrained` directions and the grey values the rest.
AlignmentResult passing(const Isometry3d& T, int inliers, int depth_constrained) {
  AlignmentResult a;
  a.T_ref_cur = T;
  a.sampled = 1000;
  a.associated = 1000;
  a.inliers = inliers;
  a.rms_m = 0.005;
  a.ncc = 0.9;
  a.ref_intensity_std = 0.1;
  a.constrained = 6;
  a.depth_constrained = depth_constrained;
  return a;
}

class ChooseHypothesisTest : public ::testing::Test {
 protected:
  HypothesisChoice choose(const AlignmentResult& method, const AlignmentResult& prediction) {
    const AlignmentResult results[] = {method, prediction};
    const CheckVerdict verdicts[] = {judgeAlignment(method, config_),
                                     judgeAlignment(prediction, config_)};
    // The method measured its rotation and translation; the prediction is only a guess.
    const HypothesisOrigin origins[] = {{true, true, true}, {false, false, false}};
    return chooseHypothesis(results, verdicts, origins, 2, still_, config_);
  }
  OdometryConfig config_;
  const Isometry3d still_ = Isometry3d::Identity();  // standing still was predicted
  const double period_ = 0.3;                        // floor tiles
};

TEST_F(ChooseHypothesisTest, APassingPoseBeatsAFailingOne) {
  AlignmentResult failed = passing(still_, 400, 6);  // 40 % inliers
  const HypothesisChoice c = choose(failed, passing(shifted(0.01), 950, 6));
  EXPECT_EQ(c.index, 1);
  EXPECT_FALSE(c.ambiguous);
}

TEST_F(ChooseHypothesisTest, ABetterFitAPeriodAwayOnGreyValuesAloneLosesToTheTrustedPose) {
  // The method jumped a tile along the floor, which only the grey values fix, and fits 5 %
  // better than the prediction: more than a tie, and still no proof.
  const HypothesisChoice c =
      choose(passing(shifted(period_), 1000, 3), passing(shifted(0.005), 950, 3));
  EXPECT_EQ(c.index, 1);
  EXPECT_TRUE(c.ambiguous);
  EXPECT_TRUE(c.overruled);
}

TEST_F(ChooseHypothesisTest, AJumpDepthMeasuredIsKept) {
  // The same jump with depth fixing all six directions is a measurement, not an alias.
  const HypothesisChoice c =
      choose(passing(shifted(period_), 1000, 6), passing(shifted(0.005), 950, 6));
  EXPECT_EQ(c.index, 0);
  EXPECT_FALSE(c.overruled);
}

TEST_F(ChooseHypothesisTest, AnUntrustedPoseIsKeptWhenNothingTrustedPasses) {
  AlignmentResult failed = passing(shifted(0.005), 950, 3);
  failed.ncc = 0.1;  // the grey values disagree
  const HypothesisChoice c = choose(passing(shifted(period_), 1000, 3), failed);
  EXPECT_EQ(c.index, 0);
  EXPECT_FALSE(c.overruled);
  EXPECT_FALSE(directionsTrusted(passing(shifted(period_), 1000, 3), still_,
                                 HypothesisOrigin{true, true, true}, config_));
}

TEST_F(ChooseHypothesisTest, AFarPoseThatFitsFewerPointsLosesToTheNearOneEvenIfThatFails) {
  // The method's KCC peak jumped a tile along the floor; the grey values there happen to agree
  // (it passes, with a score lifted by its NCC), the prediction's do not (it fails). The
  // prediction still fits more of the surface: the jump rests on grey values alone.
  AlignmentResult near = passing(shifted(0.005), 950, 3);
  near.ncc = 0.1;
  AlignmentResult far = passing(shifted(period_), 900, 3);
  ASSERT_FALSE(judgeAlignment(near, config_).passed);
  ASSERT_GT(alignmentScore(far, config_), alignmentScore(near, config_));
  const HypothesisChoice c = choose(far, near);
  EXPECT_EQ(c.index, 1);
  EXPECT_TRUE(c.overruled);
  // Fitting more points than the near pose, the far one stays (the test above); so does a far
  // pose the depth fixed in every direction.
  EXPECT_EQ(choose(passing(shifted(period_), 900, 6), near).index, 0);
}

TEST_F(ChooseHypothesisTest, FitsWithinATieAtDistantPosesGoToThePoseNearerThePrediction) {
  const HypothesisChoice c =
      choose(passing(shifted(period_), 1000, 6), passing(shifted(0.005), 995, 6));
  EXPECT_EQ(c.index, 1);
  EXPECT_TRUE(c.ambiguous);
  EXPECT_FALSE(c.overruled);
}

TEST_F(ChooseHypothesisTest, AConfirmedWeakDirectionCountsAsFixedNearThePredictionOnly) {
  // One plane: the roll about its normal came from the prediction, and the grey values fix it
  // too weakly to update it.
  AlignmentResult a = passing(shifted(0.005), 950, 3);
  a.constrained = 5;
  a.free_rotation = true;
  const HypothesisOrigin roll_predicted{true, false, true};
  EXPECT_FALSE(directionsTrusted(a, still_, roll_predicted, config_));
  a.confirmed = 1;  // ... yet they would not move it
  EXPECT_TRUE(directionsTrusted(a, still_, roll_predicted, config_));
  a.T_ref_cur = shifted(period_);  // a period from the prediction: no confirmation counts
  EXPECT_FALSE(directionsTrusted(a, still_, roll_predicted, config_));
}

TEST_F(ChooseHypothesisTest, WithTheOptionGreyFixedDirectionsCountOnlyWhereTheGreyValuesAgree) {
  // One plane: depth fixes 3 directions, the grey values 2 more, the sixth is confirmed; on a
  // texture too weak for the NCC to be asked, an NCC of 0.28 passes the check but fixes nothing.
  const HypothesisOrigin last_pose{false, false, false};
  OdometryConfig on = config_;
  on.grey_fixed_needs_ncc = true;
  AlignmentResult a = passing(shifted(0.005), 950, 3);
  a.constrained = 5;
  a.confirmed = 1;
  a.ref_intensity_std = 0.02;
  a.ncc = 0.28;
  ASSERT_TRUE(judgeAlignment(a, config_).passed);
  EXPECT_FALSE(directionsTrusted(a, still_, last_pose, on));
  a.ncc = 0.6;
  EXPECT_TRUE(directionsTrusted(a, still_, last_pose, on));
  // Depth alone fixing what it fixes needs no grey agreement; off (the default), the grey
  // values' fixes count whatever their NCC.
  a.ncc = 0.28;
  a.depth_constrained = 5;
  EXPECT_TRUE(directionsTrusted(a, still_, last_pose, on));
  a.depth_constrained = 3;
  EXPECT_TRUE(directionsTrusted(a, still_, last_pose, config_));
}

Isometry3d turned(double deg) {
  Isometry3d T = Isometry3d::Identity();
  T.linear() = Eigen::AngleAxisd(deg * M_PI / 180, Eigen::Vector3d::UnitY()).toRotationMatrix();
  return T;
}

class PredictionRecordTest : public ::testing::Test {
 protected:
  // A verified frame whose pose the prediction missed by `motion_error`.
  void verify(const Isometry3d& motion_error) {
    record_.verified(Isometry3d::Identity(), motion_error);
  }
  OdometryConfig config_;  // 5 frames, latest at most 3 back, 0.3 deg and 1.5 cm
  PredictionRecord record_;
};

TEST_F(PredictionRecordTest, ReliableOnlyAfterEnoughVerifiedFrames) {
  for (int k = 0; k < config_.prediction_trust_frames - 1; ++k) {
    verify(shifted(0.005));
    EXPECT_FALSE(record_.reliable(config_)) << k;
  }
  verify(shifted(0.005));
  EXPECT_TRUE(record_.reliable(config_));
}

TEST_F(PredictionRecordTest, AnRmsErrorOverEitherBoundIsNotReliable) {
  // Four exact predictions and one 3.5 cm miss: RMS 1.57 cm, over 1.5 cm.
  for (int k = 0; k < 4; ++k) verify(Isometry3d::Identity());
  verify(shifted(0.035));
  EXPECT_FALSE(record_.reliable(config_));
  for (int k = 0; k < 5; ++k) verify(shifted(0.014));  // the miss leaves the window
  EXPECT_TRUE(record_.reliable(config_));
  for (int k = 0; k < 5; ++k) verify(turned(0.31));
  EXPECT_FALSE(record_.reliable(config_));
  for (int k = 0; k < 5; ++k) verify(turned(0.29));
  EXPECT_TRUE(record_.reliable(config_));
}

TEST_F(PredictionRecordTest, AStaleRecordIsNotReliable) {
  for (int k = 0; k < 5; ++k) verify(Isometry3d::Identity());
  for (int k = 0; k < config_.prediction_trust_gap - 1; ++k) record_.unverified();
  EXPECT_TRUE(record_.reliable(config_));  // the latest verified frame is gap frames back
  record_.unverified();
  EXPECT_FALSE(record_.reliable(config_));
  verify(Isometry3d::Identity());
  EXPECT_TRUE(record_.reliable(config_));
}

TEST_F(PredictionRecordTest, ZeroFramesMeansNever) {
  for (int k = 0; k < 20; ++k) verify(Isometry3d::Identity());
  config_.prediction_trust_frames = 0;
  EXPECT_FALSE(record_.reliable(config_));
}

TEST(WithinPredictionTrust, BoundsRotationAndTranslationApart) {
  const OdometryConfig c;
  EXPECT_TRUE(withinPredictionTrust(shifted(0.1), shifted(0.114), c));
  EXPECT_FALSE(withinPredictionTrust(shifted(0.1), shifted(0.116), c));
  EXPECT_TRUE(withinPredictionTrust(turned(1.0), turned(1.29), c));
  EXPECT_FALSE(withinPredictionTrust(turned(1.0), turned(1.31), c));
}

// A plane without texture: refined from the method's pose and from standing still, both fit
// alike and each stays near its start, 3 cm apart along the plane.
TEST(TieBeyondOkBounds, FitsAlikeFurtherApartThanOkAllowsAreATie) {
  const OdometryConfig c;
  const AlignmentResult results[] = {passing(shifted(0.03), 950, 3), passing(shifted(0), 948, 3)};
  const CheckVerdict both_pass[] = {{true, ""}, {true, ""}};
  EXPECT_TRUE(tieBeyondOkBounds(results, both_pass, 2, 0, c));
  EXPECT_TRUE(tieBeyondOkBounds(results, both_pass, 2, 1, c));
  // A failing hypothesis is no rival, however it scored.
  const CheckVerdict one_fails[] = {{true, ""}, {false, "pose failed verification"}};
  EXPECT_FALSE(tieBeyondOkBounds(results, one_fails, 2, 0, c));
  // The one hypothesis tried has no rival.
  EXPECT_FALSE(tieBeyondOkBounds(results, both_pass, 1, 0, c));
}

TEST(TieBeyondOkBounds, AgreeingPosesOrAClearlyBetterFitAreNoTie) {
  const OdometryConfig c;
  const CheckVerdict both_pass[] = {{true, ""}, {true, ""}};
  // Converged to one pose from both starts, within what OK promises (1.5 cm).
  const AlignmentResult agreeing[] = {passing(shifted(0.010), 950, 3),
                                      passing(shifted(0.002), 948, 3)};
  EXPECT_FALSE(tieBeyondOkBounds(agreeing, both_pass, 2, 0, c));
  // The data told them apart: 5 % more points agree with the kept pose (the tie is 2 %).
  const AlignmentResult told[] = {passing(shifted(0.03), 1000, 3), passing(shifted(0), 950, 3)};
  EXPECT_FALSE(tieBeyondOkBounds(told, both_pass, 2, 0, c));
  // A turn apart counts like a shift: 0.5 deg is over the 0.3 deg OK promises.
  const AlignmentResult turned_apart[] = {passing(turned(0.5), 950, 3),
                                          passing(turned(0.0), 949, 3)};
  EXPECT_TRUE(tieBeyondOkBounds(turned_apart, both_pass, 2, 0, c));
}

// A free direction translating along a ridge axis is the KCC's unmeasured value; one turning, or
// translating across the axis, is not.
TEST(FreeAlongKccRidge, OnlyTranslationAlongARidgeAxisCounts) {
  AlignmentResult a;
  KccRidges ridges;
  ridges.count = 1;
  ridges.axis[0] = Eigen::Vector3d::UnitY();
  EXPECT_FALSE(freeAlongKccRidge(a, ridges)) << "no free direction";
  a.weak_count = 1;
  a.weak_axes.col(0) << 0, 0, 0, 0.1, 0.99, 0;  // along y
  EXPECT_TRUE(freeAlongKccRidge(a, ridges));
  a.weak_axes.col(0) << 0, 0, 0, 0.99, 0.1, 0;  // along x, across the ridge
  EXPECT_FALSE(freeAlongKccRidge(a, ridges));
  a.weak_axes.col(0) << 0.99, 0, 0, 0, 0.1, 0;  // a turn
  EXPECT_FALSE(freeAlongKccRidge(a, ridges));
  a.weak_axes.col(0) << 0, 0, 0, 0.1, 0.99, 0;
  ridges.count = 0;
  EXPECT_FALSE(freeAlongKccRidge(a, ridges)) << "no ridge";
}

// The status rules on evidence with known answers: the method's pose, near a still prediction.
class DecideStatusTest : public ::testing::Test {
 protected:
  StatusDecision decide(const AlignmentResult& best) {
    evidence_.best = &best;
    evidence_.verdict = judgeAlignment(best, config_);
    return decideStatus(evidence_, config_);
  }
  OdometryConfig config_;
  StatusEvidence evidence_ = [] {
    StatusEvidence e;
    e.origin = {true, true, true};
    return e;
  }();
};

TEST_F(DecideStatusTest, APoseDepthFixesEverywhereIsOkWithoutThePrediction) {
  const StatusDecision d = decide(passing(shifted(0.002), 950, 6));
  EXPECT_TRUE(d.ok);
  EXPECT_FALSE(d.predicted_directions);
  EXPECT_FALSE(d.tie_settled);
}

TEST_F(DecideStatusTest, AFailedCheckIsNotOkAndSaysWhy) {
  AlignmentResult a = passing(shifted(0.002), 500, 6);  // half the points disagree
  const StatusDecision d = decide(a);
  EXPECT_FALSE(d.ok);
  EXPECT_STREQ(d.reason, "pose failed verification: depth disagrees with the pose");
}

TEST_F(DecideStatusTest, ATieIsSettledOnlyByAReliablePredictionNearThePose) {
  evidence_.choice.ambiguous = true;
  const AlignmentResult near = passing(shifted(0.005), 950, 6);
  StatusDecision d = decide(near);
  EXPECT_FALSE(d.ok) << "no reliable prediction";
  EXPECT_NE(std::string(d.reason).find("two poses fit equally"), std::string::npos);
  evidence_.prediction_reliable = true;
  d = decide(near);
  EXPECT_TRUE(d.ok);
  EXPECT_TRUE(d.tie_settled);
  EXPECT_TRUE(d.predicted_directions);
  d = decide(passing(shifted(0.03), 950, 6));  // beyond prediction_trust_m of it
  EXPECT_FALSE(d.ok);
  config_.prediction_settles_ties = false;
  EXPECT_FALSE(decide(near).ok);
  evidence_.choice = {0, false, true};  // overruled
  EXPECT_NE(std::string(decide(near).reason).find("a better fit far"), std::string::npos);
}

TEST_F(DecideStatusTest, AFreeDirectionIsTheMethodsWhereItMeasuredItElseThePredictions) {
  AlignmentResult a = passing(shifted(0.005), 950, 5);
  a.constrained = 5;
  a.free_translation = true;
  EXPECT_TRUE(decide(a).ok) << "the method measured its translation";
  evidence_.origin.translation_measured = false;
  evidence_.method_problem = "low PSR; translation predicted";
  StatusDecision d = decide(a);
  EXPECT_FALSE(d.ok);
  EXPECT_STREQ(d.reason, "low PSR; translation predicted");
  evidence_.prediction_reliable = true;
  d = decide(a);
  EXPECT_TRUE(d.ok);
  EXPECT_TRUE(d.predicted_directions);
  EXPECT_FALSE(d.tie_settled);
  // Measured, but along the KCC's ridge: not the method's measurement.
  evidence_.origin.translation_measured = true;
  evidence_.prediction_reliable = false;
  evidence_.method_problem = nullptr;
  a.weak_count = 1;
  a.weak_axes.col(0) << 0, 0, 0, 1, 0, 0;
  evidence_.ridges.count = 1;
  evidence_.ridges.axis[0] = Eigen::Vector3d::UnitX();
  d = decide(a);
  EXPECT_FALSE(d.ok);
  EXPECT_NE(std::string(d.reason).find("ridge"), std::string::npos);
}

}  // namespace
}  // namespace nidevo
