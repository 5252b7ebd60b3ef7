#include "nidevo/odometry/camera.hpp"

#include <gtest/gtest.h>

#include <filesystem>
#include <fstream>

#include "nidevo/io/camera_io.hpp"

namespace nidevo {
namespace {

std::string tempFile(const std::string& name, const std::string& content) {
  auto path = std::filesystem::temp_directory_path() / ("nidevo_camera_" + name);
  std::ofstream(path) << content;
  return path.string();
}

TEST(Camera, PresetsAreValidAndIclHasNegativeFy) {
  for (const char* name : {"icl", "icl_fy_positive", "tum_fr1", "tum_fr2", "tum_fr3"}) {
    auto c = cameraPreset(name);
    ASSERT_TRUE(c.has_value()) << name;
    EXPECT_EQ(c->validate(), "") << name;
  }
  EXPECT_DOUBLE_EQ(cameraPreset("icl")->fy, -480.0);
  EXPECT_FALSE(cameraPreset("nope").has_value());
}

TEST(Camera, BackprojectThenProjectIsIdentityWithNegativeFy) {
  Camera c = *cameraPreset("icl");
  const Eigen::Vector3f p = c.backproject(100.f, 50.f, 2.5f);
  EXPECT_GT(p.y(), 0.f);  // fy < 0: image top is +y
  const Eigen::Vector2d uv = c.project(p.cast<double>());
  EXPECT_NEAR(uv.x(), 100.0, 1e-4);
  EXPECT_NEAR(uv.y(), 50.0, 1e-4);
}

TEST(Camera, ValidateNamesTheBadField) {
  Camera c;
  c.fx = 0;
  EXPECT_NE(c.validate().find("fx"), std::string::npos);
  c = Camera{};
  c.depth_scale = -1;
  EXPECT_NE(c.validate().find("depth_scale"), std::string::npos);
  c = Camera{};
  c.width = 0;
  EXPECT_NE(c.validate().find("width"), std::string::npos);
}

TEST(Camera, FileRoundTrip) {
  Camera c = *cameraPreset("tum_fr1");
  const auto path = (std::filesystem::temp_directory_path() / "nidevo_camera_rt.txt").string();
  writeCameraFile(path, c);
  const Camera r = readCameraFile(path);
  EXPECT_EQ(r.fx, c.fx);
  EXPECT_EQ(r.fy, c.fy);
  EXPECT_EQ(r.cx, c.cx);
  EXPECT_EQ(r.cy, c.cy);
  EXPECT_EQ(r.width, c.width);
  EXPECT_EQ(r.height, c.height);
  EXPECT_EQ(r.depth_scale, c.depth_scale);
}

TEST(Camera, BadFilesNameFileAndLine) {
  auto expect_error = [](const std::string& path, const std::string& needle) {
    try {
      readCameraFile(path);
      FAIL() << "no error for " << path;
    } catch (const std::runtime_error& e) {
      EXPECT_NE(std::string(e.what()).find(needle), std::string::npos) << e.what();
    }
  };
  expect_error(tempFile("a.txt", "fx 500\nfy\n"), "a.txt:2");
  expect_error(tempFile("b.txt", "fx 500\nfoo 3\n"), "unknown key 'foo'");
  expect_error(tempFile("c.txt", "fx 500\nfy 500\ncx 1\ncy 1\nwidth 10\n"), "missing key 'height'");
  expect_error(tempFile("d.txt", "fx 0\nfy 500\ncx 1\ncy 1\nwidth 10\nheight 10\n"), "fx");
  expect_error("/nonexistent/camera.txt", "cannot open");
  // Found by fuzzing: a size beyond int's range was cast (undefined behaviour) before the check.
  expect_error(tempFile("e.txt", "fx 42\nfy 42\ncx 1\ncy 1\nwidth 1e87\nheight 10\n"),
               "width must be a whole number in 1..8192");
  expect_error(tempFile("f.txt", "fx 42\nfy 42\ncx 1\ncy 1\nwidth 10\nheight 2.5\n"),
               "height must be a whole number");
}

}  // namespace
}  // namespace nidevo

namespace nidevo {
namespace {

TEST(Camera, TumPresetsCarryTheirDistortionAndItRoundTripsWithinAHundredthOfAPixel) {
  EXPECT_TRUE(cameraPreset("tum_fr3")->distortion.none());
  EXPECT_TRUE(cameraPreset("icl")->distortion.none());
  for (const char* name : {"tum_fr1", "tum_fr2"}) {
    const Camera cam = *cameraPreset(name);
    ASSERT_FALSE(cam.distortion.none()) << name;
    double worst = 0;
    for (int v = 0; v < cam.height; v += 4) {
      for (int u = 0; u < cam.width; u += 4) {
        const Eigen::Vector2d d((u - cam.cx) / cam.fx, (v - cam.cy) / cam.fy);
        const Eigen::Vector2d back = cam.distortion.distort(cam.distortion.undistort(d));
        worst =
            std::max(worst, std::hypot((back.x() - d.x()) * cam.fx, (back.y() - d.y()) * cam.fy));
      }
    }
    EXPECT_LT(worst, 0.01) << name;
  }
}

TEST(Camera, ExpandedRaysAreTheSeparableOnesWithoutDistortionAndUndistortedWithIt) {
  const std::vector<float> columns = {-0.5f, 0.f, 0.4f}, rows = {-0.3f, 0.2f};
  std::vector<float> rx, ry;
  expandRays(Distortion{}, columns, rows, &rx, &ry);
  ASSERT_EQ(rx.size(), 6u);
  for (size_t v = 0; v < 2; ++v) {
    for (size_t u = 0; u < 3; ++u) {
      EXPECT_EQ(rx[v * 3 + u], columns[u]);
      EXPECT_EQ(ry[v * 3 + u], rows[v]);
    }
  }
  const Distortion d = cameraPreset("tum_fr1")->distortion;
  expandRays(d, columns, rows, &rx, &ry);
  const Eigen::Vector2d corner = d.distort({rx[0], ry[0]});
  EXPECT_NEAR(corner.x(), columns[0], 1e-6);
  EXPECT_NEAR(corner.y(), rows[0], 1e-6);
  EXPECT_GT(std::abs(rx[0] - columns[0]), 1e-3);  // the corner ray really moved
}

}  // namespace
}  // namespace nidevo
