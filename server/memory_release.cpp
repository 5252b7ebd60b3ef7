#include "memory_release.hpp"

#include <cstdlib>  // defines __GLIBC__ on glibc
#if defined(__GLIBC__)
#include <malloc.h>
#endif

namespace nidevo::server {

bool releaseFreedMemory() {
#if defined(__GLIBC__)
  malloc_trim(0);
  return true;
#else
  return false;
#endif
}

bool keepFrameBuffersMapped() {
#if defined(__GLIBC__)
  if (!kGlibcHeap) return false;
  // Setting either turns off glibc's dynamic thresholds; both are needed (measured: either alone
  // made it worse, 300-390 faults per frame).
  return mallopt(M_MMAP_THRESHOLD, kLargestMappedBlockBytes) == 1 &&
         mallopt(M_TRIM_THRESHOLD, kKeptFreeTopBytes) == 1;
#else
  return false;
#endif
}

std::optional<double> heapAllocatedBytes() {
#if defined(__GLIBC__)
  if (!kGlibcHeap) return std::nullopt;
  const struct mallinfo2 info = mallinfo2();
  return double(info.uordblks) + double(info.hblkhd);
#else
  return std::nullopt;
#endif
}

std::vector<prometheus::MetricFamily> HeapCollector::Collect() const {
  const std::optional<double> bytes = heapAllocatedBytes();
  if (!bytes) return {};
  prometheus::ClientMetric metric;
  metric.gauge.value = *bytes;
  return {{"nidevo_heap_allocated_bytes",
           "Heap bytes allocated and not freed (glibc mallinfo2: uordblks + hblkhd).",
           prometheus::MetricType::Gauge,
           {metric}}};
}

}  // namespace nidevo::server
