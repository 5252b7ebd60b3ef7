#include "nidevo/odometry/motion_model.hpp"

#include <cmath>

namespace nidevo {

Eigen::Isometry3d MotionModel::predict() const {
  if (!has_prev_) return Eigen::Isometry3d::Identity();
  const double scale = std::pow(decay_, predicted_since_);
  const Eigen::AngleAxisd rotation(velocity_.rotation());
  Eigen::Isometry3d step = Eigen::Isometry3d::Identity();
  step.linear() = Eigen::AngleAxisd(rotation.angle() * scale, rotation.axis()).toRotationMatrix();
  step.translation() = velocity_.translation() * scale;
  return prev_ * step;
}

void MotionModel::update(const Eigen::Isometry3d& pose, bool measured) {
  if (measured && has_prev_ && prev_measured_) {
    velocity_ = prev_.inverse() * pose;
    predicted_since_ = 0;
  } else if (!measured) {
    ++predicted_since_;
  }
  prev_ = pose;
  prev_measured_ = measured;
  has_prev_ = true;
}

}  // namespace nidevo
