#pragma once
// Turns a session's first message into a camera and decoding rules, and each frame's bytes
// into the grey + metric depth images the odometry consumes.
#include <string>

#include "nidevo/odometry/camera.hpp"
#include "nidevo/odometry/image.hpp"
#include "nidevo/v1/odometry.pb.h"

namespace nidevo::server {

class FrameDecoder {
 public:
  // Empty when the config is usable, else a message naming the bad field
  // (e.g. "config.camera.fx: must be non-zero").
  [[nodiscard]] static std::string validate(const v1::SessionConfig& config);
  // `config` must have passed validate().
  explicit FrameDecoder(const v1::SessionConfig& config);

  const Camera& camera() const { return camera_; }
  // Decodes into `out` (buffers reused). Empty when decoded, else what is wrong with the frame.
  [[nodiscard]] std::string decode(const v1::Frame& frame, RgbdFrame* out) const;

 private:
  [[nodiscard]] std::string decodeColor(const std::string& bytes, GrayImage* gray) const;
  [[nodiscard]] std::string decodeDepth(const std::string& bytes, DepthImageF* depth) const;

  Camera camera_;
  v1::ColorEncoding color_encoding_;
  v1::DepthEncoding depth_encoding_;
};

}  // namespace nidevo::server
