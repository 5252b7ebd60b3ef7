// The load tester's CPU list, pinning and own CPU time.
#include "cpu_affinity.hpp"

#include <gtest/gtest.h>

#include <chrono>
#include <cmath>
#include <ctime>
#include <stdexcept>

namespace nidevo::client {
namespace {

TEST(CpuAffinity, ListsAndRangesParseSortedAndUnique) {
  EXPECT_EQ(parseCpuList("0"), (std::vector<int>{0}));
  EXPECT_EQ(parseCpuList("3,0-1,1"), (std::vector<int>{0, 1, 3}));
  EXPECT_EQ(formatCpuList({0, 1, 2, 5, 7, 8}), "0-2,5,7-8");
  EXPECT_EQ(formatCpuList(parseCpuList("2-3,0")), "0,2-3");
}

TEST(CpuAffinity, BadListsNameThePart) {
  for (const char* bad : {"", "x", "1-", "-1", "3-1", "0,,1", "99999"}) {
    try {
      parseCpuList(bad);
      ADD_FAILURE() << "accepted '" << bad << "'";
    } catch (const std::invalid_argument& e) {
      EXPECT_NE(std::string(e.what()).find("--cpus"), std::string::npos) << e.what();
    }
  }
}

TEST(CpuAffinity, PinningToTheFirstAllowedCpuIsWhatTheThreadSees) {
  const std::vector<int> before = allowedCpus();
  ASSERT_FALSE(before.empty());
  pinProcessToCpus({before.front()});
  EXPECT_EQ(allowedCpus(), (std::vector<int>{before.front()}));
  pinProcessToCpus(before);  // as it was, for the other tests
  EXPECT_EQ(allowedCpus(), before);
}

double threadCpuSeconds() {
  timespec t{};
  clock_gettime(CLOCK_THREAD_CPUTIME_ID, &t);
  return double(t.tv_sec) + 1e-9 * double(t.tv_nsec);
}

// Busy for 0.1 s of this thread's own CPU time, not of wall time: on a loaded machine (CI runs
// tests in parallel) 100 ms of wall time gave only 28 ms of CPU.
TEST(CpuAffinity, ProcessCpuTimeGrowsWhenBusy) {
  const double before = processCpuSeconds();
  const double thread_before = threadCpuSeconds();
  volatile double sink = 0;
  const auto give_up = std::chrono::steady_clock::now() + std::chrono::seconds(30);
  while (threadCpuSeconds() - thread_before < 0.1 && std::chrono::steady_clock::now() < give_up)
    for (int k = 0; k < 1000; ++k) sink = sink + std::sqrt(double(sink) + 1);
  const double busy = threadCpuSeconds() - thread_before;
  ASSERT_GE(busy, 0.1) << "the machine gave this thread under 0.1 s of CPU in 30 s";
  // The process's clock counts this thread's time too; /proc's ticks are 10 ms.
  EXPECT_GT(processCpuSeconds() - before, busy - 0.02);
}

}  // namespace
}  // namespace nidevo::client
