#pragma once
// Plain row-major images shared by every core module; no OpenCV in the algorithm's interfaces.
#include <cstddef>
#include <cstdint>
#include <vector>

namespace nidevo {

template <typename T>
struct Image {
  int width = 0;
  int height = 0;
  std::vector<T> data;

  Image() = default;
  Image(int w, int h, T fill = T{}) : width(w), height(h), data(size_t(w) * size_t(h), fill) {}
  void resize(int w, int h, T fill = T{}) {
    width = w;
    height = h;
    data.assign(size_t(w) * size_t(h), fill);
  }
  T& at(int u, int v) { return data[size_t(v) * size_t(width) + size_t(u)]; }
  const T& at(int u, int v) const { return data[size_t(v) * size_t(width) + size_t(u)]; }
  size_t size() const { return data.size(); }
  bool empty() const { return data.empty(); }
};

using GrayImage = Image<uint8_t>;      // 8-bit intensity
using DepthImage16 = Image<uint16_t>;  // raw depth, metres = value / depth_scale
using DepthImageF = Image<float>;      // metres, 0 = no measurement

// One RGB-D frame as the odometry consumes it.
struct RgbdFrame {
  double timestamp = 0.0;
  GrayImage gray;
  DepthImageF depth;  // metres
};

}  // namespace nidevo
