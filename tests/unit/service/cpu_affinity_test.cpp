// The load tester's CPU list, pinning and own CPU time.
#include "cpu_affinity.hpp"

#include <gtest/gtest.h>

#include <chrono>
#include <cmath>
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

TEST(CpuAffinity, ProcessCpuTimeGrowsWhenBusy) {
  const double before = processCpuSeconds();
  volatile double sink = 0;
  const auto until = std::chrono::steady_clock::now() + std::chrono::milliseconds(100);
  while (std::chrono::steady_clock::now() < until) sink = sink + std::sqrt(double(sink) + 1);
  EXPECT_GT(processCpuSeconds() - before, 0.05);
}

}  // namespace
}  // namespace nidevo::client
