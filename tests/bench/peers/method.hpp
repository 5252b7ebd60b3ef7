#pragma once
// A frame-to-frame RGB-D odometry under test: this project's or a peer's, behind one interface
// so that every method sees the same frames in the same process.
#include <Eigen/Geometry>
#include <memory>
#include <string>
#include <vector>

#include "nidevo/odometry/camera.hpp"
#include "nidevo/odometry/image.hpp"

namespace nidevo::bench {

struct Step {
  Eigen::Isometry3d T_world_cam = Eigen::Isometry3d::Identity();
  bool reported_good = true;  // the method's own verdict (NIDEVO: status OK; peers: success)
};

class Method {
 public:
  virtual ~Method() = default;
  virtual std::string name() const = 0;
  // Starts a sequence: the first frame's pose is the identity (world = first camera).
  virtual void start(const Camera& camera) = 0;
  // The next frame, in order.
  virtual Step track(const RgbdFrame& frame) = 0;
};

// Peers only chain frame-to-frame motions: each frame is matched against the previous one from
// an identity initial guess; a failed match keeps the previous pose and counts as a failure.
class FrameToFrameMethod : public Method {
 public:
  void start(const Camera& camera) override;
  Step track(const RgbdFrame& frame) override;

 protected:
  // Prepares `frame` (once) as the current frame; true when a previous frame exists.
  virtual void prepare(const RgbdFrame& frame) = 0;
  // T_prev_cur (maps the current camera's points into the previous camera), false on failure.
  virtual bool motionToPrevious(Eigen::Isometry3d* T_prev_cur) = 0;
  // The current frame becomes the previous one.
  virtual void advance() = 0;
  virtual void configure(const Camera& camera) = 0;

 private:
  bool has_previous_ = false;
  Eigen::Isometry3d T_world_prev_ = Eigen::Isometry3d::Identity();
};

std::unique_ptr<Method> makeNidevo();
// The peers this build has (OpenCV-contrib rgbd, Open3D), each with its default parameters.
std::vector<std::unique_ptr<Method>> makePeers();

}  // namespace nidevo::bench
