#include "method.hpp"
#include "nidevo/odometry/odometry.hpp"

namespace nidevo::bench {

namespace {

// This project's odometry with its default configuration; good = status OK.
class NidevoMethod final : public Method {
 public:
  std::string name() const override { return "nidevo"; }
  void start(const Camera& camera) override {
    odometry_ = std::make_unique<Odometry>(camera, OdometryConfig{});
  }
  Step track(const RgbdFrame& frame) override {
    const PoseEstimate pose = odometry_->track(frame);
    return {pose.T_world_cam, pose.state == TrackingState::kOk};
  }

 private:
  std::unique_ptr<Odometry> odometry_;
};

}  // namespace

std::unique_ptr<Method> makeNidevo() { return std::make_unique<NidevoMethod>(); }

}  // namespace nidevo::bench
