#pragma once
// A rendered frame's normal map and grey values at the map's pixels, as the odometry has them:
// the inputs of the pose check's alignment, for its tests.
#include <vector>

#include "nidevo/odometry/camera.hpp"
#include "nidevo/odometry/image.hpp"
#include "nidevo/odometry/normal_map.hpp"
#include "nidevo/odometry/odometry_config.hpp"

namespace nidevo::test {

struct MapFrame {
  NormalMap map;
  std::vector<float> intensity;
};

inline MapFrame mapOf(const RgbdFrame& frame, const Camera& camera, const OdometryConfig& c) {
  MapFrame out;
  NormalMapBuilder builder;
  builder.compute(frame.depth, PixelRays(camera, c.normal_stride), c.cell_size,
                  c.depth_discontinuity, c.min_depth_m, c.max_depth_m, c.crease_dot, &out.map);
  out.intensity.resize(out.map.normal.size());
  for (int v = 0; v < out.map.height; ++v)
    for (int u = 0; u < out.map.width; ++u)
      out.intensity[size_t(v * out.map.width + u)] =
          float(frame.gray.at(u * c.normal_stride, v * c.normal_stride)) / 255.f;
  return out;
}

}  // namespace nidevo::test
