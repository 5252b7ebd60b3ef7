#include "nidevo/normal_map.hpp"

#include <Eigen/Geometry>
#include <cmath>

namespace nidevo {

void NormalMap::resize(int w, int h) {
  width = w;
  height = h;
  normal.resize(size_t(w) * size_t(h));
  valid.resize(size_t(w) * size_t(h));
  points.resize(size_t(w) * size_t(h));
  smooth.resize(size_t(w) * size_t(h));
}

int NormalMap::validCount() const {
  int n = 0;
  for (uint8_t v : valid) n += v;
  return n;
}

void NormalMapBuilder::compute(const DepthImageF& depth, const Camera& camera, int stride,
                               int cell_size, float depth_discontinuity, float min_depth,
                               float max_depth, float crease_dot, NormalMap* out) {
  const Camera cam = camera.subsampled(stride);
  const int W = depth.width / stride, H = depth.height / stride;
  const size_t n = size_t(W) * size_t(H);
  out->resize(W, H);
  raw_.resize(n);
  tmp_.resize(n);

  // Back-projection as Camera::backproject computes it, with the divisions done once per
  // column and row instead of per pixel.
  ray_x_.resize(size_t(W));
  ray_y_.resize(size_t(H));
  for (int u = 0; u < W; ++u) ray_x_[size_t(u)] = float((float(u) - cam.cx) / cam.fx);
  for (int v = 0; v < H; ++v) ray_y_[size_t(v)] = float((float(v) - cam.cy) / cam.fy);
  for (int v = 0; v < H; ++v) {
    const float* row = &depth.data[size_t(v * stride) * size_t(depth.width)];
    Eigen::Vector3f* dst = &out->points[size_t(v) * W];
    const float ry = ray_y_[size_t(v)];
    for (int u = 0; u < W; ++u) {
      float z = row[u * stride];
      if (!(z >= min_depth && z <= max_depth)) z = 0.f;  // also rejects NaN
      dst[u] = Eigen::Vector3f(ray_x_[size_t(u)] * z, ry * z, z);
    }
  }

  // Central differences (Eq. 4); a missing neighbour or a depth jump leaves no normal.
  auto usable = [&](const Eigen::Vector3f& p, float z0) {
    return p.z() > 0.f && std::abs(p.z() - z0) <= depth_discontinuity * z0;
  };
  for (int v = 0; v < H; ++v) {
    for (int u = 0; u < W; ++u) {
      const size_t i = size_t(v) * W + u;
      raw_[i].setZero();
      const Eigen::Vector3f& p = out->points[i];
      if (u == 0 || v == 0 || u == W - 1 || v == H - 1 || p.z() <= 0.f) continue;
      const Eigen::Vector3f &l = out->points[i - 1], &r = out->points[i + 1],
                            &t = out->points[i - W], &b = out->points[i + W];
      if (!usable(l, p.z()) || !usable(r, p.z()) || !usable(t, p.z()) || !usable(b, p.z()))
        continue;
      Eigen::Vector3f nrm = (r - l).cross(b - t);
      const float len = nrm.norm();
      if (!(len > 0.f)) continue;
      nrm /= len;
      if (nrm.dot(p) > 0.f) nrm = -nrm;
      raw_[i] << nrm, 1.f;
    }
  }

  // Separable box filter of side cell_size over (normal, count); O(1) per pixel.
  const int lo = cell_size / 2, hi = cell_size - 1 - lo;
  for (int v = 0; v < H; ++v) {
    const Eigen::Vector4f* row = &raw_[size_t(v) * W];
    Eigen::Vector4f* dst = &tmp_[size_t(v) * W];
    Eigen::Vector4f acc = Eigen::Vector4f::Zero();
    for (int u = 0; u <= std::min(hi, W - 1); ++u) acc += row[u];
    for (int u = 0; u < W; ++u) {
      dst[u] = acc;
      if (u + hi + 1 < W) acc += row[u + hi + 1];
      if (u - lo >= 0) acc -= row[u - lo];
    }
  }
  // Vertical pass row by row (one running sum per column), so memory is read in order.
  column_sums_.assign(size_t(W), Eigen::Vector4f::Zero());
  for (int v = 0; v <= std::min(hi, H - 1); ++v)
    for (int u = 0; u < W; ++u) column_sums_[size_t(u)] += tmp_[size_t(v) * W + u];
  for (int v = 0; v < H; ++v) {
    for (int u = 0; u < W; ++u) {
      const size_t i = size_t(v) * W + u;
      const Eigen::Vector3f s = column_sums_[size_t(u)].head<3>();
      const float len = s.norm();
      const bool ok = raw_[i].w() > 0.f && len > 1e-6f;
      out->valid[i] = ok;
      out->normal[i] = ok ? Eigen::Vector3f(s / len) : Eigen::Vector3f::Zero();
    }
    if (v + hi + 1 < H)
      for (int u = 0; u < W; ++u) column_sums_[size_t(u)] += tmp_[size_t(v + hi + 1) * W + u];
    if (v - lo >= 0)
      for (int u = 0; u < W; ++u) column_sums_[size_t(u)] -= tmp_[size_t(v - lo) * W + u];
  }

  // Pixels on a crease (a 4-neighbour normal differs) are useless for plane tracking; marking
  // them once here spares stage 2 from doing it for both frames of every pair.
  std::fill(out->smooth.begin(), out->smooth.end(), uint8_t(0));
  for (int v = 1; v < H - 1; ++v) {
    for (int u = 1; u < W - 1; ++u) {
      const size_t i = size_t(v) * W + u;
      if (!out->valid[i]) continue;
      const Eigen::Vector3f& nrm = out->normal[i];
      bool ok = true;
      for (size_t j : {i - 1, i + 1, i - size_t(W), i + size_t(W)}) {
        ok = ok && out->valid[j] && nrm.dot(out->normal[j]) >= crease_dot;
      }
      out->smooth[i] = ok;
    }
  }
}

}  // namespace nidevo
