#pragma once
// Stage 1: dense normal map from depth (paper Eq. 4), smoothed by a box filter that ignores
// pixels without a normal.
#include <Eigen/Core>
#include <vector>

#include "nidevo/odometry/camera.hpp"
#include "nidevo/odometry/image.hpp"

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

// The undistorted viewing ray (x/z, y/z) of every pixel of a normal map: pixel (u, v) of the map
// is pixel (stride*u, stride*v) of the camera's image. Built once per camera, apart from the
// builder's scratch: undistorting every pixel (Newton) is too slow for every frame, and a
// builder may serve sessions with different cameras.
struct PixelRays {
  PixelRays(const Camera& camera, int stride);
  int width = 0;
  int height = 0;
  int stride = 1;
  std::vector<float> x, y;  // row-major, width x height
};

// Owns the scratch buffers so that repeated calls do not allocate. Holds nothing of a frame or a
// camera between calls, so one builder can serve every session a thread runs.
class NormalMapBuilder {
 public:
  // depth: metres, 0 = missing, of the image `rays` were built for (else std::invalid_argument).
  // Depth outside [min_depth, max_depth] counts as missing.
  void compute(const DepthImageF& depth, const PixelRays& rays, int cell_size,
               float depth_discontinuity, float min_depth, float max_depth, float crease_dot,
               NormalMap* out);

 private:
  static float* rowOf(std::vector<float>& plane, int width, int v);
  static const float* rowOf(const std::vector<float>& plane, int width, int v);
  void backProject(const DepthImageF& depth, const PixelRays& rays, float min_depth,
                   float max_depth, NormalMap* out);
  void rawNormals(const PixelRays& rays, float depth_discontinuity);
  void boxFilter(int width, int height, int cell_size, NormalMap* out);
  void markSmooth(int width, int height, float crease_dot, NormalMap* out);

  // Planes of floats (one per component) rather than Vector3f, so that the per-pixel loops
  // vectorise; each holds one value per map pixel.
  std::vector<float> z_;             // depth, 0 where missing
  std::vector<float> nx_, ny_, nz_;  // Eq. 4 normal, then (after the box filter) the smoothed
  std::vector<uint8_t> has_normal_;  // Eq. 4 gave a normal
  std::vector<float> hx_, hy_, hz_;  // horizontal box sums
  std::vector<float> sum_x_, sum_y_, sum_z_;  // vertical running sums, one per column
};

}  // namespace nidevo
