#pragma once
// Stage 2a: planes seen in both the keyframe and the current normal map, found pixel by pixel
// (paper Alg. 1): overlapping co-planar pixels grouped into modes, one median normal per frame.
#include <Eigen/Core>
#include <string>
#include <vector>

#include "nidevo/odometry/camera.hpp"
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
  int pixel_step;      // every n-th pixel of the current map in u and v
};

// The predicted rotation between the frames, so that a pixel of the current frame is compared
// with the keyframe pixel that saw the same direction, and its normal after that rotation: a
// fast turn is then not a different plane. Translation is left out (small against depth over a
// keyframe's few frames).
struct PlaneWarp {
  Eigen::Matrix3f R_key_cur;  // current-camera vectors into the keyframe camera
  Camera map_camera;          // the normal map's camera, with its lens
};

struct PlaneTrackingResult {
  int overlap_pixels = 0;         // pixels co-planar in both frames (of the map: scaled up from
                                  // those read)
  std::vector<PlanePair> planes;  // modes with at least min_plane_pixels read, largest first
};

struct Pinhole;  // lens_projection.hpp, private to the library

class PlaneTracker {
 public:
  // key and cur must have the same size. Without a warp a pixel is compared with the same pixel
  // of the keyframe (the paper). Reuses its buffers; `out->planes` keeps its capacity.
  void track(const NormalMap& key, const NormalMap& cur, const PlaneTrackingParams& params,
             PlaneTrackingResult* out, const PlaneWarp* warp = nullptr);

 private:
  // warped_row_[j] for the first `count` pixels of smooth_row_: the keyframe pixel that saw the
  // direction of cur's pixel, or -1.
  void warpPixels(const NormalMap& cur, size_t count, const PlaneWarp& warp, const Pinhole& cam);
  Eigen::Vector3f medianNormal(const NormalMap& map, const int* pixels, size_t count);
  // key_pixels[k] in the keyframe and cur_pixels[k] in the current frame are one point.
  PlanePair fittedPair(const NormalMap& key, const NormalMap& cur, int* key_pixels, int* cur_pixels,
                       size_t count, const PlaneTrackingParams& params);

  std::vector<int> overlap_pixel_, overlap_cur_;
  std::vector<int8_t> overlap_mode_;
  std::vector<int> members_, members_cur_;
  std::vector<Eigen::Vector3f> seeds_;
  std::vector<int> counts_, offsets_;
  std::vector<float> scratch_, residual_;
  KthSmallest kth_smallest_;
  std::vector<int> histogram_;
  std::vector<int> smooth_row_, warped_row_;  // track: one row's smooth pixels, their warps
};

}  // namespace nidevo
