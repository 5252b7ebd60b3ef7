#include "nidevo/eval/metrics.hpp"

#include <gtest/gtest.h>

#include <random>

namespace nidevo {
namespace {

Trajectory helix(int n) {
  Trajectory t;
  for (int i = 0; i < n; ++i) {
    Eigen::Isometry3d T = Eigen::Isometry3d::Identity();
    T.linear() = Eigen::AngleAxisd(0.02 * i, Eigen::Vector3d::UnitY()).toRotationMatrix();
    T.translation() = Eigen::Vector3d(std::cos(0.05 * i), 0.01 * i, std::sin(0.05 * i));
    t.push_back(StampedPose::fromPose(i / 30.0, T));
  }
  return t;
}

TEST(Statistics, MatchesHandComputedValues) {
  const auto s = computeStatistics({1, 2, 3, 4});
  EXPECT_DOUBLE_EQ(s.mean, 2.5);
  EXPECT_DOUBLE_EQ(s.median, 2.5);
  EXPECT_DOUBLE_EQ(s.sse, 30);
  EXPECT_DOUBLE_EQ(s.rmse, std::sqrt(7.5));
  EXPECT_DOUBLE_EQ(s.std, std::sqrt(1.25));
  EXPECT_DOUBLE_EQ(s.min, 1);
  EXPECT_DOUBLE_EQ(s.max, 4);
}

TEST(Ate, RigidlyMovedCopyHasZeroError) {
  const Trajectory ref = helix(300);
  Eigen::Isometry3d M = Eigen::Isometry3d::Identity();
  M.linear() =
      Eigen::AngleAxisd(1.1, Eigen::Vector3d(0.3, -0.5, 0.8).normalized()).toRotationMatrix();
  M.translation() = Eigen::Vector3d(4, -2, 7);
  Trajectory est;
  for (const auto& p : ref) est.push_back(StampedPose::fromPose(p.timestamp, M * p.pose()));
  const auto m = matchByTimestamp(est, ref);
  ASSERT_EQ(m.estimate.size(), 300u);
  const auto ate = computeAte(m);
  EXPECT_LT(ate.translation.rmse, 1e-9);
  EXPECT_LT(ate.translation.max, 1e-9);
  const auto rpe = computeRpe(m, 1);
  EXPECT_LT(rpe.translation.max, 1e-9);
  EXPECT_LT(rpe.rotation.max, 1e-6);
}

TEST(Ate, MatchesKnownNoise) {
  const Trajectory ref = helix(4000);
  std::mt19937_64 rng(3);
  const double sigma = 0.01;
  std::normal_distribution<double> g(0, sigma);
  Trajectory est;
  for (const auto& p : ref) {
    StampedPose q = p;
    q.translation += Eigen::Vector3d(g(rng), g(rng), g(rng));
    est.push_back(q);
  }
  const auto ate = computeAte(matchByTimestamp(est, ref));
  // The norm of 3-D isotropic noise has RMS sigma*sqrt(3).
  EXPECT_NEAR(ate.translation.rmse, sigma * std::sqrt(3.0), 0.03 * sigma * std::sqrt(3.0));
}

TEST(Ate, UnmatchedTimestampsAreSkippedAndTooFewIsAnError) {
  Trajectory ref = helix(10), est = helix(10);
  for (auto& p : est) p.timestamp += 0.5;  // nothing within 10 ms
  EXPECT_THROW(computeAte(matchByTimestamp(est, ref)), std::invalid_argument);
}

TEST(Ate, OffsetUndoesAKnownTimestampLag) {
  // Accelerating, so that no rigid motion maps the path onto itself a frame later (a helix's
  // would).
  Trajectory ref;
  for (int i = 0; i < 300; ++i) {
    Eigen::Isometry3d T = Eigen::Isometry3d::Identity();
    T.translation() = Eigen::Vector3d(1e-4 * i * i, std::sin(0.1 * i), 0);
    ref.push_back(StampedPose::fromPose(i / 30.0, T));
  }
  Trajectory late = ref;
  for (auto& p : late) p.timestamp += 0.25;  // the same poses, stamped 250 ms late
  EXPECT_THROW(computeAte(matchByTimestamp(late, ref)), std::invalid_argument);
  const auto m = matchByTimestamp(late, ref, 0.01, -0.25);
  ASSERT_EQ(m.estimate.size(), 300u);
  EXPECT_LT(computeAte(m).translation.max, 1e-9);
  EXPECT_DOUBLE_EQ(m.timestamps.front(), late.front().timestamp);  // reported as stamped
  // One frame off matches each pose with its neighbour's instant: the error is no longer zero.
  const auto off_by_one = matchByTimestamp(late, ref, 0.01, -0.25 + 1.0 / 30);
  ASSERT_EQ(off_by_one.estimate.size(), 299u);
  EXPECT_GT(computeAte(off_by_one).translation.max, 1e-3);
}

TEST(Rpe, MeasuresAKnownDriftPerFrame) {
  const Trajectory ref = helix(50);
  Trajectory est;
  for (size_t i = 0; i < ref.size(); ++i) {
    Eigen::Isometry3d T = ref[i].pose();
    T.translation() += Eigen::Vector3d(0.001 * double(i), 0, 0);
    est.push_back(StampedPose::fromPose(ref[i].timestamp, T));
  }
  const auto rpe = computeRpe(matchByTimestamp(est, ref), 1);
  EXPECT_NEAR(rpe.translation.mean, 0.001, 1e-9);
}

TEST(SilentFailures, CountPlantedErrorsOnlyWhereTheMethodReportedGood) {
  const Trajectory ref = helix(40);
  Trajectory est = ref;
  // Frame 10 jumps 10 cm and comes back at 11: the motions into 10 and into 11 are both wrong.
  Eigen::Isometry3d jumped = ref[10].pose();
  jumped.translation() += Eigen::Vector3d(0.1, 0, 0);
  est[10] = StampedPose::fromPose(ref[10].timestamp, jumped);
  // Frame 30 turns 3 degrees too far, and stays turned: only the motion into 30 is wrong.
  for (size_t i = 30; i < est.size(); ++i) {
    Eigen::Isometry3d turned = ref[i].pose();
    turned.linear() = turned.linear() * Eigen::AngleAxisd(3 * M_PI / 180, Eigen::Vector3d::UnitY());
    est[i] = StampedPose::fromPose(ref[i].timestamp, turned);
  }
  std::vector<bool> good(est.size(), true);
  SilentFailures all = countSilentFailures(est, good, ref);
  EXPECT_EQ(all.count, 3);
  EXPECT_EQ(all.judged, 39);
  ASSERT_EQ(all.timestamps.size(), 3u);
  EXPECT_DOUBLE_EQ(all.timestamps[0], ref[10].timestamp);
  EXPECT_DOUBLE_EQ(all.timestamps[2], ref[30].timestamp);
  good[10] = false;  // the method said frame 10 was not good: not silent
  good[30] = false;
  EXPECT_EQ(countSilentFailures(est, good, ref).count, 1);
  // With wider bounds (5 degrees, 20 cm) none of these errors counts.
  EXPECT_EQ(countSilentFailures(est, std::vector<bool>(est.size(), true), ref, 5.0, 0.2).count, 0);
  EXPECT_THROW(countSilentFailures(est, std::vector<bool>(3, true), ref), std::invalid_argument);
}

}  // namespace
}  // namespace nidevo
