#pragma once
// Damped constant-velocity prediction for frames that cannot be measured: the last measured
// frame-to-frame motion, shrunk by `decay` for every frame predicted since, so that a long
// stretch without measurements slows to a stop instead of spinning away.
#include <Eigen/Geometry>

namespace nidevo {

class MotionModel {
 public:
  explicit MotionModel(double decay = 0.7) : decay_(decay) {}

  bool empty() const { return !has_prev_; }
  // The pose one frame after the last update (identity before any update).
  Eigen::Isometry3d predict() const;
  // The last pose given to update() (identity before any update).
  const Eigen::Isometry3d& last() const { return prev_; }
  // measured: the pose came from the method, not from predict().
  void update(const Eigen::Isometry3d& pose, bool measured);
  void reset() { *this = MotionModel(decay_); }

 private:
  double decay_;
  Eigen::Isometry3d prev_ = Eigen::Isometry3d::Identity();
  Eigen::Isometry3d velocity_ = Eigen::Isometry3d::Identity();
  bool has_prev_ = false;
  bool prev_measured_ = false;
  int predicted_since_ = 0;
};

}  // namespace nidevo
