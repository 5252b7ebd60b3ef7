#include "frame_encoder.hpp"

#include <cmath>
#include <cstring>
#include <opencv2/core.hpp>
#include <opencv2/imgcodecs.hpp>
#include <opencv2/imgproc.hpp>
#include <stdexcept>
#include <vector>

namespace nidevo::client {

FrameEncoding parseFrameEncoding(const std::string& name) {
  FrameEncoding e;
  if (name == "raw") return e;
  if (name == "raw-f32") {
    e.depth = v1::DEPTH_ENCODING_FLOAT32;
    return e;
  }
  if (name == "png" || name == "jpeg") {
    e.color = name == "png" ? v1::COLOR_ENCODING_PNG : v1::COLOR_ENCODING_JPEG;
    e.depth = v1::DEPTH_ENCODING_PNG16;
    return e;
  }
  throw std::invalid_argument("encoding: '" + name + "' is not raw, raw-f32, png or jpeg");
}

namespace {

uint16_t depthUnits(float metres, double depth_scale) {
  if (!(metres > 0.f)) return 0;
  const double raw = std::round(double(metres) * depth_scale);
  return raw > 65535.0 ? 0 : uint16_t(raw);  // beyond 16 bits: no measurement
}

}  // namespace

void encodeFrame(const RgbdFrame& image, double depth_scale, const FrameEncoding& encoding,
                 v1::Frame* frame) {
  const int w = image.gray.width, h = image.gray.height;
  const size_t pixels = size_t(w) * size_t(h);
  frame->set_timestamp(image.timestamp);
  cv::Mat gray(h, w, CV_8UC1, const_cast<uint8_t*>(image.gray.data.data()));
  std::vector<uint8_t> buffer;
  switch (encoding.color) {
    case v1::COLOR_ENCODING_GRAY8:
      frame->set_color(image.gray.data.data(), pixels);
      break;
    case v1::COLOR_ENCODING_RGB8:
    case v1::COLOR_ENCODING_BGR8: {
      cv::Mat colour;
      cv::cvtColor(gray, colour, cv::COLOR_GRAY2BGR);
      frame->set_color(colour.data, 3 * pixels);
      break;
    }
    case v1::COLOR_ENCODING_PNG:
      cv::imencode(".png", gray, buffer, {cv::IMWRITE_PNG_COMPRESSION, 1});
      frame->set_color(buffer.data(), buffer.size());
      break;
    case v1::COLOR_ENCODING_JPEG:
      cv::imencode(".jpg", gray, buffer, {cv::IMWRITE_JPEG_QUALITY, encoding.jpeg_quality});
      frame->set_color(buffer.data(), buffer.size());
      break;
    default:
      throw std::invalid_argument("encodeFrame: unsupported colour encoding");
  }
  const float* depth = image.depth.data.data();
  switch (encoding.depth) {
    case v1::DEPTH_ENCODING_UINT16: {
      std::string* out = frame->mutable_depth();
      out->resize(2 * pixels);
      for (size_t i = 0; i < pixels; ++i) {
        const uint16_t d = depthUnits(depth[i], depth_scale);
        (*out)[2 * i] = char(d & 0xff);  // little-endian on every host
        (*out)[2 * i + 1] = char(d >> 8);
      }
      break;
    }
    case v1::DEPTH_ENCODING_FLOAT32:
      frame->set_depth(reinterpret_cast<const char*>(depth), 4 * pixels);
      break;
    case v1::DEPTH_ENCODING_PNG16: {
      cv::Mat raw(h, w, CV_16UC1);
      for (int v = 0; v < h; ++v)
        for (int u = 0; u < w; ++u)
          raw.at<uint16_t>(v, u) =
              depthUnits(depth[size_t(v) * size_t(w) + size_t(u)], depth_scale);
      cv::imencode(".png", raw, buffer, {cv::IMWRITE_PNG_COMPRESSION, 1});
      frame->set_depth(buffer.data(), buffer.size());
      break;
    }
    default:
      throw std::invalid_argument("encodeFrame: unsupported depth encoding");
  }
}

}  // namespace nidevo::client
