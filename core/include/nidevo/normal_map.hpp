#pragma once
// Stage 1: dense normal map from depth (paper Eq. 4), smoothed by a box filter that ignores
// pixels without a normal.
#include <Eigen/Core>
#include <vector>

#include "nidevo/camera.hpp"
#include "nidevo/image.hpp"

namespace nidevo {

struct NormalMap {
  int width = 0;
  int height = 0;
  std::vector<Eigen::Vector3f> normal;  // unit, towards the camera; meaningful where valid
  std::vector<uint8_t> valid;
  std::vector<Eigen::Vector3f> points;  // back-projected points of the map's pixels, z = 0 if none
  std::vector<uint8_t> smooth;          // valid, and every 4-neighbour's normal within crease_dot
  void resize(int w, int h);
  int validCount() const;
};

// Owns the scratch buffers so that repeated calls do not allocate.
class NormalMapBuilder {
 public:
  // depth: metres, 0 = missing. stride: subsampling of the depth image (pixel (u,v) of the map
  // is depth pixel (stride*u, stride*v)). Depth outside [min_depth, max_depth] counts as missing.
  void compute(const DepthImageF& depth, const Camera& camera, int stride, int cell_size,
               float depth_discontinuity, float min_depth, float max_depth, float crease_dot,
               NormalMap* out);

 private:
  std::vector<Eigen::Vector4f> raw_;  // xyz normal + 1 where valid, 0 elsewhere
  std::vector<Eigen::Vector4f> tmp_;  // horizontal box sums
  std::vector<Eigen::Vector4f> column_sums_;
  std::vector<float> ray_x_, ray_y_;  // (u - cx) / fx per column, (v - cy) / fy per row
};

}  // namespace nidevo
