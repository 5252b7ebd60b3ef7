#include "nidevo/odometry/normal_map.hpp"

#include <gtest/gtest.h>

#include <Eigen/Geometry>
#include <algorithm>
#include <cmath>
#include <stdexcept>
#include <string>

#include "nidevo/io/camera_io.hpp"

namespace nidevo {
namespace {

// Depth of the plane n.p = -d seen through the camera: z = -d / (n . ray) with ray = (x, y, 1).
DepthImageF planeDepth(const Camera& cam, const Eigen::Vector3f& n, float d) {
  DepthImageF depth(cam.width, cam.height, 0.f);
  for (int v = 0; v < cam.height; ++v) {
    for (int u = 0; u < cam.width; ++u) {
      // The pixel's true ray: through the lens distortion when the camera has one.
      const Eigen::Vector2d xy =
          cam.distortion.undistort({(u - cam.cx) / cam.fx, (v - cam.cy) / cam.fy});
      const Eigen::Vector3f ray(float(xy.x()), float(xy.y()), 1.f);
      const float z = -d / n.dot(ray);
      depth.at(u, v) = z > 0 && z < 20 ? z : 0.f;
    }
  }
  return depth;
}

double angleDeg(const Eigen::Vector3f& a, const Eigen::Vector3f& b) {
  return std::acos(std::clamp(double(a.normalized().dot(b.normalized())), -1.0, 1.0)) * 180 / M_PI;
}

// The builder's row kernels are written for the vectoriser; this is Eq. 4 and the box filter
// written plainly with Eigen, pixel by pixel. The two must agree bit for bit.
void referenceNormalMap(const DepthImageF& depth, const Camera& camera, int stride, int cell_size,
                        float jump, float min_depth, float max_depth, float crease_dot,
                        NormalMap* out) {
  const Camera cam = camera.subsampled(stride);
  const int W = depth.width / stride, H = depth.height / stride;
  out->resize(W, H);
  for (int v = 0; v < H; ++v) {
    for (int u = 0; u < W; ++u) {
      float z = depth.at(u * stride, v * stride);
      if (!(z >= min_depth && z <= max_depth)) z = 0.f;
      const float rx = float((float(u) - cam.cx) / cam.fx),
                  ry = float((float(v) - cam.cy) / cam.fy);
      out->points[size_t(v) * W + u] = Eigen::Vector3f(rx * z, ry * z, z);
    }
  }
  std::vector<Eigen::Vector4f> raw(size_t(W) * H, Eigen::Vector4f::Zero());
  auto usable = [&](const Eigen::Vector3f& p, float z0) {
    return p.z() > 0.f && std::abs(p.z() - z0) <= jump * z0;
  };
  for (int v = 1; v < H - 1; ++v) {
    for (int u = 1; u < W - 1; ++u) {
      const size_t i = size_t(v) * W + u;
      const Eigen::Vector3f& p = out->points[i];
      if (p.z() <= 0.f) continue;
      const auto &l = out->points[i - 1], &r = out->points[i + 1], &t = out->points[i - W],
                 &b = out->points[i + W];
      if (!usable(l, p.z()) || !usable(r, p.z()) || !usable(t, p.z()) || !usable(b, p.z()))
        continue;
      Eigen::Vector3f nrm = (r - l).cross(b - t);
      const float len = nrm.norm();
      if (!(len > 0.f)) continue;
      nrm /= len;
      if (nrm.dot(p) > 0.f) nrm = -nrm;
      raw[i] = Eigen::Vector4f(nrm.x(), nrm.y(), nrm.z(), 1.f);
    }
  }
  const int lo = cell_size / 2, hi = cell_size - 1 - lo;
  std::vector<Eigen::Vector4f> horizontal(raw.size());
  for (int v = 0; v < H; ++v) {
    Eigen::Vector4f acc = Eigen::Vector4f::Zero();
    for (int u = 0; u <= std::min(hi, W - 1); ++u) acc += raw[size_t(v) * W + u];
    for (int u = 0; u < W; ++u) {
      horizontal[size_t(v) * W + u] = acc;
      if (u + hi + 1 < W) acc += raw[size_t(v) * W + u + hi + 1];
      if (u - lo >= 0) acc -= raw[size_t(v) * W + u - lo];
    }
  }
  std::vector<Eigen::Vector4f> column(size_t(W), Eigen::Vector4f::Zero());
  for (int v = 0; v <= std::min(hi, H - 1); ++v)
    for (int u = 0; u < W; ++u) column[u] += horizontal[size_t(v) * W + u];
  for (int v = 0; v < H; ++v) {
    for (int u = 0; u < W; ++u) {
      const size_t i = size_t(v) * W + u;
      const Eigen::Vector3f sum = column[u].head<3>();
      const float len = sum.norm();
      out->valid[i] = raw[i].w() > 0.f && len > 1e-6f;
      out->normal[i] = out->valid[i] ? Eigen::Vector3f(sum / len) : Eigen::Vector3f::Zero();
    }
    if (v + hi + 1 < H)
      for (int u = 0; u < W; ++u) column[u] += horizontal[size_t(v + hi + 1) * W + u];
    if (v - lo >= 0)
      for (int u = 0; u < W; ++u) column[u] -= horizontal[size_t(v - lo) * W + u];
  }
  std::fill(out->smooth.begin(), out->smooth.end(), uint8_t(0));
  for (int v = 1; v < H - 1; ++v) {
    for (int u = 1; u < W - 1; ++u) {
      const size_t i = size_t(v) * W + u;
      bool ok = out->valid[i];
      for (size_t j : {i - 1, i + 1, i - size_t(W), i + size_t(W)})
        ok = ok && out->valid[j] && out->normal[i].dot(out->normal[j]) >= crease_dot;
      out->smooth[i] = ok;
    }
  }
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
  builder.compute(depth, PixelRays(cam, stride), 10, 0.05f, 0.1f, 10.f, 0.999f, &map);
  ASSERT_EQ(map.width, cam.width / stride);
  int checked = 0;
  double worst = 0;
  for (size_t i = 0; i < map.normal.size(); ++i) {
    if (!map.valid[i]) continue;
    worst = std::max(worst, angleDeg(map.normal[i], n));
    ++checked;
  }
  EXPECT_GT(checked, int(double(map.normal.size()) * 0.8));
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
  builder.compute(depth, PixelRays(cam, 1), 5, 0.05f, 0.1f, 10.f, 0.999f, &map);
  EXPECT_FALSE(map.valid[size_t(240) * map.width + 320]);
  EXPECT_FALSE(map.valid[size_t(240) * map.width + 319]);
  EXPECT_TRUE(map.valid[size_t(240) * map.width + 100]);
  EXPECT_TRUE(map.smooth[size_t(240) * map.width + 100]);
  EXPECT_FALSE(map.smooth[size_t(240) * map.width + 318]);  // next to an invalid pixel
}

TEST(NormalMap, EqualsThePlainPerPixelComputationBitForBit) {
  // An odd-sized camera (rows not a multiple of the vector width) over a bumpy scene with
  // holes, NaN, out-of-range depth and depth steps.
  Camera cam = *cameraPreset("icl");
  cam.width = 203;
  cam.height = 117;
  cam.cx = 101.3;
  cam.cy = 57.9;
  DepthImageF depth(cam.width, cam.height, 0.f);
  for (int v = 0; v < cam.height; ++v) {
    for (int u = 0; u < cam.width; ++u) {
      float z = 2.f + 0.3f * std::sin(0.11f * float(u)) * std::cos(0.07f * float(v)) +
                (u > 120 ? 0.6f : 0.f) + 0.002f * float((u * 7919 + v * 104729) % 13);
      if ((u * 31 + v * 17) % 97 == 0) z = 0.f;
      if ((u * 13 + v * 29) % 211 == 0) z = std::nanf("");
      if (u < 6 && v < 6) z = 50.f;
      depth.at(u, v) = z;
    }
  }
  for (int stride : {1, 2, 3}) {  // 3: a stride known at run time only
    for (int cell : {1, 5, 10}) {
      SCOPED_TRACE("stride " + std::to_string(stride) + ", cell " + std::to_string(cell));
      NormalMapBuilder builder;
      NormalMap fast, plain;
      builder.compute(depth, PixelRays(cam, stride), cell, 0.05f, 0.1f, 10.f, 0.999f, &fast);
      referenceNormalMap(depth, cam, stride, cell, 0.05f, 0.1f, 10.f, 0.999f, &plain);
      ASSERT_EQ(fast.width, plain.width);
      ASSERT_EQ(fast.height, plain.height);
      EXPECT_GT(plain.validCount(), plain.width * plain.height / 2);
      int differing = 0;
      for (size_t i = 0; i < plain.normal.size(); ++i) {
        differing += fast.valid[i] != plain.valid[i] || fast.smooth[i] != plain.smooth[i] ||
                     (plain.valid[i] && fast.normal[i] != plain.normal[i]) ||
                     fast.points[i] != plain.points[i];
      }
      EXPECT_EQ(differing, 0);
    }
  }
}

// One builder serves every session a worker runs: maps from one builder that alternates between
// cameras (sizes, distortion) equal those of a builder used for one camera only.
TEST(NormalMap, OneBuilderServesCamerasInTurnAsFreshBuildersDo) {
  const Camera icl = *cameraPreset("icl"), fr1 = *cameraPreset("tum_fr1");
  Camera small = icl.subsampled(2);
  const Eigen::Vector3f n = Eigen::Vector3f(0.2f, -0.4f, -1.f).normalized();
  struct Case {
    Camera cam;
    int stride;
  };
  const Case cases[] = {{fr1, 2}, {small, 1}, {icl, 2}, {fr1, 2}, {small, 1}};
  NormalMapBuilder shared;
  for (const Case& c : cases) {
    SCOPED_TRACE(std::to_string(c.cam.width) + "x" + std::to_string(c.cam.height));
    const DepthImageF depth = planeDepth(c.cam, n, 2.f);
    const PixelRays rays(c.cam, c.stride);
    NormalMap from_shared, from_fresh;
    shared.compute(depth, rays, 10, 0.05f, 0.1f, 10.f, 0.999f, &from_shared);
    NormalMapBuilder().compute(depth, rays, 10, 0.05f, 0.1f, 10.f, 0.999f, &from_fresh);
    ASSERT_GT(from_fresh.validCount(), from_fresh.width * from_fresh.height / 2);
    EXPECT_EQ(from_shared.normal, from_fresh.normal);
    EXPECT_EQ(from_shared.valid, from_fresh.valid);
    EXPECT_EQ(from_shared.points, from_fresh.points);
    EXPECT_EQ(from_shared.smooth, from_fresh.smooth);
  }
}

TEST(NormalMap, DepthOfAnotherSizeThanTheRaysIsRefusedByName) {
  const Camera cam = *cameraPreset("icl");
  NormalMap map;
  try {
    NormalMapBuilder().compute(DepthImageF(320, 240, 1.f), PixelRays(cam, 2), 10, 0.05f, 0.1f, 10.f,
                               0.999f, &map);
    FAIL() << "no exception";
  } catch (const std::invalid_argument& e) {
    EXPECT_EQ(
        std::string(e.what()),
        "normal map: depth 320x240 at stride 2 gives a 160x120 map, the rays are for 320x240");
  }
}

TEST(NormalMap, NoValidDepthGivesNoNormals) {
  const Camera cam = *cameraPreset("icl");
  NormalMapBuilder builder;
  NormalMap map;
  builder.compute(DepthImageF(cam.width, cam.height, 0.f), PixelRays(cam, 2), 10, 0.05f, 0.1f, 10.f,
                  0.999f, &map);
  EXPECT_EQ(map.validCount(), 0);
}

}  // namespace
}  // namespace nidevo
