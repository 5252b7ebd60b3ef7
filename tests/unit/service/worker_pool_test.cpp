#include "worker_pool.hpp"

#include <gtest/gtest.h>

#include <atomic>
#include <set>
#include <stdexcept>

namespace nidevo {
namespace {

TEST(WorkerPool, RunsEveryTaskOnItsThreadsAndDrainsOnDestruction) {
  std::atomic<int> done{0};
  std::mutex mutex;
  std::set<std::thread::id> threads;
  {
    server::WorkerPool pool(3);
    EXPECT_EQ(pool.size(), 3);
    for (int i = 0; i < 1000; ++i)
      pool.submit([&] {
        {
          std::lock_guard<std::mutex> lock(mutex);
          threads.insert(std::this_thread::get_id());
        }
        ++done;
      });
  }
  EXPECT_EQ(done.load(), 1000);
  EXPECT_LE(threads.size(), 3u);
  EXPECT_EQ(threads.count(std::this_thread::get_id()), 0u);
}

TEST(WorkerPool, RejectsZeroThreads) { EXPECT_THROW(server::WorkerPool(0), std::invalid_argument); }

}  // namespace
}  // namespace nidevo
