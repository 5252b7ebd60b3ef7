#pragma once
// Synthetic RGB-D sequences with exact ground truth: ray-cast scenes, smooth handheld motion,
// optional ICL-NUIM-like sensor noise. Deterministic for a given config.
#include <Eigen/Geometry>
#include <string>
#include <vector>

#include "nidevo/io/trajectory.hpp"
#include "nidevo/odometry/camera.hpp"
#include "nidevo/odometry/image.hpp"
#include "nidevo/sim/scene.hpp"
#include "nidevo/sim/texture.hpp"

namespace nidevo::synth {

// kIclLike: ICL-NUIM-like disparity noise; kStructuredLight: a Kinect-like sensor, coarser
// disparity steps (so depth steps grow with the square of depth), holes at depth edges and on
// grazing or dark surfaces, a shorter range.
enum class SensorNoise { kNone, kIclLike, kStructuredLight };
SensorNoise parseSensorNoise(const std::string& name);  // none, icl, kinect
const char* toString(SensorNoise n);

struct SequenceConfig {
  std::string scene = "office";
  TextureRichness texture = TextureRichness::kRich;
  SensorNoise noise = SensorNoise::kNone;
  int frames = 300;
  double rate_hz = 30.0;
  double speed = 0.25;  // mean camera speed along the path, m/s
  uint64_t seed = 1;
  Camera camera = Camera{};  // ICL-NUIM intrinsics by default
  // ICL-like sensor model (used when noise == kIclLike).
  double max_range_m = 6.0;
  double min_incidence_cos = 0.12;          // depth lost at grazing angles below this cosine
  double disparity_focal_baseline = 35.13;  // px * m, Kinect-like
  double disparity_sigma_px = 0.05;
  double disparity_step_px = 1.0 / 16.0;
  double lateral_sigma_px = 0.5;
  double rgb_sigma = 3.0;  // 8-bit units
  // Structured-light sensor model (noise == kStructuredLight); disparity noise as above.
  double sl_disparity_step_px = 0.125;
  double sl_min_range_m = 0.5;
  double sl_max_range_m = 4.5;
  double sl_min_incidence_cos = 0.25;  // grazing surfaces give no depth
  double sl_dark_reflectance = 0.08;   // nor do dark ones (too little of the pattern returns)
  double sl_edge_jump = 0.04;          // relative depth jump to a neighbour that makes a hole
  // Auto-exposure: jumps of the image gain by a factor of 1 +- [min, max], this many per second
  // on average (0: none). The depth does not change.
  double exposure_jumps_per_s = 0;
  double exposure_jump_min = 0.1;
  double exposure_jump_max = 0.3;

  [[nodiscard]] std::string validate() const;  // empty when valid, else names the bad field
};

// The structured-light model's depth for a true depth and a disparity noise (px): disparity
// quantised to sl_disparity_step_px, so the depth step is about depth^2 * step / (f b).
double structuredLightDepth(double depth, double disparity_noise_px, const SequenceConfig& config);

// A rendered frame in full: colour for writing files, grey and depth for the odometry.
struct RenderedFrame {
  double timestamp = 0.0;
  std::vector<uint8_t> rgb;  // interleaved RGB, width * height * 3
  RgbdFrame frame;           // grey + depth (metres)
};

class SyntheticSequence {
 public:
  explicit SyntheticSequence(const SequenceConfig& config);

  const SequenceConfig& config() const { return config_; }
  const Scene& scene() const { return scene_; }
  int size() const { return config_.frames; }
  double timestamp(int i) const { return i / config_.rate_hz; }
  // T_world_cam of frame i (world: the scene frame, y up).
  Eigen::Isometry3d groundTruth(int i) const;
  Trajectory groundTruthTrajectory() const;

  RenderedFrame render(int i) const;
  // Renders an arbitrary pose; noise_index seeds the sensor noise.
  RenderedFrame renderAt(const Eigen::Isometry3d& T_world_cam, double timestamp,
                         uint64_t noise_index) const;
  RgbdFrame renderFrame(int i) const { return render(i).frame; }
  // Clean depth of an arbitrary pose, used by tests to check geometry.
  DepthImageF renderDepth(const Eigen::Isometry3d& T_world_cam) const;
  // Clean depth along the ray through a real-valued pixel (0 when nothing is hit).
  double depthAt(const Eigen::Isometry3d& T_world_cam, double u, double v) const;
  // Distance from a world point to the nearest scene rectangle.
  double distanceToScene(const Eigen::Vector3d& p_world) const;

  // Writes rgb/, depth/, rgb.txt, depth.txt, associations.txt, groundtruth.txt, camera.txt.
  void writeTumFolder(const std::string& folder) const;

 private:
  Eigen::Isometry3d poseAtTime(double t) const;
  // Normalised ray (z = 1) through pixel (u, v), through the lens distortion if there is one.
  Eigen::Vector2d rayAt(double u, double v) const;
  double exposureGain(uint64_t frame) const;
  SequenceConfig config_;
  Scene scene_;
  std::vector<Eigen::Vector2d> pixel_rays_;  // rayAt of every pixel when distorted, else empty
  std::vector<double> exposure_gain_;        // per frame
  std::vector<double> segment_end_time_;     // cumulative time at the end of each path segment
};

}  // namespace nidevo::synth
