#include "nidevo/odometry/selection.hpp"

#include <algorithm>
#include <cmath>

namespace nidevo {

void KthSmallest::reserve(size_t n) {
  sample_.reserve(n / 16 + 1);
  band_.reserve(n);
}

float KthSmallest::operator()(float* values, size_t n, size_t k) {
  // Below this size one nth_element is as fast as the bracketing; from here up (a plane fit's
  // medians are over 1-4 k values and more) the bracketing is faster.
  constexpr size_t kDirect = 1024;
  if (n <= kDirect) {
    std::nth_element(values, values + k, values + n);
    return values[k];
  }
  // A regular sample of about n/16 values; the bracket spans the sample ranks around k's,
  // widened by three standard deviations of a sample quantile (at most sqrt(m)/2 each).
  const size_t step = 16, m = n / step;
  sample_.resize(m);
  for (size_t i = 0; i < m; ++i) sample_[i] = values[i * step];
  const size_t centre = std::min(m - 1, k / step);
  const size_t margin = size_t(1.5 * std::sqrt(double(m))) + 8;
  const size_t lo_rank = centre > margin ? centre - margin : 0;
  const size_t hi_rank = std::min(m - 1, centre + margin);
  std::nth_element(sample_.begin(), sample_.begin() + long(lo_rank), sample_.end());
  const float lo = sample_[lo_rank];
  std::nth_element(sample_.begin() + long(lo_rank), sample_.begin() + long(hi_rank), sample_.end());
  const float hi = sample_[hi_rank];

  band_.resize(n);
  size_t below = 0, in_band = 0;
  for (size_t i = 0; i < n; ++i) {
    const float x = values[i];
    below += x < lo;
    band_[in_band] = x;
    in_band += (x >= lo) & (x <= hi);
  }
  // The rank-k value lies in [lo, hi] exactly when the values below lo and those in the band
  // straddle k; otherwise the sample was unlucky and the whole array is searched.
  if (below <= k && k < below + in_band) {
    std::nth_element(band_.begin(), band_.begin() + long(k - below), band_.begin() + long(in_band));
    return band_[k - below];
  }
  std::nth_element(values, values + k, values + n);
  return values[k];
}

}  // namespace nidevo
