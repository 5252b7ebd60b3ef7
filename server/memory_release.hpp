#pragma once
// The heap memory the allocator keeps after sessions end: given back to the operating system,
// and what is still allocated, exported for leak checks.
#include <optional>
#include <vector>

#include "prometheus/collectable.h"
#include "prometheus/metric_family.h"

namespace nidevo::server {

// glibc keeps freed session buffers (images, FFT planes, gRPC messages) in its per-thread arenas,
// so after a burst of sessions the resident size stays near its peak. malloc_trim gives the free
// pages back. It walks every arena under its lock, so the service calls it only when no session
// is open (nobody waits on an allocation then). True when the allocator supports it (glibc).
bool releaseFreedMemory();

// glibc hands blocks over its mmap threshold (128 KiB, raised on the fly) straight back to the
// operating system when freed, and trims a heap's free top over 128 KiB: every 0.9 MB frame
// message gRPC receives then faults its pages in anew (about 90 page faults per VGA frame, and a
// request path of 2-4 ms instead of 0.7 ms on one frame in four: docs/performance.md,
// "Capacity"). Fixed thresholds keep those blocks for the next frame; what sessions leave behind
// is still given back by releaseFreedMemory when none is open. Call once, before the first
// thread starts. True when the allocator supports it (glibc).
inline constexpr int kLargestMappedBlockBytes = 32 << 20;  // glibc's largest mmap threshold
// Room for a raw 1280x720 frame message (4.6 MB) with its receive slices; 64 MiB kept 1-2 MB more
// per session resident with 8 VGA sessions, for no fewer page faults.
inline constexpr int kKeptFreeTopBytes = 16 << 20;
bool keepFrameBuffersMapped();

// Whether malloc is glibc's: a sanitizer's allocator replaces it, and glibc then counts nothing.
#if defined(__SANITIZE_ADDRESS__) || defined(__SANITIZE_THREAD__)
inline constexpr bool kGlibcHeap = false;
#elif defined(__has_feature)
inline constexpr bool kGlibcHeap =
    !(__has_feature(address_sanitizer) || __has_feature(thread_sanitizer) ||
      __has_feature(memory_sanitizer));
#else
inline constexpr bool kGlibcHeap = true;
#endif

// Bytes the allocator has handed out and not got back, over every arena and the mmapped chunks
// (glibc mallinfo2: uordblks + hblkhd). Unlike the resident size it does not move with what the
// arenas keep or give back, so a leak shows in it at once. Empty without glibc's malloc.
std::optional<double> heapAllocatedBytes();

// nidevo_heap_allocated_bytes at each scrape (nothing without glibc).
class HeapCollector : public prometheus::Collectable {
 public:
  std::vector<prometheus::MetricFamily> Collect() const override;
};

}  // namespace nidevo::server
