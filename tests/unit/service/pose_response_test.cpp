// The odometry's PoseEstimate as the API's answer: the pose check's figures reach the client.
#include "pose_response.hpp"

#include <gtest/gtest.h>

namespace nidevo::server {
namespace {

TEST(PoseResponse, CarriesEveryFigureOfThePoseCheck) {
  PoseEstimate pose;
  pose.state = TrackingState::kDegraded;
  pose.reason = "depth and grey values disagree on the rotation";
  PoseVerification& v = pose.verification;
  v.hypothesis = "prediction";
  v.passed = true;
  v.inlier_fraction = 0.93;
  v.overlap_fraction = 0.81;
  v.residual_rms_m = 0.006;
  v.ncc = 0.94;
  v.constrained_directions = 6;
  v.depth_constrained_directions = 5;
  v.confirmed_directions = 1;
  v.predicted_directions = true;
  v.grey_depth_gap_deg = 1.25;
  v.sigma_rotation_deg = 0.031;
  v.sigma_translation_m = 0.0012;
  v1::Frame frame;
  frame.set_sequence(7);
  v1::TrackResponse out;
  fillPoseResponse(frame, pose, Eigen::Isometry3d::Identity(), &out);
  EXPECT_EQ(out.status(), v1::FRAME_STATUS_DEGRADED);
  ASSERT_TRUE(out.has_check());
  const v1::PoseCheck& c = out.check();
  EXPECT_EQ(c.hypothesis(), "prediction");
  EXPECT_TRUE(c.passed());
  EXPECT_EQ(c.inlier_fraction(), 0.93);
  EXPECT_EQ(c.overlap_fraction(), 0.81);
  EXPECT_EQ(c.residual_rms_m(), 0.006);
  EXPECT_EQ(c.ncc(), 0.94);
  EXPECT_EQ(c.constrained_directions(), 6);
  EXPECT_EQ(c.depth_constrained_directions(), 5);
  EXPECT_EQ(c.confirmed_directions(), 1);
  EXPECT_TRUE(c.predicted_directions());
  EXPECT_EQ(c.grey_depth_gap_deg(), 1.25);
  EXPECT_EQ(c.sigma_rotation_deg(), 0.031);
  EXPECT_EQ(c.sigma_translation_m(), 0.0012);

  // A pose without a check (the first frame) clears an earlier answer's.
  pose.verification = PoseVerification{};
  fillPoseResponse(frame, pose, Eigen::Isometry3d::Identity(), &out);
  EXPECT_FALSE(out.has_check());
}

}  // namespace
}  // namespace nidevo::server
