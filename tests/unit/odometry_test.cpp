#include "nidevo/odometry/odometry.hpp"

#include <gtest/gtest.h>

#include <cmath>
#include <random>

#include "nidevo/io/camera_io.hpp"
#include "nidevo/odometry/motion_model.hpp"
#include "nidevo/sim/sequence.hpp"
#include "painted_wall.hpp"

namespace nidevo {
namespace {

bool finitePose(const Eigen::Isometry3d& T) { return T.matrix().allFinite(); }

synth::SequenceConfig officeConfig(int frames) {
  synth::SequenceConfig c;
  c.frames = frames;
  return c;
}

TEST(Odometry, RecoversAKnownTranslationBetweenTwoFrames) {
  const synth::SyntheticSequence seq(officeConfig(1));
  const Eigen::Isometry3d T0 = seq.groundTruth(0);
  for (const Eigen::Vector3d& d :
       {Eigen::Vector3d(0.05, 0, 0), Eigen::Vector3d(0, -0.04, 0), Eigen::Vector3d(0, 0, 0.06),
        Eigen::Vector3d(0.02, -0.03, 0.04)}) {
    Odometry odometry(seq.config().camera, OdometryConfig{});
    odometry.track(seq.renderAt(T0, 0.0, 0).frame);
    Eigen::Isometry3d T1 = T0;
    T1.translation() += T0.linear() * d;
    const PoseEstimate p = odometry.track(seq.renderAt(T1, 0.033, 1).frame);
    EXPECT_EQ(p.state, TrackingState::kOk);
    EXPECT_EQ(p.rotation_source, RotationSource::kPlanes);
    EXPECT_GE(p.planes_used, 2);
    EXPECT_LT((p.T_world_cam.translation() - d).norm(), 0.003) << d.transpose();
    // 0.017 deg: the grey-value polish of the pose check sees the renderer's bilinear
    // resampling (0.011 deg here; under 0.006 deg without it).
    EXPECT_LT(Eigen::AngleAxisd(p.T_world_cam.rotation()).angle(), 3e-4);
    EXPECT_GT(p.psr, 20);
  }
}

TEST(Odometry, UndistortsTheLensOfTheCamera) {
  synth::SequenceConfig c = officeConfig(1);
  c.camera = *cameraPreset("tum_fr1");  // TUM's fr1 lens: k1 0.26, strong at the corners
  const synth::SyntheticSequence seq(c);
  const Eigen::Isometry3d T0 = seq.groundTruth(0);
  Eigen::Isometry3d T1 = T0;
  T1.linear() = T0.linear() * Eigen::AngleAxisd(0.03, Eigen::Vector3d::UnitY()).toRotationMatrix();
  T1.translation() += T0.linear() * Eigen::Vector3d(0.03, -0.02, 0.03);
  const Eigen::Isometry3d truth = T0.inverse() * T1;
  Camera pinhole = c.camera;
  pinhole.distortion = Distortion{};
  double errors[2];
  for (int k = 0; k < 2; ++k) {
    Odometry odometry(k == 0 ? c.camera : pinhole, OdometryConfig{});
    odometry.track(seq.renderAt(T0, 0.0, 0).frame);
    const PoseEstimate p = odometry.track(seq.renderAt(T1, 0.033, 1).frame);
    const Eigen::Isometry3d err = truth.inverse() * p.T_world_cam;
    errors[k] = err.translation().norm() + Eigen::AngleAxisd(err.rotation()).angle();
    if (k == 0) {
      EXPECT_EQ(p.state, TrackingState::kOk);
      EXPECT_LT(err.translation().norm(), 0.003);
      EXPECT_LT(Eigen::AngleAxisd(err.rotation()).angle(), 0.002);
    }
  }
  EXPECT_LT(errors[0], errors[1]);  // the pinhole model of the same lens does worse
}

TEST(Odometry, OnePlaneFallbackRecoversARollAboutThePlaneNormalFromTexture) {
  const synth::SyntheticSequence seq(officeConfig(1));
  const Camera cam = seq.config().camera;
  // A textured wall 2 m ahead, square to the optical axis; the camera then rolls about that
  // axis, the wall's normal: depth alone cannot see it, the image rotates about (cx, cy).
  RgbdFrame wall = seq.renderFrame(0);
  std::fill(wall.depth.data.begin(), wall.depth.data.end(), 2.f);
  const double roll = 2.0 * M_PI / 180;
  RgbdFrame rolled = wall;
  rolled.timestamp += 0.033;
  for (int v = 0; v < cam.height; ++v) {
    for (int u = 0; u < cam.width; ++u) {
      // Pixel (u, v) of the rolled camera sees the ray R_z(roll) * ray(u, v) of the first one.
      const double x = (u - cam.cx) / cam.fx, y = (v - cam.cy) / cam.fy;
      const double xs = std::cos(roll) * x - std::sin(roll) * y;
      const double ys = std::sin(roll) * x + std::cos(roll) * y;
      const int us = int(std::lround(xs * cam.fx + cam.cx)),
                vs = int(std::lround(ys * cam.fy + cam.cy));
      rolled.gray.at(u, v) = us >= 0 && vs >= 0 && us < cam.width && vs < cam.height
                                 ? wall.gray.at(us, vs)
                                 : uint8_t(128);
    }
  }
  Odometry odometry(cam, OdometryConfig{});
  odometry.track(wall);
  const PoseEstimate p = odometry.track(rolled);

  EXPECT_NE(p.rotation_source, RotationSource::kPlanes);
  const Eigen::Matrix3d truth =
      Eigen::AngleAxisd(roll, Eigen::Vector3d::UnitZ()).toRotationMatrix();
  EXPECT_LT(Eigen::AngleAxisd(truth.transpose() * p.T_world_cam.linear()).angle() * 180 / M_PI,
            0.1);
  EXPECT_LT(p.T_world_cam.translation().norm(), 0.005);
}

// A wall's texture rolled by `roll_deg` about the optical axis, the wall's normal, as the camera
// sees it after that roll: depth alone cannot see the turn.
RgbdFrame rolledWall(const Camera& cam, const RgbdFrame& wall, double roll_deg) {
  const double roll = roll_deg * M_PI / 180;
  RgbdFrame rolled = wall;
  rolled.timestamp += 0.033;
  for (int v = 0; v < cam.height; ++v) {
    for (int u = 0; u < cam.width; ++u) {
      const double x = (u - cam.cx) / cam.fx, y = (v - cam.cy) / cam.fy;
      const double us = (std::cos(roll) * x - std::sin(roll) * y) * cam.fx + cam.cx;
      const double vs = (std::sin(roll) * x + std::cos(roll) * y) * cam.fy + cam.cy;
      const int u0 = int(std::floor(us)), v0 = int(std::floor(vs));
      if (u0 < 0 || v0 < 0 || u0 + 1 >= cam.width || v0 + 1 >= cam.height) {
        rolled.gray.at(u, v) = 128;
        continue;
      }
      // Bilinear, as a lens blurs: nearest-neighbour steps would point along the pixel grid.
      const double a = us - u0, b = vs - v0;
      const double g =
          (1 - a) * (1 - b) * wall.gray.at(u0, v0) + a * (1 - b) * wall.gray.at(u0 + 1, v0) +
          (1 - a) * b * wall.gray.at(u0, v0 + 1) + a * b * wall.gray.at(u0 + 1, v0 + 1);
      rolled.gray.at(u, v) = uint8_t(std::lround(g));
    }
  }
  return rolled;
}

// Stage 2 alone, with one plane in view and a turn about its normal the prediction knows nothing
// of: the grey values' gradient directions measure it when one_plane_image_yaw is on.
TEST(Odometry, OnePlaneImageYawMeasuresATurnThePredictionMissed) {
  const synth::SyntheticSequence seq(officeConfig(1));
  const Camera cam = seq.config().camera;
  RgbdFrame wall = seq.renderFrame(0);
  std::fill(wall.depth.data.begin(), wall.depth.data.end(), 2.f);
  const double roll_deg = 10.0;
  const RgbdFrame rolled = rolledWall(cam, wall, roll_deg);
  const Eigen::Matrix3d truth =
      Eigen::AngleAxisd(roll_deg * M_PI / 180, Eigen::Vector3d::UnitZ()).toRotationMatrix();
  double error_deg[2];
  for (bool on : {false, true}) {
    OdometryConfig c;
    c.one_plane_image_yaw = on;
    Odometry odometry(cam, c);
    FrameState first, second;
    odometry.computeNormals(wall, &first);
    odometry.estimateRotation(&first);
    odometry.computeNormals(rolled, &second);
    odometry.estimateRotation(&second);
    ASSERT_EQ(second.rotation_source, RotationSource::kOnePlane);
    EXPECT_EQ(second.plane_yaw.measured, on)
        << "ncc " << second.plane_yaw.ncc << " turn " << second.plane_yaw.turn_rad << " pixels "
        << second.plane_yaw.key_pixels << " " << second.plane_yaw.cur_pixels;
    error_deg[on] = Eigen::AngleAxisd(truth.transpose() * second.R_world_cam).angle() * 180 / M_PI;
  }
  EXPECT_GT(error_deg[0], 9.0);  // the prediction: standing still
  // The histograms' precision on this texture is about a degree (bins, smoothing and gradient
  // floors tried: 0.2-1.4 deg); the pose check refines from there.
  EXPECT_LT(error_deg[1], 1.5);
}

TEST(Odometry, RecoversAKnownRotationBetweenTwoFrames) {
  const synth::SyntheticSequence seq(officeConfig(1));
  const Eigen::Isometry3d T0 = seq.groundTruth(0);
  Odometry odometry(seq.config().camera, OdometryConfig{});
  odometry.track(seq.renderAt(T0, 0.0, 0).frame);
  const Eigen::Matrix3d dR =
      Eigen::AngleAxisd(0.05, Eigen::Vector3d(0.3, 1, 0.2).normalized()).toRotationMatrix();
  Eigen::Isometry3d T1 = T0;
  T1.linear() = T0.linear() * dR;
  const PoseEstimate p = odometry.track(seq.renderAt(T1, 0.033, 1).frame);
  EXPECT_LT(Eigen::AngleAxisd(p.T_world_cam.linear().transpose() * dR).angle(), 1e-3);
  EXPECT_LT(p.T_world_cam.translation().norm(), 0.005);
}

// Frames 0, 1, 2 turned by 0, 3 and 6 deg about a tilted axis, the keyframe staying at frame 0:
// frame 2 is matched against a keyframe 6 deg away, the motion model predicting the turn.
PoseEstimate turnSixDegrees(bool predicted_association, double* error_deg,
                            int plane_pixel_step = OdometryConfig{}.plane_pixel_step) {
  const synth::SyntheticSequence seq(officeConfig(1));
  const Eigen::Isometry3d T0 = seq.groundTruth(0);
  OdometryConfig config;
  config.predicted_association = predicted_association;
  config.plane_pixel_step = plane_pixel_step;
  config.align_iterations = 0;  // the method's own rotation, unrefined by the pose check
  Odometry odometry(seq.config().camera, config);
  const Eigen::Vector3d axis = Eigen::Vector3d(0.2, 1, 0.1).normalized();
  PoseEstimate p;
  for (int k = 0; k < 3; ++k) {
    Eigen::Isometry3d T = T0;
    T.linear() = T0.linear() * Eigen::AngleAxisd(k * 3 * M_PI / 180, axis).toRotationMatrix();
    p = odometry.track(seq.renderAt(T, 0.033 * k, k).frame);
    EXPECT_FALSE(k == 1 && p.rotation_keyframe) << "the keyframe must stay at frame 0";
  }
  const Eigen::Matrix3d truth = Eigen::AngleAxisd(6 * M_PI / 180, axis).toRotationMatrix();
  *error_deg = Eigen::AngleAxisd(p.T_world_cam.linear().transpose() * truth).angle() * 180 / M_PI;
  return p;
}

TEST(Odometry, PredictedAssociationSurvivesASixDegreeTurnFromTheKeyframe) {
  double same_pixel_error = 0, predicted_error = 0;
  const PoseEstimate same_pixel = turnSixDegrees(false, &same_pixel_error);
  const PoseEstimate predicted = turnSixDegrees(true, &predicted_error);
  EXPECT_EQ(predicted.rotation_source, RotationSource::kPlanes);
  EXPECT_GE(predicted.planes_used, 2);
  EXPECT_LT(predicted_error, 0.05);
  // Pixels paired through the predicted turn see the same surface point: more of them pass the
  // co-planarity test than pixels paired by position (6 deg is about 25 map pixels here).
  EXPECT_GT(predicted.overlap_pixels, 1.08 * same_pixel.overlap_pixels);
}

// A frame whose grey values were seen 1.2 deg further along a turn than its depth: DEGRADED,
// with the pose the same as with the rule off; the same frame with its own grey values is OK.
TEST(Odometry, GreyValuesOutOfStepWithDepthAreDegradedWithThePoseUnchanged) {
  const synth::SyntheticSequence seq(officeConfig(1));
  const Eigen::Isometry3d T0 = seq.groundTruth(0);
  const Eigen::Vector3d axis = Eigen::Vector3d(0.2, 1, 0.1).normalized();
  auto turned = [&](double deg) {
    Eigen::Isometry3d T = T0;
    T.linear() = T0.linear() * Eigen::AngleAxisd(deg * M_PI / 180, axis).toRotationMatrix();
    return T;
  };
  RgbdFrame out_of_step = seq.renderAt(turned(2.0), 0.033, 1).frame;
  out_of_step.gray = seq.renderAt(turned(3.2), 0.033, 1).frame.gray;
  auto second = [&](const RgbdFrame& frame, float max_gap_rad) {
    OdometryConfig config;
    config.verify_max_grey_depth_gap_rad = max_gap_rad;
    Odometry odometry(seq.config().camera, config);
    odometry.track(seq.renderAt(T0, 0.0, 0).frame);
    return odometry.track(frame);
  };
  const float rule = OdometryConfig{}.verify_max_grey_depth_gap_rad;
  const PoseEstimate in_step = second(seq.renderAt(turned(2.0), 0.033, 1).frame, rule);
  EXPECT_EQ(in_step.state, TrackingState::kOk) << in_step.reason;
  EXPECT_LT(in_step.verification.grey_depth_gap_deg, 0.3);
  const PoseEstimate flagged = second(out_of_step, rule);
  EXPECT_EQ(flagged.state, TrackingState::kDegraded);
  EXPECT_STREQ(flagged.reason,
               "depth and grey values disagree on the rotation (colour and depth out of step, "
               "motion blur?)");
  EXPECT_NEAR(flagged.verification.grey_depth_gap_deg, 1.2, 0.15);
  const PoseEstimate rule_off = second(out_of_step, 0.f);
  EXPECT_EQ(rule_off.state, TrackingState::kOk) << rule_off.reason;
  EXPECT_EQ(rule_off.T_world_cam.matrix(), flagged.T_world_cam.matrix());
}

// The frame after one whose grey values were out of step with its depth: right in itself, yet
// its motion since that frame carries the frame's error, so it is DEGRADED too; the one after
// is OK again, and no pose changes with the rule.
TEST(Odometry, TheFrameAfterOneOutOfStepIsDegradedWithThePoseUnchanged) {
  const synth::SyntheticSequence seq(officeConfig(1));
  const Eigen::Isometry3d T0 = seq.groundTruth(0);
  const Eigen::Vector3d axis = Eigen::Vector3d(0.2, 1, 0.1).normalized();
  auto frameTurned = [&](double deg, int k) {
    Eigen::Isometry3d T = T0;
    T.linear() = T0.linear() * Eigen::AngleAxisd(deg * M_PI / 180, axis).toRotationMatrix();
    return seq.renderAt(T, 0.033 * k, k).frame;
  };
  RgbdFrame out_of_step = frameTurned(2.0, 1);
  out_of_step.gray = frameTurned(3.2, 1).gray;
  const std::vector<RgbdFrame> frames = {frameTurned(0, 0), out_of_step, frameTurned(4.0, 2),
                                         frameTurned(6.0, 3)};
  auto run = [&](float max_gap_rad) {
    OdometryConfig config;
    config.verify_max_grey_depth_gap_rad = max_gap_rad;
    Odometry odometry(seq.config().camera, config);
    std::vector<PoseEstimate> out;
    for (const RgbdFrame& f : frames) out.push_back(odometry.track(f));
    return out;
  };
  const std::vector<PoseEstimate> with_rule = run(OdometryConfig{}.verify_max_grey_depth_gap_rad);
  const std::vector<PoseEstimate> without = run(0.f);
  ASSERT_EQ(with_rule[1].state, TrackingState::kDegraded) << "the frame out of step itself";
  ASSERT_EQ(without[2].state, TrackingState::kOk) << without[2].reason;
  EXPECT_EQ(with_rule[2].state, TrackingState::kDegraded);
  EXPECT_STREQ(with_rule[2].reason,
               "the last frame's depth and grey values disagreed on the rotation: the motion "
               "since it is not verified");
  EXPECT_EQ(with_rule[3].state, TrackingState::kOk) << with_rule[3].reason;
  for (size_t k = 0; k < frames.size(); ++k)
    EXPECT_EQ(with_rule[k].T_world_cam.matrix(), without[k].T_world_cam.matrix()) << "frame " << k;
}

// A second frame with 5 mm of depth noise: its spread is well inside what OK promises at the
// default two sigmas; a rule of just more sigmas than reach the first bound calls it DEGRADED,
// just fewer OK; the pose is the same either way.
TEST(Odometry, APoseWhoseSpreadIsWiderThanOkAllowsIsDegradedWithThePoseUnchanged) {
  const synth::SyntheticSequence seq(officeConfig(1));
  RgbdFrame noisy = seq.renderFrame(1);
  std::mt19937 rng(3);
  std::normal_distribution<float> gauss(0.f, 0.005f);
  for (float& z : noisy.depth.data)
    if (z > 0) z += gauss(rng);
  auto second = [&](float sigmas) {
    OdometryConfig config;
    config.verify_max_spread_sigmas = sigmas;
    Odometry odometry(seq.config().camera, config);
    odometry.track(seq.renderFrame(0));
    return odometry.track(noisy);
  };
  const PoseEstimate sure = second(OdometryConfig{}.verify_max_spread_sigmas);
  ASSERT_EQ(sure.state, TrackingState::kOk) << sure.reason;
  const OdometryConfig c;
  EXPECT_GT(sure.verification.sigma_translation_m, 0);
  EXPECT_LT(2 * sure.verification.sigma_translation_m, c.prediction_trust_m);
  // The number of sigmas at which the first of the two spreads reaches its bound.
  const double bound =
      std::min(c.prediction_trust_m / sure.verification.sigma_translation_m,
               c.prediction_trust_rad * 180 / M_PI / sure.verification.sigma_rotation_deg);
  EXPECT_EQ(second(float(0.99 * bound)).state, TrackingState::kOk) << "within both bounds";
  const PoseEstimate flagged = second(float(1.01 * bound));
  EXPECT_EQ(flagged.state, TrackingState::kDegraded);
  EXPECT_STREQ(flagged.reason, "the pose's spread from the sensor noise is wider than OK allows");
  EXPECT_EQ(flagged.T_world_cam.matrix(), sure.T_world_cam.matrix());
}

// A wall with bold stripes across y and faint ones across x every 5 cm: depth fixes three
// directions, the grey values the other three, yet along x they fit the pose moved by a period
// as well. The rule calls the frame DEGRADED and leaves every pose as it was; with stripes every
// 8 cm the grey values tell x, and the frame is OK.
TEST(Odometry, ADirectionTheGreyValuesFixButCannotTellIsDegradedWithThePoseUnchanged) {
  const synth::SyntheticSequence seq(officeConfig(2));
  const Camera cam = seq.config().camera;
  auto run = [&](double x_period, bool rule) {
    const auto paint = test::boldAndFaintStripes(x_period);
    OdometryConfig config;
    config.verify_grey_fixed_told = rule;
    Odometry odometry(cam, config);
    odometry.track(test::paintedWall(cam, seq.renderFrame(0), Eigen::Vector3d::Zero(), paint));
    return odometry.track(
        test::paintedWall(cam, seq.renderFrame(1), Eigen::Vector3d(0.01, 0.005, 0), paint));
  };
  const PoseEstimate without = run(0.05, false);
  ASSERT_EQ(without.state, TrackingState::kOk) << without.reason;
  ASSERT_EQ(without.verification.depth_constrained_directions, 3);
  ASSERT_EQ(without.verification.constrained_directions, 6);
  const PoseEstimate with_rule = run(0.05, true);
  EXPECT_EQ(with_rule.state, TrackingState::kDegraded);
  EXPECT_STREQ(with_rule.reason,
               "a direction only the grey values fixed: they fit the pose moved along it "
               "(align_confirm_shift_m) as well");
  EXPECT_EQ(with_rule.T_world_cam.matrix(), without.T_world_cam.matrix());
  const PoseEstimate told = run(0.08, true);
  EXPECT_EQ(told.state, TrackingState::kOk) << told.reason;
}

TEST(Odometry, NoValidDepthIsLostButFiniteAndRecovers) {
  const synth::SyntheticSequence seq(officeConfig(6));
  Odometry odometry(seq.config().camera, OdometryConfig{});
  odometry.track(seq.renderFrame(0));
  RgbdFrame empty = seq.renderFrame(1);
  std::fill(empty.depth.data.begin(), empty.depth.data.end(), 0.f);
  const PoseEstimate lost = odometry.track(empty);
  EXPECT_EQ(lost.state, TrackingState::kLost);
  EXPECT_NE(std::string(lost.reason), "");
  EXPECT_TRUE(finitePose(lost.T_world_cam));
  RgbdFrame nan_depth = seq.renderFrame(2);
  std::fill(nan_depth.depth.data.begin(), nan_depth.depth.data.end(), std::nanf(""));
  EXPECT_TRUE(finitePose(odometry.track(nan_depth).T_world_cam));
  // Back: the pose is checked against the reference again, but the motion since the last
  // answer corrects a prediction, so the first frame back is not OK; the next one is.
  const PoseEstimate back = odometry.track(seq.renderFrame(3));
  EXPECT_TRUE(finitePose(back.T_world_cam));
  EXPECT_EQ(back.state, TrackingState::kDegraded);
  EXPECT_STREQ(back.reason,
               "the last frame had no depth (its pose was predicted): the motion since it is not "
               "measured");
  const PoseEstimate next = odometry.track(seq.renderFrame(4));
  EXPECT_EQ(next.state, TrackingState::kOk) << next.reason;
}

// A session whose first frames have no depth: the first frame with depth takes the last
// answer's pose without anything to measure the motion since, so it is not OK; the session's
// very first frame is (it defines the world).
TEST(Odometry, TheFirstFrameWithDepthAfterFramesWithoutIsNotOk) {
  const synth::SyntheticSequence seq(officeConfig(6));
  Odometry first_has_depth(seq.config().camera, OdometryConfig{});
  EXPECT_EQ(first_has_depth.track(seq.renderFrame(0)).state, TrackingState::kOk);
  Odometry odometry(seq.config().camera, OdometryConfig{});
  RgbdFrame empty = seq.renderFrame(0);
  std::fill(empty.depth.data.begin(), empty.depth.data.end(), 0.f);
  EXPECT_EQ(odometry.track(empty).state, TrackingState::kLost);
  const PoseEstimate p = odometry.track(seq.renderFrame(1));
  EXPECT_EQ(p.state, TrackingState::kDegraded);
  EXPECT_STREQ(p.reason,
               "the first frame with depth after frames without it: the motion since the last "
               "pose is not measured");
  EXPECT_TRUE(finitePose(p.T_world_cam));
  // Later frames are checked against it as usual.
  for (int k = 2; k < 6; ++k)
    EXPECT_TRUE(finitePose(odometry.track(seq.renderFrame(k)).T_world_cam));
}

TEST(Odometry, OnePlaneIsDegradedNotGarbage) {
  const synth::SyntheticSequence seq(officeConfig(1));
  const Camera cam = seq.config().camera;
  // A single wall 2 m ahead fills the view.
  RgbdFrame wall = seq.renderFrame(0);
  std::fill(wall.depth.data.begin(), wall.depth.data.end(), 2.f);
  OdometryConfig depth_only;
  depth_only.align_photometric_weight = 0;  // nothing but the wall's geometry to check with
  for (const OdometryConfig& config : {depth_only, OdometryConfig{}}) {
    Odometry odometry(cam, config);
    RgbdFrame frame = wall;
    odometry.track(frame);
    frame.timestamp += 0.033;
    const PoseEstimate p = odometry.track(frame);
    EXPECT_LE(p.planes_used, 1);
    EXPECT_NE(p.rotation_source, RotationSource::kPlanes);
    EXPECT_TRUE(finitePose(p.T_world_cam));
    EXPECT_LT(p.T_world_cam.translation().norm(), 0.01);
    if (config.align_photometric_weight == 0) {
      EXPECT_EQ(p.state, TrackingState::kDegraded);
    } else if (p.state == TrackingState::kOk) {
      // The wall's texture fixed what its geometry leaves free.
      EXPECT_TRUE(p.verification.passed);
      EXPECT_FALSE(p.verification.free_rotation);
    }
  }
}

// The depth sensor sees only a narrow band of the view (the rest out of range): too little of
// the reference lands on valid depth, so that frame fails the check, and it must become the
// reference itself, or every later frame would be checked against a view it no longer sees.
TEST(Odometry, AFrameThatFailsTheCheckBecomesTheReference) {
  const synth::SyntheticSequence seq(officeConfig(1));
  const Eigen::Isometry3d T0 = seq.groundTruth(0);
  const OdometryConfig config;
  Odometry odometry(seq.config().camera, config);
  odometry.track(seq.renderAt(T0, 0.0, 0).frame);
  RgbdFrame band = seq.renderAt(T0, 0.033, 1).frame;
  for (int v = 0; v < band.depth.height; ++v)
    for (int u = 0; u < band.depth.width; ++u)
      if (std::abs(u - band.depth.width / 2) > band.depth.width / 10) band.depth.at(u, v) = 0.f;
  const PoseEstimate narrow = odometry.track(band);
  EXPECT_NE(narrow.state, TrackingState::kOk);
  EXPECT_LT(narrow.verification.overlap_fraction, config.verify_min_overlap);
  EXPECT_STREQ(narrow.verification.hypothesis, "method");  // its own keyframes, not a guess
  band.timestamp += 0.033;
  const PoseEstimate next = odometry.track(band);
  EXPECT_GT(next.verification.overlap_fraction, 0.9);  // checked against frame 1, not frame 0
  EXPECT_EQ(next.state, TrackingState::kOk) << next.reason;
}

TEST(Odometry, AllBlackImageDoesNotCrashOrProduceNaN) {
  const synth::SyntheticSequence seq(officeConfig(3));
  Odometry odometry(seq.config().camera, OdometryConfig{});
  for (int i = 0; i < 3; ++i) {
    RgbdFrame f = seq.renderFrame(i);
    std::fill(f.gray.data.begin(), f.gray.data.end(), uint8_t(0));
    const PoseEstimate p = odometry.track(f);
    EXPECT_TRUE(finitePose(p.T_world_cam));
    EXPECT_TRUE(std::isfinite(p.psr));
  }
}

TEST(Odometry, PlaneTrackingOnEveryOtherPixelFindsTheSamePlanesAndRotation) {
  double all_error = 0, sparse_error = 0;
  const PoseEstimate all = turnSixDegrees(true, &all_error, 1);
  const PoseEstimate sparse = turnSixDegrees(true, &sparse_error, 2);
  EXPECT_EQ(sparse.rotation_source, RotationSource::kPlanes);
  EXPECT_EQ(sparse.planes_used, all.planes_used);
  EXPECT_LT(all_error, 0.05);
  EXPECT_LT(sparse_error, 0.05);
  // The overlap is counted over the whole map, scaled up from the pixels read.
  EXPECT_NEAR(sparse.overlap_pixels, all.overlap_pixels, 0.05 * all.overlap_pixels);
}

TEST(Odometry, RejectsFramesOfTheWrongSizeAndBadConfigs) {
  const Camera cam = *cameraPreset("icl");
  Odometry odometry(cam, OdometryConfig{});
  RgbdFrame small;
  small.gray.resize(320, 240);
  small.depth.resize(320, 240);
  try {
    odometry.track(small);
    FAIL();
  } catch (const std::invalid_argument& e) {
    EXPECT_NE(std::string(e.what()).find("320x240 but the camera is 640x480"), std::string::npos);
  }
  OdometryConfig bad;
  bad.cell_size = 0;
  try {
    Odometry o(cam, bad);
    FAIL();
  } catch (const std::invalid_argument& e) {
    EXPECT_NE(std::string(e.what()).find("cell_size"), std::string::npos);
  }
  bad = OdometryConfig{};
  bad.align_converged_m = -1e-4f;
  EXPECT_NE(bad.validate().find("align_converged_m"), std::string::npos);
  bad = OdometryConfig{};
  bad.align_join_m = 0.5f;
  EXPECT_NE(bad.validate().find("align_join_m"), std::string::npos);
  bad = OdometryConfig{};
  bad.align_step_eigenvalue = -1e-3f;
  EXPECT_NE(bad.validate().find("align_step_eigenvalue"), std::string::npos);
  bad = OdometryConfig{};
  bad.align_step_inlier_slack = 0.9f;
  EXPECT_NE(bad.validate().find("align_step_inlier_slack"), std::string::npos);
  bad = OdometryConfig{};
  bad.recovery_min_depth_directions = 7;
  EXPECT_NE(bad.validate().find("recovery_min_depth_directions"), std::string::npos);
  bad = OdometryConfig{};
  bad.verify_max_spread_sigmas = -1.f;
  EXPECT_NE(bad.validate().find("verify_max_spread_sigmas"), std::string::npos);
  bad = OdometryConfig{};
  bad.align_confirm_shift_m = -0.01f;
  EXPECT_NE(bad.validate().find("align_confirm_shift_m"), std::string::npos);
  bad = OdometryConfig{};
  bad.align_coarse_levels = 4;
  EXPECT_NE(bad.validate().find("align_coarse_levels"), std::string::npos);
  bad = OdometryConfig{};
  bad.align_coarse_gate_growth = 0.5f;  // a coarse level must not gate tighter than the fine one
  EXPECT_NE(bad.validate().find("align_coarse_gate_growth"), std::string::npos);
  bad = OdometryConfig{};
  bad.plane_pixel_step = 0;
  EXPECT_NE(bad.validate().find("plane_pixel_step"), std::string::npos);
  bad = OdometryConfig{};
  bad.plane_yaw_smooth_radius = 8;
  EXPECT_NE(bad.validate().find("plane_yaw_smooth_radius"), std::string::npos);
  bad = OdometryConfig{};
  bad.plane_yaw_min_turn_rad = 0.5f;  // beyond plane_yaw_max_turn_rad
  EXPECT_NE(bad.validate().find("plane_yaw_min_turn_rad"), std::string::npos);
  bad = OdometryConfig{};
  bad.plane_yaw_bins = 8;
  EXPECT_NE(bad.validate().find("plane_yaw_bins"), std::string::npos);
  bad = OdometryConfig{};
  bad.projection_width = 17;
  EXPECT_THROW(Odometry(cam, bad), std::invalid_argument);
  Camera bad_cam = cam;
  bad_cam.fy = 0;
  EXPECT_THROW(Odometry(bad_cam, OdometryConfig{}), std::invalid_argument);
}

TEST(MotionModel, DecaysTowardsStandingStill) {
  MotionModel model(0.5);
  Eigen::Isometry3d T = Eigen::Isometry3d::Identity();
  model.update(T, true, 0.0);
  T.translation().x() = 0.1;
  model.update(T, true, 1 / 30.0);
  EXPECT_NEAR(model.predict(2 / 30.0).translation().x(), 0.2, 1e-12);
  model.update(model.predict(2 / 30.0), false, 2 / 30.0);
  EXPECT_NEAR(model.predict(3 / 30.0).translation().x(), 0.2 + 0.1 * 0.5, 1e-12);
}

// A 30 Hz stream whose timestamps jitter by up to 20 %, turning 2 deg a frame about y and moving
// 1 cm a frame along it (along the axis, so that n frames are exactly n times each).
struct JitteredStream {
  MotionModel model;
  double t = 0;
  int frame = 0;
  Eigen::Isometry3d pose(int k) const {
    Eigen::Isometry3d T = Eigen::Isometry3d::Identity();
    T.linear() =
        Eigen::AngleAxisd(k * 2.0 * M_PI / 180, Eigen::Vector3d::UnitY()).toRotationMatrix();
    T.translation().y() = 0.01 * k;
    return T;
  }
  double timeOf(int k) const { return k / 30.0 + (k % 3 == 1 ? 0.2 : k % 3 == 2 ? -0.2 : 0) / 30; }
  void feed(int frames) {
    for (int k = 0; k < frames; ++k, ++frame) model.update(pose(frame), true, timeOf(frame));
  }
};

double rotationErrorDeg(const Eigen::Isometry3d& a, const Eigen::Isometry3d& b) {
  return Eigen::AngleAxisd(a.linear().transpose() * b.linear()).angle() * 180 / M_PI;
}

TEST(MotionModel, JitterCountsAsOneFrameAndADroppedFrameAsTwo) {
  JitteredStream s;
  s.feed(10);
  EXPECT_EQ(s.model.framesBetween(s.timeOf(9), s.timeOf(10)), 1.0);  // a 40 ms gap
  // The next frame, on time: one frame's motion.
  const Eigen::Isometry3d next = s.model.predict(s.timeOf(10));
  EXPECT_LT(rotationErrorDeg(next, s.pose(10)), 1e-9);
  EXPECT_NEAR(next.translation().y(), 0.10, 1e-9);
  // Frame 10 dropped: frame 11 is two frames' motion away.
  EXPECT_EQ(s.model.framesBetween(s.timeOf(9), s.timeOf(11)), 2.0);
  const Eigen::Isometry3d skipped = s.model.predict(s.timeOf(11));
  EXPECT_LT(rotationErrorDeg(skipped, s.pose(11)), 1e-9);
  EXPECT_NEAR(skipped.translation().y(), 0.11, 1e-9);
  // A motion measured over the drop is per two frames: the frame after is one more.
  s.model.update(s.pose(11), true, s.timeOf(11));
  const Eigen::Isometry3d after = s.model.predict(s.timeOf(12));
  EXPECT_LT(rotationErrorDeg(after, s.pose(12)), 1e-9);
  EXPECT_NEAR(after.translation().y(), 0.12, 1e-9);
}

TEST(MotionModel, WithoutUsableTimestampsEveryUpdateIsOneFrame) {
  MotionModel model;
  Eigen::Isometry3d T = Eigen::Isometry3d::Identity();
  model.update(T, true, 0);
  T.translation().x() = 0.1;
  model.update(T, true, 0);  // no timestamps: all zero
  EXPECT_NEAR(model.predict(0).translation().x(), 0.2, 1e-12);
  EXPECT_NEAR(model.predict(-5).translation().x(), 0.2, 1e-12);  // backwards: one frame
  EXPECT_EQ(model.framesBetween(0, 1), 1.0);
}

TEST(MotionModel, ALongPauseExtrapolatesAtMostFourFrames) {
  JitteredStream s;
  s.feed(10);
  EXPECT_EQ(s.model.framesBetween(s.timeOf(9), s.timeOf(9) + 10.0), MotionModel::kMaxFrames);
  EXPECT_NEAR(s.model.predict(s.timeOf(9) + 10.0).translation().y(), 0.09 + 0.04, 1e-9);
}

}  // namespace
}  // namespace nidevo
