#include "nidevo/odometry/motion_model.hpp"

#include <algorithm>
#include <cmath>

namespace nidevo {

double MotionModel::framesBetween(double from, double to) const {
  const double gap = to - from;
  if (!(gap > 0) || !std::isfinite(gap) || gap_count_ == 0) return 1;
  std::array<double, 15> sorted = gaps_;
  const auto mid = sorted.begin() + gap_count_ / 2;
  std::nth_element(sorted.begin(), mid, sorted.begin() + gap_count_);
  return std::clamp(std::round(gap / *mid), 1.0, kMaxFrames);
}

Eigen::Isometry3d MotionModel::predict(double timestamp) const {
  if (!has_prev_) return Eigen::Isometry3d::Identity();
  const double frames = framesBetween(prev_timestamp_, timestamp);
  const double scale = std::pow(decay_, predicted_since_) * frames / velocity_frames_;
  const Eigen::AngleAxisd rotation(velocity_.rotation());
  Eigen::Isometry3d step = Eigen::Isometry3d::Identity();
  step.linear() = Eigen::AngleAxisd(rotation.angle() * scale, rotation.axis()).toRotationMatrix();
  step.translation() = velocity_.translation() * scale;
  return prev_ * step;
}

void MotionModel::update(const Eigen::Isometry3d& pose, bool measured, double timestamp) {
  const double gap = timestamp - prev_timestamp_;
  if (has_prev_ && gap > 0 && std::isfinite(gap)) {
    gaps_[size_t(gap_next_)] = gap;
    gap_next_ = (gap_next_ + 1) % int(gaps_.size());
    gap_count_ = std::min(gap_count_ + 1, int(gaps_.size()));
  }
  if (measured && has_prev_ && prev_measured_) {
    velocity_ = prev_.inverse() * pose;
    velocity_frames_ = framesBetween(prev_timestamp_, timestamp);
    predicted_since_ = 0;
  } else if (!measured) {
    ++predicted_since_;
  }
  prev_ = pose;
  prev_timestamp_ = timestamp;
  prev_measured_ = measured;
  has_prev_ = true;
}

}  // namespace nidevo
