#include "nidevo/odometry/depth_shift.hpp"

#include <algorithm>
#include <cmath>

namespace nidevo {

DepthShift DepthShiftEstimator::estimate(const OrthoImage& key, const OrthoImage& cur, double du,
                                         double dv, const DepthShiftParams& p) {
  const int W = key.width, H = key.height;
  diffs_.resize(size_t(W) * size_t(H));
  scratch_.reserve(diffs_.size());  // its size follows the inlier count: never grow per frame
  kth_smallest_.reserve(diffs_.size());
  size_t n = 0;
  const int iu = int(std::floor(du)), iv = int(std::floor(dv));
  const float fu = float(du - iu), fv = float(dv - iv);
  // Depth change over two cells allowed by the slope limit.
  const float slope_limit = p.max_slope > 0 ? float(2.0 * p.resolution * p.max_slope) : 0.f;
  const float w00 = (1 - fu) * (1 - fv), w10 = fu * (1 - fv), w01 = (1 - fu) * fv, w11 = fu * fv;
  const int step = std::max(1, p.sample_step);
  const bool check_slope = slope_limit > 0.f;
  for (int v = std::max(0, -iv); v < std::min(H, H - iv - 1); v += step) {
    // Cells on the border have no four neighbours for the slope test: skipped.
    if (check_slope && (v == 0 || v == H - 1)) continue;
    for (int u = std::max(0, -iu); u < std::min(W, W - iu - 1); u += step) {
      if (check_slope && (u == 0 || u == W - 1)) continue;
      const size_t k = size_t(v) * size_t(W) + size_t(u);
      const size_t c = size_t(v + iv) * size_t(W) + size_t(u + iu);
      const float zk = key.depth[k];
      int keep = zk > 0.f;
      if (check_slope) {
        const float zl = key.depth[k - 1], zr = key.depth[k + 1], zt = key.depth[k - size_t(W)],
                    zb = key.depth[k + size_t(W)];
        keep &= (zl > 0.f) & (zr > 0.f) & (zt > 0.f) & (zb > 0.f) &
                !(std::abs(zr - zl) > slope_limit) & !(std::abs(zb - zt) > slope_limit);
      }
      const float z00 = cur.depth[c], z10 = cur.depth[c + 1], z01 = cur.depth[c + size_t(W)],
                  z11 = cur.depth[c + size_t(W) + 1];
      keep &= (z00 > 0.f) & (z10 > 0.f) & (z01 > 0.f) & (z11 > 0.f);
      const float zc = w00 * z00 + w10 * z10 + w01 * z01 + w11 * z11;
      const float gc = w00 * cur.gray[c] + w10 * cur.gray[c + 1] + w01 * cur.gray[c + size_t(W)] +
                       w11 * cur.gray[c + size_t(W) + 1];
      keep &= !(std::abs(gc - key.gray[k]) >= p.gray_tolerance);
      // Written always, kept by counting: which cells pass follows the scene, not a pattern the
      // CPU's branch predictor can learn.
      diffs_[n] = zk - zc;
      n += size_t(keep);
    }
  }
  DepthShift r;
  if (n == 0) return r;
  // Start from the median, then refine with the mean of the inliers around it.
  scratch_.assign(diffs_.begin(), diffs_.begin() + long(n));
  double dz = kth_smallest_(scratch_.data(), n, n / 2);
  int inliers = 0;
  for (int it = 0; it < p.iterations; ++it) {
    double sum = 0;
    int count = 0;
    for (size_t i = 0; i < n; ++i) {
      // Adding 0 leaves the sum's bits as they are (it never is -0).
      const bool inlier = std::abs(diffs_[i] - dz) < p.inlier_m;
      sum += inlier ? double(diffs_[i]) : 0.0;
      count += inlier;
    }
    if (count == 0) break;
    dz = sum / count;
    inliers = count;
  }
  r.dz = dz;
  r.inliers = inliers;
  return r;
}

}  // namespace nidevo
