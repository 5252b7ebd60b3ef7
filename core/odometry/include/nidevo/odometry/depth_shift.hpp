#pragma once
// Stage 3c: translation along the projection axis (paper Eq. 18): the mean depth difference of
// well-matched cells once the current projection is shifted onto the keyframe's.
#include <vector>

#include "nidevo/odometry/ortho_projection.hpp"

namespace nidevo {

// Built from OdometryConfig by depthShiftParams() (odometry_config.hpp): no defaults here.
struct DepthShiftParams {
  float gray_tolerance;  // |grey_key - grey_cur| must be below
  float inlier_m;        // |difference - dz| must be below
  int iterations;
  int sample_step;  // use every n-th cell in u and v
  // Cells whose key surface is steeper than this (depth change per metre across the projection)
  // are skipped: for a surface seen edge-on the nearest point of a cell is where the field of
  // view cuts it, which moves with the camera and not with the scene. 0 disables the test.
  float max_slope;
  double resolution;  // m per cell of the translation keyframe, needed for the slope test
};

struct DepthShift {
  double dz = 0;    // depth_key - depth_cur of the same point (metres)
  int inliers = 0;  // 0: no estimate
};

class DepthShiftEstimator {
 public:
  // (du, dv): the KCC shift, cur(u) ~ key(u - d). The current images are sampled bilinearly at
  // key cell + d where all four neighbours have depth.
  DepthShift estimate(const OrthoImage& key, const OrthoImage& cur, double du, double dv,
                      const DepthShiftParams& params);

 private:
  std::vector<float> diffs_;
  std::vector<float> scratch_;
  KthSmallest kth_smallest_;
};

}  // namespace nidevo
