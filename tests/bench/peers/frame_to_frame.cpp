#include "method.hpp"

namespace nidevo::bench {

void FrameToFrameMethod::start(const Camera& camera) {
  configure(camera);
  has_previous_ = false;
  T_world_prev_ = Eigen::Isometry3d::Identity();
}

Step FrameToFrameMethod::track(const RgbdFrame& frame) {
  prepare(frame);
  Step step;
  if (has_previous_) {
    Eigen::Isometry3d T_prev_cur = Eigen::Isometry3d::Identity();
    step.reported_good = motionToPrevious(&T_prev_cur);
    if (step.reported_good) T_world_prev_ = T_world_prev_ * T_prev_cur;
  }
  step.T_world_cam = T_world_prev_;
  advance();
  has_previous_ = true;
  return step;
}

}  // namespace nidevo::bench
