// keepFrameBuffersMapped: a frame-sized message received as growing slices, copied into one
// block and freed by another thread (as gRPC's reader and the session's worker do) faults its
// pages in anew on every frame with glibc's default thresholds, and not once with the server's.
// Its own binary: the allocator's thresholds are process-wide and cannot be set back.
#include <gtest/gtest.h>
#include <sys/resource.h>

#include <cstdlib>
#include <cstring>
#include <thread>
#include <vector>

#include "memory_release.hpp"

namespace nidevo::server {
namespace {

long minorFaults() {
  rusage usage{};
  getrusage(RUSAGE_SELF, &usage);
  return usage.ru_minflt;
}

// Page faults over `frames` receptions of a 0.9 MB frame after a few to settle.
long faultsPerFrames(int frames) {
  auto receive = [] {
    std::vector<char*> slices;
    for (size_t size : {size_t(8192), size_t(65536), size_t(262144), size_t(600000)}) {
      char* slice = static_cast<char*>(std::malloc(size));
      std::memset(slice, 1, size);
      slices.push_back(slice);
    }
    constexpr size_t kMessage = 935000;  // a raw 640x480 grey + depth frame
    char* message = static_cast<char*>(std::malloc(kMessage));
    std::memset(message, 2, kMessage);
    for (char* slice : slices) std::free(slice);
    std::thread worker([message] { std::free(message); });
    worker.join();
  };
  for (int i = 0; i < 5; ++i) receive();
  const long before = minorFaults();
  for (int i = 0; i < frames; ++i) receive();
  return minorFaults() - before;
}

TEST(FrameBufferReuse, KeptMappedAFrameMessageNoLongerFaultsItsPagesInEachTime) {
  if (!kGlibcHeap) GTEST_SKIP() << "not glibc's allocator (a sanitizer's replaces it)";
  const int frames = 20;
  const long with_defaults = faultsPerFrames(frames);
  ASSERT_TRUE(keepFrameBuffersMapped());
  const long kept = faultsPerFrames(frames);
  // 4 KiB pages: a message whose pages all fault again is about 230 faults per frame.
  EXPECT_GT(with_defaults, frames * 100) << "glibc's defaults no longer fault here: is the "
                                            "setting still needed?";
  EXPECT_LT(kept, frames) << "defaults: " << with_defaults;
}

}  // namespace
}  // namespace nidevo::server
