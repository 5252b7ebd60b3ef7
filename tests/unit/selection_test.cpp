#include "nidevo/odometry/selection.hpp"

#include <gtest/gtest.h>

#include <algorithm>
#include <limits>
#include <random>
#include <string>
#include <vector>

namespace nidevo {
namespace {

float reference(std::vector<float> values, size_t k) {
  std::nth_element(values.begin(), values.begin() + long(k), values.end());
  return values[k];
}

// Arrays small and large, shaped to defeat a sample: sorted, reversed, many ties, a few huge
// outliers where the sample sees none, infinities (how the projector marks points without depth).
std::vector<std::pair<std::string, std::vector<float>>> arrays() {
  std::mt19937 rng(3);
  std::uniform_real_distribution<float> unit(0.f, 1.f);
  std::vector<std::pair<std::string, std::vector<float>>> out;
  for (size_t n :
       {size_t(1), size_t(100), size_t(1024), size_t(1025), size_t(4097), size_t(76800)}) {
    std::vector<float> uniform(n), sorted(n), ties(n), outliers(n), with_inf(n);
    for (size_t i = 0; i < n; ++i) {
      uniform[i] = unit(rng);
      ties[i] = float(int(unit(rng) * 5));
      // Off the sample's grid (every 16th): values the sample never sees.
      outliers[i] = i % 16 == 7 ? 1e6f + float(i) : unit(rng);
      with_inf[i] = i % 3 == 0 ? std::numeric_limits<float>::infinity() : unit(rng);
    }
    sorted = uniform;
    std::sort(sorted.begin(), sorted.end());
    std::vector<float> reversed(sorted.rbegin(), sorted.rend());
    const std::string size = " n=" + std::to_string(n);
    out.push_back({"uniform" + size, uniform});
    out.push_back({"sorted" + size, sorted});
    out.push_back({"reversed" + size, reversed});
    out.push_back({"ties" + size, ties});
    out.push_back({"outliers" + size, outliers});
    out.push_back({"with_inf" + size, with_inf});
  }
  return out;
}

TEST(KthSmallest, EqualsNthElementAtEveryQuantile) {
  KthSmallest select;
  for (const auto& [name, values] : arrays()) {
    const size_t n = values.size();
    for (double f : {0.0, 0.01, 0.25, 0.5, 0.8, 0.9, 0.99, 1.0}) {
      const size_t k = std::min(n - 1, size_t(f * double(n)));
      std::vector<float> work = values;
      EXPECT_EQ(select(work.data(), n, k), reference(values, k)) << name << " k=" << k;
    }
  }
}

}  // namespace
}  // namespace nidevo
