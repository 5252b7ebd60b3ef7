#pragma once
#include <cstddef>

namespace nidevo {

// values[i] = std::exp(values[i]), the same bits as glibc's expf on this CPU, four or eight at a
// time where glibc itself runs its FMA variant (x86-64 with AVX2 and FMA): that variant's steps
// (a 32-entry table of 2^(i/32) and a cubic, in double precision) done in AVX2 lanes, and any
// value glibc treats apart (|x| >= 88, NaN) left to std::exp. Elsewhere a plain std::exp loop.
// The Gaussian kernel of the KCC takes one exp per response cell; glibc's scalar call was a
// twentieth of a frame's instructions.
void expInPlace(float* values, size_t n);

// Whether expInPlace takes the vector path here (for tests and benchmarks).
bool expInPlaceIsVectorised();

}  // namespace nidevo
