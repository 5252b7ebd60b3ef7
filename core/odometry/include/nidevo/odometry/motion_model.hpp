#pragma once
// Damped constant-velocity prediction for frames that cannot be measured: the last measured
// motion per frame, times the frames since the last update, shrunk by `decay` for every frame
// predicted since, so that a long stretch without measurements slows to a stop instead of
// spinning away.
//
// Frames are counted from the timestamps: a gap is the median of the recent frame gaps times a
// whole number. A sensor's jitter (a 30 Hz stream's gaps vary by +-20 %) then counts as one
// frame, and a dropped frame (by the sensor, or by the server's LATEST policy) as two, so that
// the motion over it is predicted twice as far. Without usable timestamps (none, or not
// increasing) every update is one frame.
#include <Eigen/Geometry>
#include <array>

namespace nidevo {

class MotionModel {
 public:
  explicit MotionModel(double decay = 0.7) : decay_(decay) {}

  bool empty() const { return !has_prev_; }
  // The pose at `timestamp` (seconds; identity before any update).
  Eigen::Isometry3d predict(double timestamp) const;
  // The last pose given to update() (identity before any update).
  const Eigen::Isometry3d& last() const { return prev_; }
  // measured: the pose came from the method, not from predict().
  void update(const Eigen::Isometry3d& pose, bool measured, double timestamp);
  void reset() { *this = MotionModel(decay_); }

  // Frames between two timestamps as the recent gaps count them: at least 1, at most
  // kMaxFrames (a longer pause is no reason to extrapolate further).
  double framesBetween(double from, double to) const;
  static constexpr double kMaxFrames = 4;

 private:
  double decay_;
  Eigen::Isometry3d prev_ = Eigen::Isometry3d::Identity();
  Eigen::Isometry3d velocity_ = Eigen::Isometry3d::Identity();  // over velocity_frames_ frames
  double velocity_frames_ = 1;
  double prev_timestamp_ = 0;
  bool has_prev_ = false;
  bool prev_measured_ = false;
  int predicted_since_ = 0;
  std::array<double, 15> gaps_{};  // the last gaps between updates, seconds (a ring)
  int gap_count_ = 0, gap_next_ = 0;
};

}  // namespace nidevo
