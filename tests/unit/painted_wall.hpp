#pragma once
// A flat wall with a texture of the test's choosing, as a camera sees it: scenes whose every
// direction of motion the test knows to be fixed or free.
#include <Eigen/Geometry>
#include <algorithm>
#include <cmath>

#include "nidevo/odometry/camera.hpp"
#include "nidevo/odometry/image.hpp"

namespace nidevo::test {

// A wall 2 m ahead, square to the optical axis, painted with grey(x, y) (0-255, x and y in metres
// on the wall), seen from a camera at `t` (no rotation): every pixel's grey value is that of the
// wall point its ray meets. `like` gives the frame's size and timestamp.
template <typename Paint>
RgbdFrame paintedWall(const Camera& cam, const RgbdFrame& like, const Eigen::Vector3d& t,
                      Paint grey) {
  RgbdFrame f = like;
  std::fill(f.depth.data.begin(), f.depth.data.end(), 2.f);
  for (int v = 0; v < cam.height; ++v) {
    for (int u = 0; u < cam.width; ++u) {
      const double x = (u - cam.cx) / cam.fx * 2 + t.x(), y = (v - cam.cy) / cam.fy * 2 + t.y();
      f.gray.at(u, v) = uint8_t(grey(x, y));
    }
  }
  return f;
}

// Bold stripes across y every 10 cm and faint ones across x every `x_period` metres: a wall then
// leaves depth three directions, bold ones for the grey values to fix and x for them to fix
// least.
inline auto boldAndFaintStripes(double x_period) {
  return [x_period](double x, double y) {
    return 128 + 60 * std::cos(2 * M_PI * y / 0.1) + 10 * std::cos(2 * M_PI * x / x_period);
  };
}

}  // namespace nidevo::test
