#include "nidevo/odometry/camera.hpp"

#include <cmath>

namespace nidevo {

std::string Camera::validate() const {
  auto bad_focal = [](double f) { return !std::isfinite(f) || std::abs(f) < 1e-6; };
  if (bad_focal(fx)) return "fx must be finite and non-zero";
  if (bad_focal(fy)) return "fy must be finite and non-zero";
  if (width <= 0 || width > 8192) return "width must be in 1..8192";
  if (height <= 0 || height > 8192) return "height must be in 1..8192";
  if (!std::isfinite(cx) || cx < -width || cx > 2.0 * width) return "cx is far outside the image";
  if (!std::isfinite(cy) || cy < -height || cy > 2.0 * height) return "cy is far outside the image";
  if (!std::isfinite(depth_scale) || depth_scale <= 0) return "depth_scale must be positive";
  return {};
}

std::string Camera::checkImageSize(int image_width, int image_height) const {
  if (image_width == width && image_height == height) return {};
  return "image is " + std::to_string(image_width) + "x" + std::to_string(image_height) +
         " but the camera is " + std::to_string(width) + "x" + std::to_string(height);
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
