#pragma once
// Exact order statistics (medians, quantiles) of float arrays, faster than std::nth_element on
// large arrays: a sample brackets the answer, and only the values inside the bracket are
// selected from. The result is always the value std::nth_element would put at rank k.
#include <cstddef>
#include <vector>

namespace nidevo {

class KthSmallest {
 public:
  // The value of rank k (0-based, ascending) among values[0, n); k < n, no NaN. The array may be
  // reordered. Reuses its buffers: no allocation once they have grown.
  float operator()(float* values, size_t n, size_t k);
  // Grows the buffers for arrays of up to n values now, so that later calls do not allocate.
  void reserve(size_t n);

 private:
  std::vector<float> sample_;
  std::vector<float> band_;
};

}  // namespace nidevo
