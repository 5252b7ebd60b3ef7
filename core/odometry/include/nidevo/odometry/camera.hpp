#pragma once
#include <Eigen/Core>
#include <string>
#include <vector>

namespace nidevo {

// Brown-Conrady lens distortion (OpenCV's and ROS "plumb_bob" order k1 k2 p1 p2 k3) on
// normalised image coordinates; all zero: none.
struct Distortion {
  double k1 = 0, k2 = 0, p1 = 0, p2 = 0, k3 = 0;

  bool none() const { return k1 == 0 && k2 == 0 && p1 == 0 && p2 == 0 && k3 == 0; }
  // Ideal (pinhole) normalised coordinates to distorted ones. Inline: the pose check calls it
  // for every point of every refinement step.
  Eigen::Vector2d distort(const Eigen::Vector2d& ideal) const {
    const double x = ideal.x(), y = ideal.y(), r2 = x * x + y * y;
    const double radial = 1 + r2 * (k1 + r2 * (k2 + r2 * k3));
    return {x * radial + 2 * p1 * x * y + p2 * (r2 + 2 * x * x),
            y * radial + p1 * (r2 + 2 * y * y) + 2 * p2 * x * y};
  }
  // The inverse, by Newton's method (to 1e-12 within the image of real lenses).
  Eigen::Vector2d undistort(const Eigen::Vector2d& distorted) const;
};

// Pinhole camera; fy may be negative (ICL-NUIM), nothing here assumes fy > 0.
struct Camera {
  double fx = 481.2;
  double fy = -480.0;
  double cx = 319.5;
  double cy = 239.5;
  int width = 640;
  int height = 480;
  double depth_scale = 5000.0;  // raw units per metre for 16-bit depth
  // Depth is registered to the (distorted) colour image; the odometry back-projects every pixel
  // through per-pixel undistorted rays (expandRays), the renderer distorts.
  Distortion distortion;

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

// Per-pixel normalised rays (row-major, column_ray.size() x row_ray.size()) of a grid whose pixel
// (u, v) has the distorted ray (column_ray[u], row_ray[v]); undistorted unless `d` is none, when
// they are the separable values exactly.
void expandRays(const Distortion& d, const std::vector<float>& column_ray,
                const std::vector<float>& row_ray, std::vector<float>* ray_x,
                std::vector<float>* ray_y);

}  // namespace nidevo
