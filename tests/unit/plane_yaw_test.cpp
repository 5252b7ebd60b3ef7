#include "nidevo/odometry/plane_yaw.hpp"

#include <gtest/gtest.h>

#include <Eigen/Geometry>
#include <cmath>

#include "map_frame.hpp"
#include "nidevo/odometry/odometry_config.hpp"

namespace nidevo {
namespace {

using Eigen::Matrix3d;
using Eigen::Vector3d;

constexpr double kDeg = M_PI / 180.0;

Camera vgaCamera() {
  Camera c;
  c.width = 640;
  c.height = 480;
  c.fx = c.fy = 525;
  c.cx = 319.5;
  c.cy = 239.5;
  return c;
}

// Tiles of 25 cm with a darker diagonal band across each, and a slow swell: directions that
// repeat every quarter turn, and a band that tells them apart.
double floorGrey(double x, double z) {
  const double tx = x / 0.25 - std::floor(x / 0.25), tz = z / 0.25 - std::floor(z / 0.25);
  double g = (int(std::floor(x / 0.25)) + int(std::floor(z / 0.25))) % 2 == 0 ? 170 : 90;
  if (std::abs(tx - tz) < 0.15) g -= 40;
  return g + 20 * std::sin(3 * x + 2 * z);
}

// A floor 1.4 m below a camera at C with R_world_cam (camera y down, world y down): depth and grey
// of every pixel whose ray meets it.
RgbdFrame floorFrame(const Camera& cam, const Matrix3d& R_world_cam, const Vector3d& C,
                     bool textured = true) {
  RgbdFrame f;
  f.gray.resize(cam.width, cam.height, 0);
  f.depth.resize(cam.width, cam.height, 0.f);
  for (int v = 0; v < cam.height; ++v) {
    for (int u = 0; u < cam.width; ++u) {
      const Vector3d ray((u - cam.cx) / cam.fx, (v - cam.cy) / cam.fy, 1.0);
      const Vector3d d = R_world_cam * ray;
      if (d.y() <= 1e-3) continue;
      const double t = (1.4 - C.y()) / d.y();
      if (t > 8) continue;
      const Vector3d X = C + t * d;
      f.depth.at(u, v) = float(t);
      f.gray.at(u, v) = uint8_t(std::clamp(textured ? floorGrey(X.x(), X.z()) : 128.0, 0.0, 255.0));
    }
  }
  return f;
}

Matrix3d pitchDown(double deg) {
  return Eigen::AngleAxisd(-deg * kDeg, Vector3d::UnitX()).matrix();
}
Matrix3d yaw(double deg) { return Eigen::AngleAxisd(deg * kDeg, Vector3d::UnitY()).matrix(); }

struct Views {
  test::MapFrame key, cur;
  Vector3d n_key, n_cur;
  Matrix3d R_key_cur;
};

// The floor from two cameras `turn_deg` apart about the vertical, the second also moved by `move`.
Views twoViews(double turn_deg, const Vector3d& move, bool textured = true) {
  const Camera cam = vgaCamera();
  const OdometryConfig c;
  const Matrix3d R_wk = pitchDown(35), R_wc = yaw(turn_deg) * pitchDown(35);
  Views out;
  out.key = test::mapOf(floorFrame(cam, R_wk, Vector3d::Zero(), textured), cam, c);
  out.cur = test::mapOf(floorFrame(cam, R_wc, move, textured), cam, c);
  const Vector3d n_world(0, -1, 0);  // towards the cameras, above the floor
  out.n_key = R_wk.transpose() * n_world;
  out.n_cur = R_wc.transpose() * n_world;
  out.R_key_cur = R_wk.transpose() * R_wc;
  return out;
}

// The turn the estimator finds when the current view's rotation is the true one turned by
// -error about the plane's normal (what stage 2 leaves when the prediction is that far off).
PlaneYaw estimateWithError(const Views& v, double error_deg) {
  const Camera map_camera = vgaCamera().subsampled(OdometryConfig{}.normal_stride);
  const Matrix3d R_hyp = Eigen::AngleAxisd(-error_deg * kDeg, v.n_key) * v.R_key_cur;
  PlaneView key{&v.key.map, v.key.intensity.data(), v.n_key.cast<float>(),
                Eigen::Matrix3f::Identity()};
  PlaneView cur{&v.cur.map, v.cur.intensity.data(), v.n_cur.cast<float>(), R_hyp.cast<float>()};
  PlaneYawEstimator estimator;
  return estimator.estimate(key, cur, map_camera, PlaneYawParams{});
}

TEST(PlaneYaw, RecoversAKnownTurnAboutTheNormal) {
  for (double turn : {6.0, -12.0}) {
    const Views v = twoViews(turn, Vector3d(0.05, 0, 0.1));
    // The prediction saw no turn at all: the whole turn is left to the grey values.
    const PlaneYaw y = estimateWithError(v, turn);
    ASSERT_TRUE(y.measured) << "turn " << turn << " ncc " << y.ncc;
    EXPECT_NEAR(y.turn_rad / kDeg, turn, 0.5) << "ncc " << y.ncc;
  }
}

TEST(PlaneYaw, FindsNoTurnWhereThereIsNone) {
  const Views v = twoViews(8.0, Vector3d(-0.1, 0, 0.05));
  const PlaneYaw y = estimateWithError(v, 0.0);
  ASSERT_TRUE(y.measured);
  EXPECT_NEAR(y.turn_rad / kDeg, 0.0, 0.5);
}

TEST(PlaneYaw, MeasuresNothingOnAnUntexturedPlane) {
  const Views v = twoViews(6.0, Vector3d::Zero(), false);
  const PlaneYaw y = estimateWithError(v, 6.0);
  EXPECT_FALSE(y.measured);
  EXPECT_LT(y.key_pixels, PlaneYawParams{}.min_pixels);
}

TEST(PlaneYaw, ATurnBeyondTheSearchIsNotMeasured) {
  const Views v = twoViews(30.0, Vector3d::Zero());
  const PlaneYaw y = estimateWithError(v, 30.0);  // beyond max_turn_rad (20 deg)
  EXPECT_FALSE(y.measured && std::abs(y.turn_rad / kDeg - 30.0) < 1.0);
  EXPECT_FALSE(y.measured && std::abs(y.turn_rad) > PlaneYawParams{}.max_turn_rad);
}

}  // namespace
}  // namespace nidevo
