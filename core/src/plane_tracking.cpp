#include "nidevo/plane_tracking.hpp"

#include <algorithm>

namespace nidevo {

namespace {

bool smoothAround(const NormalMap& m, size_t i, int W, float crease_dot) {
  const Eigen::Vector3f& n = m.normal[i];
  for (size_t j : {i - 1, i + 1, i - size_t(W), i + size_t(W)}) {
    if (!m.valid[j] || n.dot(m.normal[j]) < crease_dot) return false;
  }
  return true;
}

}  // namespace

void PlaneTracker::track(const NormalMap& key, const NormalMap& cur,
                         const PlaneTrackingParams& p, PlaneTrackingResult* out) {
  const int W = key.width, H = key.height;
  const size_t n = size_t(W) * size_t(H);
  mode_of_.assign(n, -1);
  seeds_.resize(size_t(p.max_modes));
  counts_.assign(size_t(p.max_modes), 0);
  scratch_.resize(n);
  out->overlap_pixels = 0;
  out->planes.clear();

  const int border = std::max(p.border, 1);
  int modes = 0;
  for (int v = border; v < H - border; ++v) {
    for (int u = border; u < W - border; ++u) {
      const size_t i = size_t(v) * W + u;
      if (!key.valid[i] || !cur.valid[i]) continue;
      const Eigen::Vector3f& nk = key.normal[i];
      if (nk.dot(cur.normal[i]) < p.overlap_dot) continue;
      if (!smoothAround(key, i, W, p.crease_dot) || !smoothAround(cur, i, W, p.crease_dot)) continue;
      ++out->overlap_pixels;
      int m = 0;
      while (m < modes && nk.dot(seeds_[size_t(m)]) < p.mode_dot) ++m;
      if (m == modes) {
        if (modes == p.max_modes) continue;
        seeds_[size_t(modes++)] = nk;
      }
      mode_of_[i] = int8_t(m);
      ++counts_[size_t(m)];
    }
  }

  // The median of each component, renormalised: robust against the pixels near plane borders.
  auto median_normal = [&](int m, const NormalMap& map) {
    Eigen::Vector3f r;
    for (int c = 0; c < 3; ++c) {
      size_t k = 0;
      for (size_t i = 0; i < n; ++i)
        if (mode_of_[i] == m) scratch_[k++] = map.normal[i][c];
      std::nth_element(scratch_.begin(), scratch_.begin() + long(k / 2), scratch_.begin() + long(k));
      r[c] = scratch_[k / 2];
    }
    return r.normalized();
  };
  for (int m = 0; m < modes; ++m) {
    if (counts_[size_t(m)] < p.min_plane_pixels) continue;
    out->planes.push_back({median_normal(m, key), median_normal(m, cur), counts_[size_t(m)]});
  }
  std::sort(out->planes.begin(), out->planes.end(),
            [](const PlanePair& a, const PlanePair& b) { return a.pixels > b.pixels; });
}

}  // namespace nidevo
