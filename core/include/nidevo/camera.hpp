#pragma once
#include <Eigen/Core>
#include <optional>
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
  std::string validate() const;

  Eigen::Vector3f backproject(float u, float v, float z) const {
    return {float((u - cx) / fx) * z, float((v - cy) / fy) * z, z};
  }
  Eigen::Vector2d project(const Eigen::Vector3d& p) const {
    return {fx * p.x() / p.z() + cx, fy * p.y() / p.z() + cy};
  }
  // Intrinsics of the image subsampled by `factor` (pixel (u,v) -> (factor*u, factor*v)).
  Camera subsampled(int factor) const;
};

// Built-in presets: "icl", "icl_fy_positive", "tum_fr1", "tum_fr2", "tum_fr3".
std::optional<Camera> cameraPreset(const std::string& name);
std::string cameraPresetNames();

// Text format: one "key value" pair per line (fx fy cx cy width height depth_scale), '#' comments.
// Throws std::runtime_error naming the file and line on any problem.
Camera readCameraFile(const std::string& path);
void writeCameraFile(const std::string& path, const Camera& camera);

}  // namespace nidevo
