#include "nidevo/io/frame_conversion.hpp"

#include <cstring>
#include <opencv2/core.hpp>
#include <opencv2/imgproc.hpp>

namespace nidevo {

namespace {

template <typename T>
void resizeIfNeeded(int width, int height, Image<T>* image) {
  if (image->width != width || image->height != height) image->resize(width, height);
}

}  // namespace

std::string grayFrom8Bit(const uint8_t* pixels, int width, int height, int channels,
                         size_t row_bytes, ChannelOrder order, GrayImage* gray) {
  int code = 0;
  switch (channels) {
    case 1:
      break;
    case 3:
      code = order == ChannelOrder::kBgr ? cv::COLOR_BGR2GRAY : cv::COLOR_RGB2GRAY;
      break;
    case 4:
      code = order == ChannelOrder::kBgr ? cv::COLOR_BGRA2GRAY : cv::COLOR_RGBA2GRAY;
      break;
    default:
      return "unsupported channel count " + std::to_string(channels);
  }
  resizeIfNeeded(width, height, gray);
  const size_t out_row = size_t(width);
  if (channels == 1) {
    for (int v = 0; v < height; ++v)
      std::memcpy(&gray->data[size_t(v) * out_row], pixels + size_t(v) * row_bytes, out_row);
    return {};
  }
  // OpenCV headers over the caller's bytes: no copy of the input.
  const cv::Mat src(height, width, CV_8UC(channels), const_cast<uint8_t*>(pixels), row_bytes);
  cv::Mat dst(height, width, CV_8UC1, gray->data.data());
  cv::cvtColor(src, dst, code);
  return {};
}

void depthFrom16Bit(const void* raw, int width, int height, size_t row_bytes, double depth_scale,
                    DepthImageF* depth) {
  resizeIfNeeded(width, height, depth);
  const float inv_scale = float(1.0 / depth_scale);
  const auto* bytes = static_cast<const unsigned char*>(raw);
  for (int v = 0; v < height; ++v) {
    const unsigned char* in = bytes + size_t(v) * row_bytes;
    float* out = &depth->data[size_t(v) * size_t(width)];
    for (int u = 0; u < width; ++u) {
      const auto value = uint16_t(in[2 * u] | (in[2 * u + 1] << 8));
      out[u] = float(value) * inv_scale;
    }
  }
}

}  // namespace nidevo
