#pragma once
// Replaces the global operator new to count allocations while `counting` is set. Include it in
// exactly one source file of a test binary of its own (the replacement is program-wide).
#include <atomic>
#include <cstdlib>
#include <new>

namespace nidevo::test {
inline std::atomic<bool> counting{false};
inline std::atomic<long> allocations{0};
}  // namespace nidevo::test

void* operator new(std::size_t size) {
  if (nidevo::test::counting) ++nidevo::test::allocations;
  if (void* p = std::malloc(size ? size : 1)) return p;
  throw std::bad_alloc();
}
void operator delete(void* p) noexcept { std::free(p); }
void operator delete(void* p, std::size_t) noexcept { std::free(p); }
