#include "frame_decoder.hpp"

#include <cmath>
#include <cstring>
#include <opencv2/core.hpp>
#include <opencv2/imgcodecs.hpp>
#include <opencv2/imgproc.hpp>

#include "nidevo/io/frame_conversion.hpp"
#include "pose_response.hpp"

namespace nidevo::server {

namespace {

constexpr uint32_t kMaxSide = 8192;

std::string sizeMismatch(const char* what, size_t got, size_t expected) {
  return std::string(what) + ": " + std::to_string(got) + " bytes, expected " +
         std::to_string(expected) + " for the session's image size";
}

// Empty when the bytes are not an image OpenCV can decode.
cv::Mat decodeImage(const std::string& bytes, int flags) {
  try {
    return cv::imdecode(cv::Mat(1, int(bytes.size()), CV_8UC1, const_cast<char*>(bytes.data())),
                        flags);
  } catch (const cv::Exception&) {
    return {};
  }
}

Camera cameraOf(const v1::SessionConfig& config) {
  const auto& c = config.camera();
  Camera camera;
  camera.fx = c.fx();
  camera.fy = c.fy();
  camera.cx = c.cx();
  camera.cy = c.cy();
  camera.width = int(c.width());
  camera.height = int(c.height());
  const v1::LensDistortion& d = c.distortion();
  camera.distortion = {d.k1(), d.k2(), d.p1(), d.p2(), d.k3()};
  camera.depth_scale = config.depth_scale() > 0 ? config.depth_scale() : 1.0;  // unused for f32
  return camera;
}

}  // namespace

std::string FrameDecoder::validate(const v1::SessionConfig& config) {
  if (!config.has_camera()) return "config.camera: missing";
  const auto& c = config.camera();
  if (c.width() == 0 || c.height() == 0 || c.width() > kMaxSide || c.height() > kMaxSide)
    return "config.camera.width/height: must be 1.." + std::to_string(kMaxSide) + ", got " +
           std::to_string(c.width()) + "x" + std::to_string(c.height());
  if (!v1::ColorEncoding_IsValid(config.color_encoding()) ||
      config.color_encoding() == v1::COLOR_ENCODING_UNSPECIFIED)
    return "config.color_encoding: unsupported value " + std::to_string(config.color_encoding());
  if (!v1::DepthEncoding_IsValid(config.depth_encoding()) ||
      config.depth_encoding() == v1::DEPTH_ENCODING_UNSPECIFIED)
    return "config.depth_encoding: unsupported value " + std::to_string(config.depth_encoding());
  if (config.depth_encoding() != v1::DEPTH_ENCODING_FLOAT32 &&
      !(std::isfinite(config.depth_scale()) && config.depth_scale() > 0))
    return "config.depth_scale: must be positive for 16-bit depth";
  if (!v1::OverloadPolicy_IsValid(config.overload_policy()))
    return "config.overload_policy: unsupported value " + std::to_string(config.overload_policy());
  if (std::string e = cameraOf(config).validate(); !e.empty()) return "config.camera: " + e;
  return validateInitialPose(config);
}

FrameDecoder::FrameDecoder(const v1::SessionConfig& config)
    : camera_(cameraOf(config)),
      color_encoding_(config.color_encoding()),
      depth_encoding_(config.depth_encoding()) {}

std::string FrameDecoder::decode(const v1::Frame& frame, RgbdFrame* out) const {
  out->timestamp = frame.timestamp();
  if (std::string e = decodeColor(frame.color(), &out->gray); !e.empty()) return e;
  return decodeDepth(frame.depth(), &out->depth);
}

std::string FrameDecoder::decodeColor(const std::string& bytes, GrayImage* gray) const {
  const int w = camera_.width, h = camera_.height;
  const size_t pixels = size_t(w) * size_t(h);
  const auto* data = reinterpret_cast<const uint8_t*>(bytes.data());
  std::string error;
  switch (color_encoding_) {
    case v1::COLOR_ENCODING_GRAY8:
      if (bytes.size() != pixels) return sizeMismatch("frame.color", bytes.size(), pixels);
      error = grayFrom8Bit(data, w, h, 1, size_t(w), ChannelOrder::kBgr, gray);
      break;
    case v1::COLOR_ENCODING_RGB8:
    case v1::COLOR_ENCODING_BGR8: {
      if (bytes.size() != 3 * pixels) return sizeMismatch("frame.color", bytes.size(), 3 * pixels);
      const ChannelOrder order =
          color_encoding_ == v1::COLOR_ENCODING_RGB8 ? ChannelOrder::kRgb : ChannelOrder::kBgr;
      error = grayFrom8Bit(data, w, h, 3, 3 * size_t(w), order, gray);
      break;
    }
    case v1::COLOR_ENCODING_JPEG:
    case v1::COLOR_ENCODING_PNG: {
      if (bytes.empty()) return "frame.color: empty";
      const cv::Mat decoded = decodeImage(bytes, cv::IMREAD_UNCHANGED);
      if (decoded.empty()) return "frame.color: not a decodable image";
      if (std::string e = camera_.checkImageSize(decoded.cols, decoded.rows); !e.empty())
        return "frame.color: " + e;
      if (decoded.depth() != CV_8U) return "frame.color: must be 8-bit";
      error = grayFrom8Bit(decoded.ptr<uint8_t>(), w, h, decoded.channels(), decoded.step,
                           ChannelOrder::kBgr, gray);
      break;
    }
    default:
      return "frame.color: unsupported encoding";
  }
  return error.empty() ? error : "frame.color: " + error;
}

std::string FrameDecoder::decodeDepth(const std::string& bytes, DepthImageF* depth) const {
  const int w = camera_.width, h = camera_.height;
  const size_t pixels = size_t(w) * size_t(h);
  switch (depth_encoding_) {
    case v1::DEPTH_ENCODING_UINT16:
      if (bytes.size() != 2 * pixels) return sizeMismatch("frame.depth", bytes.size(), 2 * pixels);
      depthFrom16Bit(bytes.data(), w, h, 2 * size_t(w), camera_.depth_scale, depth);
      return "";
    case v1::DEPTH_ENCODING_FLOAT32: {
      if (bytes.size() != 4 * pixels) return sizeMismatch("frame.depth", bytes.size(), 4 * pixels);
      if (depth->width != w || depth->height != h) depth->resize(w, h);
      float* out = depth->data.data();
      std::memcpy(out, bytes.data(), 4 * pixels);
      for (size_t i = 0; i < pixels; ++i)
        if (!(out[i] > 0.f) || !std::isfinite(out[i])) out[i] = 0.f;
      return "";
    }
    case v1::DEPTH_ENCODING_PNG16: {
      if (bytes.empty()) return "frame.depth: empty";
      const cv::Mat decoded = decodeImage(bytes, cv::IMREAD_UNCHANGED | cv::IMREAD_ANYDEPTH);
      if (decoded.empty()) return "frame.depth: not a decodable PNG";
      if (decoded.type() != CV_16UC1) return "frame.depth: must be a 16-bit single-channel PNG";
      if (std::string e = camera_.checkImageSize(decoded.cols, decoded.rows); !e.empty())
        return "frame.depth: " + e;
      depthFrom16Bit(decoded.ptr(), w, h, decoded.step, camera_.depth_scale, depth);
      return "";
    }
    default:
      return "frame.depth: unsupported encoding";
  }
}

}  // namespace nidevo::server
