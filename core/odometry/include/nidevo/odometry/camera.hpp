#pragma once
#include <Eigen/Core>
#include <string>

namespace nidevo {

// Pinhole camera; fy may be negative (ICL-NUIM), nothing here assumes fy > 0.
struct Camera {
  double fx = 481.2;
  double fy = -480.0;
  double cx = 319.5;
  double cy = 239.5;
  int width = 640;
  int height = 480;
  double depth_scale = 5000.0;  // raw units per metre for 16-bit depth

  // Empty when valid, otherwise a message naming the bad field.
  [[nodiscard]] std::string validate() const;
  // Empty when an image of this size fits the camera, else "image is WxH but the camera is WxH".
  [[nodiscard]] std::string checkImageSize(int image_width, int image_height) const;

  Eigen::Vector3f backproject(float u, float v, float z) const {
    return {float((u - cx) / fx) * z, float((v - cy) / fy) * z, z};
  }
  Eigen::Vector2d project(const Eigen::Vector3d& p) const {
    return {fx * p.x() / p.z() + cx, fy * p.y() / p.z() + cy};
  }
  // Intrinsics of the image subsampled by `factor` (pixel (u,v) -> (factor*u, factor*v)).
  Camera subsampled(int factor) const;
};

}  // namespace nidevo
