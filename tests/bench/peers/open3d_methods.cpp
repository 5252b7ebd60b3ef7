// Open3D's RGB-D odometry (0.16), hybrid and colour terms, default options, intrinsics only.
// Depth goes in as float metres (depth_scale 1); the default depth_trunc of 3 m applies.
#include <open3d/camera/PinholeCameraIntrinsic.h>
#include <open3d/geometry/Image.h>
#include <open3d/geometry/RGBDImage.h>
#include <open3d/pipelines/odometry/Odometry.h>

#include <cstring>

#include "method.hpp"

namespace nidevo::bench {

namespace {

namespace o3d = open3d;

class Open3dMethod final : public FrameToFrameMethod {
 public:
  explicit Open3dMethod(bool hybrid) : hybrid_(hybrid) {}
  std::string name() const override { return hybrid_ ? "open3d_hybrid" : "open3d_color"; }

 protected:
  void configure(const Camera& camera) override {
    intrinsic_ = o3d::camera::PinholeCameraIntrinsic(camera.width, camera.height, camera.fx,
                                                     camera.fy, camera.cx, camera.cy);
    previous_.reset();
  }
  void prepare(const RgbdFrame& frame) override {
    o3d::geometry::Image gray, depth;
    gray.Prepare(frame.gray.width, frame.gray.height, 1, 1);
    std::memcpy(gray.data_.data(), frame.gray.data.data(), frame.gray.data.size());
    depth.Prepare(frame.depth.width, frame.depth.height, 1, 4);
    std::memcpy(depth.data_.data(), frame.depth.data.data(), 4 * frame.depth.data.size());
    current_ = o3d::geometry::RGBDImage::CreateFromColorAndDepth(gray, depth, 1.0);
  }
  bool motionToPrevious(Eigen::Isometry3d* T_prev_cur) override {
    // ComputeRGBDOdometry(source, target) maps source points into the target: T_prev_cur.
    const auto [ok, T, information] =
        hybrid_ ? o3d::pipelines::odometry::ComputeRGBDOdometry(
                      *current_, *previous_, intrinsic_, Eigen::Matrix4d::Identity(),
                      o3d::pipelines::odometry::RGBDOdometryJacobianFromHybridTerm())
                : o3d::pipelines::odometry::ComputeRGBDOdometry(
                      *current_, *previous_, intrinsic_, Eigen::Matrix4d::Identity(),
                      o3d::pipelines::odometry::RGBDOdometryJacobianFromColorTerm());
    (void)information;
    if (!ok) return false;
    T_prev_cur->matrix() = T;
    return true;
  }
  void advance() override { previous_ = current_; }

 private:
  bool hybrid_;
  o3d::camera::PinholeCameraIntrinsic intrinsic_;
  std::shared_ptr<o3d::geometry::RGBDImage> current_, previous_;
};

}  // namespace

void addOpen3dPeers(std::vector<std::unique_ptr<Method>>* methods) {
  methods->push_back(std::make_unique<Open3dMethod>(true));
  methods->push_back(std::make_unique<Open3dMethod>(false));
}

}  // namespace nidevo::bench
