#include "nidevo/normal_map.hpp"

#include <gtest/gtest.h>

#include <cmath>

namespace nidevo {
namespace {

// Depth of the plane n.p = -d seen through the camera: z = -d / (n . ray) with ray = (x, y, 1).
DepthImageF planeDepth(const Camera& cam, const Eigen::Vector3f& n, float d) {
  DepthImageF depth(cam.width, cam.height, 0.f);
  for (int v = 0; v < cam.height; ++v) {
    for (int u = 0; u < cam.width; ++u) {
      const Eigen::Vector3f ray(float((u - cam.cx) / cam.fx), float((v - cam.cy) / cam.fy), 1.f);
      const float z = -d / n.dot(ray);
      depth.at(u, v) = z > 0 && z < 20 ? z : 0.f;
    }
  }
  return depth;
}

double angleDeg(const Eigen::Vector3f& a, const Eigen::Vector3f& b) {
  return std::acos(std::clamp(double(a.normalized().dot(b.normalized())), -1.0, 1.0)) * 180 / M_PI;
}

class NormalMapPlanes : public ::testing::TestWithParam<std::tuple<const char*, int>> {};

TEST_P(NormalMapPlanes, SmoothedNormalsOfARenderedPlaneAreWithinHalfADegree) {
  const Camera cam = *cameraPreset(std::get<0>(GetParam()));
  const int stride = std::get<1>(GetParam());
  // A tilted wall 2.5 m ahead, normal towards the camera.
  const Eigen::Vector3f n = Eigen::Vector3f(0.3f, -0.2f, -1.f).normalized();
  DepthImageF depth = planeDepth(cam, n, 2.5f);
  // Holes: missing depth must be ignored, not averaged in.
  for (int v = 100; v < 140; ++v)
    for (int u = 200; u < 260; ++u) depth.at(u, v) = 0.f;
  NormalMapBuilder builder;
  NormalMap map;
  builder.compute(depth, cam, stride, 10, 0.05f, 0.1f, 10.f, 0.999f, &map);
  ASSERT_EQ(map.width, cam.width / stride);
  int checked = 0;
  double worst = 0;
  for (size_t i = 0; i < map.normal.size(); ++i) {
    if (!map.valid[i]) continue;
    worst = std::max(worst, angleDeg(map.normal[i], n));
    ++checked;
  }
  EXPECT_GT(checked, int(map.normal.size() * 0.8));
  EXPECT_LT(worst, 0.5);
  // Pixels inside the hole have no normal.
  EXPECT_FALSE(map.valid[size_t(120 / stride) * map.width + size_t(230 / stride)]);
}

INSTANTIATE_TEST_SUITE_P(Cameras, NormalMapPlanes,
                         ::testing::Combine(::testing::Values("icl", "icl_fy_positive", "tum_fr1"),
                                            ::testing::Values(1, 2)));

TEST(NormalMap, DepthDiscontinuityBreaksNormalsAndCreasesAreMarked) {
  const Camera cam = *cameraPreset("icl");
  DepthImageF depth(cam.width, cam.height, 2.f);
  for (int v = 0; v < cam.height; ++v)
    for (int u = 320; u < cam.width; ++u) depth.at(u, v) = 3.f;  // a step
  NormalMapBuilder builder;
  NormalMap map;
  builder.compute(depth, cam, 1, 5, 0.05f, 0.1f, 10.f, 0.999f, &map);
  EXPECT_FALSE(map.valid[size_t(240) * map.width + 320]);
  EXPECT_FALSE(map.valid[size_t(240) * map.width + 319]);
  EXPECT_TRUE(map.valid[size_t(240) * map.width + 100]);
  EXPECT_TRUE(map.smooth[size_t(240) * map.width + 100]);
  EXPECT_FALSE(map.smooth[size_t(240) * map.width + 318]);  // next to an invalid pixel
}

TEST(NormalMap, NoValidDepthGivesNoNormals) {
  const Camera cam = *cameraPreset("icl");
  NormalMapBuilder builder;
  NormalMap map;
  builder.compute(DepthImageF(cam.width, cam.height, 0.f), cam, 2, 10, 0.05f, 0.1f, 10.f, 0.999f,
                  &map);
  EXPECT_EQ(map.validCount(), 0);
}

}  // namespace
}  // namespace nidevo
