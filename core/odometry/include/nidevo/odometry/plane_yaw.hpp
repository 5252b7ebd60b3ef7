#pragma once
// One plane fixes two of the rotation's three directions (stage 2); the turn about its normal was
// the prediction's. The grey values on the plane measure it: the directions of their gradients,
// taken on the plane, turn with the camera about the normal and do not move with a translation.
// Non-iterative, like the method: one weighted histogram of directions per frame and a circular
// correlation of the two.
#include <Eigen/Geometry>
#include <vector>

#include "nidevo/odometry/camera.hpp"
#include "nidevo/odometry/normal_map.hpp"

namespace nidevo {

struct PlaneYawParams {
  int bins = 120;           // over the full turn
  int pixel_step = 2;       // every n-th map pixel in u and v
  float plane_dot = 0.97f;  // a pixel is on the plane when its normal is this close
  // Grey gradients are taken on the image smoothed by a binomial of this radius (0: none): a
  // sharp edge's central differences point along the pixel grid, not across the edge.
  int smooth_radius = 7;
  float min_gradient = 0.01f;  // grey step per map pixel below which the direction is noise
  // A map pixel covering more of the plane than this (metres) sees texture finer than itself:
  // its gradients follow the pixel grid (aliasing), not the plane.
  float max_footprint_m = 0.1f;
  int min_pixels = 400;        // on the plane with a gradient, in each frame
  float min_ncc = 0.6f;        // the histograms' correlation at the chosen turn
  float max_turn_rad = 0.35f;  // the turn searched, either way
};

// A plane as seen from one frame: its normal in that frame's camera, and the rotation into the
// frame the directions are compared in (the keyframe's).
struct PlaneView {
  const NormalMap* map = nullptr;
  const float* intensity = nullptr;  // one per map pixel
  Eigen::Vector3f normal = Eigen::Vector3f::UnitZ();
  Eigen::Matrix3f R_key_cam = Eigen::Matrix3f::Identity();
};

struct PlaneYaw {
  bool measured = false;
  double turn_rad = 0;  // about the keyframe's normal, applied after the current view's R_key_cam
  double ncc = 0;       // of the two histograms at that turn
  int key_pixels = 0, cur_pixels = 0;
};

// Owns the histograms, so that repeated calls do not allocate.
class PlaneYawEstimator {
 public:
  // The turn Rot(key.normal, turn) that, applied after cur.R_key_cam, lines the current frame's
  // gradient directions up with the keyframe's. key.R_key_cam must be the identity and
  // cur.R_key_cam must map cur.normal onto key.normal.
  PlaneYaw estimate(const PlaneView& key, const PlaneView& cur, const Camera& map_camera,
                    const PlaneYawParams& p);

  // Bin k of the full turn holds the weight of directions near k * 2 pi / bins, measured from
  // the first axis of the plane's basis (e1, n x e1) in the keyframe. Returns the pixels used.
  int histogram(const PlaneView& view, const Eigen::Vector3f& e1, const Eigen::Vector3f& e2,
                const Camera& map_camera, const PlaneYawParams& p, std::vector<float>* bins);

 private:
  // The grey values smoothed over the pixels with depth (normalised convolution), into grey_.
  void smoothGrey(const PlaneView& view, int radius);

  std::vector<float> key_, cur_;
  std::vector<float> grey_, mask_, row_grey_, row_mask_;
};

}  // namespace nidevo
