#pragma once
// Stage 2a: planes seen in both the keyframe and the current normal map, found pixel by pixel
// (paper Alg. 1): overlapping co-planar pixels grouped into modes, one median normal per frame.
#include <Eigen/Core>
#include <string>
#include <vector>

#include "nidevo/odometry/normal_map.hpp"
#include "nidevo/odometry/selection.hpp"

namespace nidevo {

struct PlanePair {
  Eigen::Vector3f key;  // plane normal in the keyframe
  Eigen::Vector3f cur;  // the same plane's normal in the current frame
  int pixels = 0;
};

enum class PlaneNormalEstimator {
  kMedian,    // per-component median of the smoothed normals (the paper)
  kPlaneFit,  // least-squares plane through the member pixels' 3-D points (PCA)
};
PlaneNormalEstimator parsePlaneNormalEstimator(const std::string& name);  // median, fit
const char* toString(PlaneNormalEstimator e);

// Built from OdometryConfig by planeTrackingParams() (odometry_config.hpp): no defaults here.
struct PlaneTrackingParams {
  int border;  // in normal-map pixels
  float overlap_dot;
  float mode_dot;
  int min_plane_pixels;
  int max_modes;
  PlaneNormalEstimator estimator;
  float fit_cone_dot;  // kPlaneFit: members within this of the mode's median normal
};

struct PlaneTrackingResult {
  int overlap_pixels = 0;         // pixels co-planar in both frames
  std::vector<PlanePair> planes;  // modes with at least min_plane_pixels, largest first
};

class PlaneTracker {
 public:
  // key and cur must have the same size. Reuses its buffers; `out->planes` keeps its capacity.
  void track(const NormalMap& key, const NormalMap& cur, const PlaneTrackingParams& params,
             PlaneTrackingResult* out);

 private:
  Eigen::Vector3f medianNormal(const NormalMap& map, const int* pixels, size_t count);
  PlanePair fittedPair(const NormalMap& key, const NormalMap& cur, int* pixels, size_t count,
                       const PlaneTrackingParams& params);

  std::vector<int> overlap_pixel_;
  std::vector<int8_t> overlap_mode_;
  std::vector<int> members_;
  std::vector<Eigen::Vector3f> seeds_;
  std::vector<int> counts_, offsets_;
  std::vector<float> scratch_, residual_;
  KthSmallest kth_smallest_;
  std::vector<int> histogram_;
};

}  // namespace nidevo
