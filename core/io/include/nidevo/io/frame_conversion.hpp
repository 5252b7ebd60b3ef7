#pragma once
// The one conversion of a sensor's images into the odometry's frame, shared by the dataset
// reader and the server's frame decoder: 8-bit colour to grey, 16-bit depth to metres.
#include <cstddef>
#include <cstdint>
#include <string>

#include "nidevo/odometry/image.hpp"

namespace nidevo {

// Byte order of 3- and 4-channel pixels: OpenCV's image files are BGR(A), raw streams may be RGB.
enum class ChannelOrder { kBgr, kRgb };

// 8-bit pixels, `channels` (1, 3 or 4) per pixel, rows `row_bytes` apart. Empty on success, else
// what is wrong ("unsupported channel count 2"). `gray` is resized only when its size differs.
[[nodiscard]] std::string grayFrom8Bit(const uint8_t* pixels, int width, int height, int channels,
                                       size_t row_bytes, ChannelOrder order, GrayImage* gray);

// Raw 16-bit depth in units of 1/depth_scale metres, rows `row_bytes` apart, little-endian (the
// wire format and every platform we build for), any alignment; 0 stays 0 (no measurement).
// `depth` is resized only when its size differs.
void depthFrom16Bit(const void* raw, int width, int height, size_t row_bytes, double depth_scale,
                    DepthImageF* depth);

}  // namespace nidevo
