#include "nidevo/odometry/plane_yaw.hpp"

#include <algorithm>
#include <cmath>

namespace nidevo {

namespace {

// atan2 within 1e-5 rad: the histogram's bins are degrees wide, and libm's atan2 would be most
// of the pass's cost.
float fastAtan2(float y, float x) {
  const float ax = std::abs(x), ay = std::abs(y);
  const float a = std::min(ax, ay) / std::max(ax, ay), s = a * a;
  float r = ((-0.0464964749f * s + 0.15931422f) * s - 0.327622764f) * s * a + a;
  if (ay > ax) r = float(M_PI_2) - r;
  if (x < 0) r = float(M_PI) - r;
  return y < 0 ? -r : r;
}

// Circular [1 2 1] / 4: a direction near a bin's edge counts in both neighbours alike.
void smoothCircular(std::vector<float>* bins) {
  std::vector<float>& h = *bins;
  const size_t n = h.size();
  const float first = h[0];
  float previous = h[n - 1];
  for (size_t k = 0; k < n; ++k) {
    const float next = k + 1 < n ? h[k + 1] : first, here = h[k];
    h[k] = 0.25f * (previous + 2.f * here + next);
    previous = here;
  }
}

// Normalised correlation of a with b turned by `shift` bins: sum_k a[k] b[k - shift].
double correlation(const std::vector<float>& a, const std::vector<float>& b, int shift) {
  const int n = int(a.size());
  double ab = 0, aa = 0, bb = 0, ma = 0, mb = 0;
  for (int k = 0; k < n; ++k) ma += a[size_t(k)], mb += b[size_t(k)];
  ma /= n, mb /= n;
  for (int k = 0; k < n; ++k) {
    const double x = a[size_t(k)] - ma, y = b[size_t(((k - shift) % n + n) % n)] - mb;
    ab += x * y, aa += x * x, bb += y * y;
  }
  return aa > 0 && bb > 0 ? ab / std::sqrt(aa * bb) : 0.0;
}

}  // namespace

void PlaneYawEstimator::smoothGrey(const PlaneView& view, int radius) {
  const NormalMap& map = *view.map;
  const int W = map.width, H = map.height;
  const size_t n = size_t(W) * size_t(H);
  // Binomial weights of 2 radius + 1 taps.
  float w[16];
  const int r = std::min(radius, 7);
  w[0] = 1.f;
  for (int k = 1; k <= 2 * r; ++k) {
    w[k] = 0.f;
    for (int j = k; j > 0; --j) w[j] += w[j - 1];
  }
  grey_.resize(n);
  mask_.resize(n);
  row_grey_.resize(n);
  row_mask_.resize(n);
  for (size_t i = 0; i < n; ++i) {
    const float m = map.points[i].z() > 0.f ? 1.f : 0.f;
    mask_[i] = m;
    grey_[i] = m * view.intensity[i];
  }
  // Rows, then columns; each sum skips what lies off the image.
  for (int v = 0; v < H; ++v) {
    for (int u = 0; u < W; ++u) {
      float g = 0, m = 0;
      for (int k = -r; k <= r; ++k) {
        const int x = u + k;
        if (x < 0 || x >= W) continue;
        const size_t j = size_t(v) * size_t(W) + size_t(x);
        g += w[k + r] * grey_[j];
        m += w[k + r] * mask_[j];
      }
      row_grey_[size_t(v) * size_t(W) + size_t(u)] = g;
      row_mask_[size_t(v) * size_t(W) + size_t(u)] = m;
    }
  }
  for (int v = 0; v < H; ++v) {
    for (int u = 0; u < W; ++u) {
      float g = 0, m = 0;
      for (int k = -r; k <= r; ++k) {
        const int y = v + k;
        if (y < 0 || y >= H) continue;
        const size_t j = size_t(y) * size_t(W) + size_t(u);
        g += w[k + r] * row_grey_[j];
        m += w[k + r] * row_mask_[j];
      }
      grey_[size_t(v) * size_t(W) + size_t(u)] = m > 0.f ? g / m : 0.f;
    }
  }
}

int PlaneYawEstimator::histogram(const PlaneView& view, const Eigen::Vector3f& e1,
                                 const Eigen::Vector3f& e2, const Camera& map_camera,
                                 const PlaneYawParams& p, std::vector<float>* bins) {
  bins->assign(size_t(p.bins), 0.f);
  const NormalMap& map = *view.map;
  smoothGrey(view, p.smooth_radius);
  const float* grey = grey_.data();
  const int W = map.width, H = map.height, step = std::max(1, p.pixel_step);
  const float fx = float(map_camera.fx), fy = float(map_camera.fy);
  const float per_radian = float(p.bins) / float(2 * M_PI);
  const Eigen::Vector3f& n = view.normal;
  // The basis seen from this frame: directions on the plane are compared in the keyframe's.
  const Eigen::Vector3f a1 = view.R_key_cam.transpose() * e1, a2 = view.R_key_cam.transpose() * e2;
  const float min_gradient_sq = p.min_gradient * p.min_gradient;
  // |f|: a camera may flip an axis (ICL-NUIM's fy is negative).
  const float max_footprint_f = p.max_footprint_m * std::min(std::abs(fx), std::abs(fy));
  int used = 0;
  for (int v = 1; v + 1 < H; v += step) {
    for (int u = 1; u + 1 < W; u += step) {
      const size_t i = size_t(v) * size_t(W) + size_t(u);
      // Either sign: the plane trackers' normals need not face the camera.
      if (!map.valid[i] || std::abs(map.normal[i].dot(n)) < p.plane_dot) continue;
      // A neighbour without depth (the box filter gives normals to pixels without it) may see
      // another object, or nothing.
      if (!(map.points[i].z() > 0.f) || !(map.points[i - 1].z() > 0.f) ||
          !(map.points[i + 1].z() > 0.f) || !(map.points[i - size_t(W)].z() > 0.f) ||
          !(map.points[i + size_t(W)].z() > 0.f))
        continue;
      const float gu = 0.5f * (grey[i + 1] - grey[i - 1]);
      const float gv = 0.5f * (grey[i + size_t(W)] - grey[i - size_t(W)]);
      const float g2 = gu * gu + gv * gv;
      if (g2 < min_gradient_sq) continue;
      // The gradient of the grey value as a function on the plane: the projection's Jacobian
      // transposed times the image gradient (up to the factor 1/z), less its part along n.
      const Eigen::Vector3f& X = map.points[i];
      // The pixel's footprint on the plane: z / f along the ray, stretched by the slant.
      const float slant = std::abs(n.dot(X)) / X.norm();
      if (X.z() > max_footprint_f * slant) continue;
      const float rx = X.x() / X.z(), ry = X.y() / X.z();
      Eigen::Vector3f g(fx * gu, fy * gv, -(fx * rx * gu + fy * ry * gv));
      g -= n * n.dot(g);
      const float c1 = g.dot(a1), c2 = g.dot(a2);
      if (c1 == 0.f && c2 == 0.f) continue;
      float f = fastAtan2(c2, c1) * per_radian;
      if (f < 0) f += float(p.bins);
      const int k0 = std::min(int(f), p.bins - 1);
      const float t = f - float(k0), w = std::sqrt(g2);
      (*bins)[size_t(k0)] += w * (1.f - t);
      (*bins)[size_t((k0 + 1) % p.bins)] += w * t;
      ++used;
    }
  }
  smoothCircular(bins);
  return used;
}

PlaneYaw PlaneYawEstimator::estimate(const PlaneView& key, const PlaneView& cur,
                                     const Camera& map_camera, const PlaneYawParams& p) {
  PlaneYaw out;
  const Eigen::Vector3f n = key.normal.normalized();
  // Any axis not near n gives the basis' first direction.
  const Eigen::Vector3f seed =
      std::abs(n.x()) < 0.6f ? Eigen::Vector3f::UnitX() : Eigen::Vector3f::UnitY();
  const Eigen::Vector3f e1 = (seed - n * n.dot(seed)).normalized(), e2 = n.cross(e1);
  out.key_pixels = histogram(key, e1, e2, map_camera, p, &key_);
  out.cur_pixels = histogram(cur, e1, e2, map_camera, p, &cur_);
  if (out.key_pixels < p.min_pixels || out.cur_pixels < p.min_pixels) return out;
  const double bin_rad = 2 * M_PI / p.bins;
  const int reach = int(std::ceil(p.max_turn_rad / bin_rad));
  int best = 0;
  double best_c = -2, c_at[3] = {0, 0, 0};
  for (int s = -reach; s <= reach; ++s) {
    const double c = correlation(key_, cur_, s);
    if (c > best_c) best_c = c, best = s;
  }
  for (int d = -1; d <= 1; ++d) c_at[d + 1] = correlation(key_, cur_, best + d);
  double offset = 0;
  const double curvature = c_at[0] - 2 * c_at[1] + c_at[2];
  if (curvature < 0) offset = std::clamp(0.5 * (c_at[0] - c_at[2]) / curvature, -0.5, 0.5);
  out.turn_rad = (best + offset) * bin_rad;
  out.ncc = best_c;
  // A maximum at the window's edge may lie beyond it.
  out.measured =
      best_c >= p.min_ncc && std::abs(best) < reach && std::abs(out.turn_rad) <= p.max_turn_rad;
  return out;
}

}  // namespace nidevo
