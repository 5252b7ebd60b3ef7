#include "nidevo/odometry/camera.hpp"

#include <Eigen/LU>
#include <cmath>

namespace nidevo {

// Newton's method on distort(p) = d from p = d, with the Jacobian by central differences; it
// stays where a fixed-point iteration diverges (strong distortion near the image corners).
Eigen::Vector2d Distortion::undistort(const Eigen::Vector2d& d) const {
  Eigen::Vector2d p = d;
  constexpr double kStep = 1e-6;
  for (int i = 0; i < 20; ++i) {
    const Eigen::Vector2d residual = distort(p) - d;
    if (residual.squaredNorm() < 1e-24) break;
    Eigen::Matrix2d J;
    J.col(0) = (distort(p + Eigen::Vector2d(kStep, 0)) - distort(p - Eigen::Vector2d(kStep, 0))) /
               (2 * kStep);
    J.col(1) = (distort(p + Eigen::Vector2d(0, kStep)) - distort(p - Eigen::Vector2d(0, kStep))) /
               (2 * kStep);
    p -= J.inverse() * residual;
  }
  return p;
}

std::string Camera::validate() const {
  auto bad_focal = [](double f) { return !std::isfinite(f) || std::abs(f) < 1e-6; };
  if (bad_focal(fx)) return "fx must be finite and non-zero";
  if (bad_focal(fy)) return "fy must be finite and non-zero";
  if (width <= 0 || width > 8192) return "width must be in 1..8192";
  if (height <= 0 || height > 8192) return "height must be in 1..8192";
  if (!std::isfinite(cx) || cx < -width || cx > 2.0 * width) return "cx is far outside the image";
  if (!std::isfinite(cy) || cy < -height || cy > 2.0 * height) return "cy is far outside the image";
  if (!std::isfinite(depth_scale) || depth_scale <= 0) return "depth_scale must be positive";
  for (double k : {distortion.k1, distortion.k2, distortion.p1, distortion.p2, distortion.k3})
    if (!std::isfinite(k) || std::abs(k) > 10)
      return "distortion coefficients must be in [-10, 10]";
  return {};
}

std::string Camera::checkImageSize(int image_width, int image_height) const {
  if (image_width == width && image_height == height) return {};
  return "image is " + std::to_string(image_width) + "x" + std::to_string(image_height) +
         " but the camera is " + std::to_string(width) + "x" + std::to_string(height);
}

void expandRays(const Distortion& d, const std::vector<float>& column_ray,
                const std::vector<float>& row_ray, std::vector<float>* ray_x,
                std::vector<float>* ray_y) {
  const size_t W = column_ray.size(), H = row_ray.size();
  ray_x->resize(W * H);
  ray_y->resize(W * H);
  for (size_t v = 0; v < H; ++v) {
    for (size_t u = 0; u < W; ++u) {
      float x = column_ray[u], y = row_ray[v];
      if (!d.none()) {
        const Eigen::Vector2d ideal = d.undistort(Eigen::Vector2d(x, y));
        x = float(ideal.x());
        y = float(ideal.y());
      }
      (*ray_x)[v * W + u] = x;
      (*ray_y)[v * W + u] = y;
    }
  }
}

Camera Camera::subsampled(int factor) const {
  Camera c = *this;
  c.fx = fx / factor;
  c.fy = fy / factor;
  c.cx = cx / factor;
  c.cy = cy / factor;
  c.width = width / factor;
  c.height = height / factor;
  return c;
}

}  // namespace nidevo
