#pragma once
// Subsampling loops read every stride-th pixel; with the stride a compile-time constant the
// compiler vectorises those strided loads (with a runtime stride it does not).
#include <type_traits>

namespace nidevo {

// Calls f(stride) with the stride as a std::integral_constant where it is the usual 1 or 2,
// else as the int it is. f must be generic in the stride's type.
template <class F>
void withConstantStride(int stride, F&& f) {
  if (stride == 2) {
    f(std::integral_constant<int, 2>{});
  } else if (stride == 1) {
    f(std::integral_constant<int, 1>{});
  } else {
    f(stride);
  }
}

}  // namespace nidevo
