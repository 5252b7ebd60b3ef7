#include "frame_decoder.hpp"

#include <cmath>
#include <cstring>
#include <opencv2/core.hpp>
#include <opencv2/imgcodecs.hpp>
#include <opencv2/imgproc.hpp>

namespace nidevo::server {

namespace {

constexpr uint32_t kMaxSide = 8192;

std::string sizeMismatch(const char* what, size_t got, size_t expected) {
  return std::string(what) + ": " + std::to_string(got) + " bytes, expected " +
         std::to_string(expected) + " for the session's image size";
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
  return "";
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
  if (gray->width != w || gray->height != h) gray->resize(w, h);
  cv::Mat dst(h, w, CV_8UC1, gray->data.data());
  auto* data = const_cast<char*>(bytes.data());  // OpenCV headers over the message's bytes
  switch (color_encoding_) {
    case v1::COLOR_ENCODING_GRAY8:
      if (bytes.size() != pixels) return sizeMismatch("frame.color", bytes.size(), pixels);
      std::memcpy(gray->data.data(), bytes.data(), pixels);
      return "";
    case v1::COLOR_ENCODING_RGB8:
    case v1::COLOR_ENCODING_BGR8: {
      if (bytes.size() != 3 * pixels) return sizeMismatch("frame.color", bytes.size(), 3 * pixels);
      cv::Mat src(h, w, CV_8UC3, data);
      cv::cvtColor(
          src, dst,
          color_encoding_ == v1::COLOR_ENCODING_RGB8 ? cv::COLOR_RGB2GRAY : cv::COLOR_BGR2GRAY);
      return "";
    }
    case v1::COLOR_ENCODING_JPEG:
    case v1::COLOR_ENCODING_PNG: {
      if (bytes.empty()) return "frame.color: empty";
      cv::Mat decoded;
      try {
        decoded = cv::imdecode(cv::Mat(1, int(bytes.size()), CV_8UC1, data), cv::IMREAD_UNCHANGED);
      } catch (const cv::Exception&) {
        decoded.release();
      }
      if (decoded.empty()) return "frame.color: not a decodable image";
      if (decoded.cols != w || decoded.rows != h)
        return "frame.color: image is " + std::to_string(decoded.cols) + "x" +
               std::to_string(decoded.rows) + ", session expects " + std::to_string(w) + "x" +
               std::to_string(h);
      if (decoded.depth() != CV_8U) return "frame.color: must be 8-bit";
      if (decoded.channels() == 1)
        decoded.copyTo(dst);
      else if (decoded.channels() == 3)
        cv::cvtColor(decoded, dst, cv::COLOR_BGR2GRAY);
      else if (decoded.channels() == 4)
        cv::cvtColor(decoded, dst, cv::COLOR_BGRA2GRAY);
      else
        return "frame.color: unsupported channel count " + std::to_string(decoded.channels());
      return "";
    }
    default:
      return "frame.color: unsupported encoding";
  }
}

std::string FrameDecoder::decodeDepth(const std::string& bytes, DepthImageF* depth) const {
  const int w = camera_.width, h = camera_.height;
  const size_t pixels = size_t(w) * size_t(h);
  if (depth->width != w || depth->height != h) depth->resize(w, h);
  float* out = depth->data.data();
  const float inv_scale = float(1.0 / camera_.depth_scale);
  switch (depth_encoding_) {
    case v1::DEPTH_ENCODING_UINT16: {
      if (bytes.size() != 2 * pixels) return sizeMismatch("frame.depth", bytes.size(), 2 * pixels);
      const auto* in = reinterpret_cast<const unsigned char*>(bytes.data());
      for (size_t i = 0; i < pixels; ++i)
        out[i] = float(uint16_t(in[2 * i] | (in[2 * i + 1] << 8))) * inv_scale;
      return "";
    }
    case v1::DEPTH_ENCODING_FLOAT32: {
      if (bytes.size() != 4 * pixels) return sizeMismatch("frame.depth", bytes.size(), 4 * pixels);
      std::memcpy(out, bytes.data(), 4 * pixels);
      for (size_t i = 0; i < pixels; ++i)
        if (!(out[i] > 0.f) || !std::isfinite(out[i])) out[i] = 0.f;
      return "";
    }
    case v1::DEPTH_ENCODING_PNG16: {
      if (bytes.empty()) return "frame.depth: empty";
      cv::Mat decoded;
      try {
        decoded =
            cv::imdecode(cv::Mat(1, int(bytes.size()), CV_8UC1, const_cast<char*>(bytes.data())),
                         cv::IMREAD_UNCHANGED | cv::IMREAD_ANYDEPTH);
      } catch (const cv::Exception&) {
        decoded.release();
      }
      if (decoded.empty()) return "frame.depth: not a decodable PNG";
      if (decoded.type() != CV_16UC1) return "frame.depth: must be a 16-bit single-channel PNG";
      if (decoded.cols != w || decoded.rows != h)
        return "frame.depth: image is " + std::to_string(decoded.cols) + "x" +
               std::to_string(decoded.rows) + ", session expects " + std::to_string(w) + "x" +
               std::to_string(h);
      for (int v = 0; v < h; ++v) {
        const uint16_t* row = decoded.ptr<uint16_t>(v);
        for (int u = 0; u < w; ++u)
          out[size_t(v) * size_t(w) + size_t(u)] = float(row[u]) * inv_scale;
      }
      return "";
    }
    default:
      return "frame.depth: unsupported encoding";
  }
}

}  // namespace nidevo::server
