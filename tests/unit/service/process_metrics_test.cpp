// The standard process metrics: /proc/<pid>/stat parsed on lines with a known answer, and this
// test process's own figures plausible.
#include "process_metrics.hpp"

#include <gtest/gtest.h>
#include <unistd.h>

#include <chrono>
#include <cmath>
#include <ctime>
#include <set>
#include <sstream>
#include <vector>

#include "memory_release.hpp"

namespace nidevo::server {
namespace {

// A /proc/<pid>/stat line: pid, a command with spaces and ')', then fields 3.. with utime 250,
// stime 50, starttime 1000, vsize 123456789, rss 2000 (pages) and zeros elsewhere.
std::string statLine() {
  std::ostringstream line;
  line << "4242 (nidevo) se(r)ver) S";
  for (int field = 4; field <= 52; ++field) {
    const char* value = "0";
    if (field == 14) value = "250";
    if (field == 15) value = "50";
    if (field == 22) value = "1000";
    if (field == 23) value = "123456789";
    if (field == 24) value = "2000";
    line << ' ' << value;
  }
  return line.str() + "\n";
}

TEST(ProcessMetrics, ProcStatFieldsAreCountedFromTheLastParenthesis) {
  const auto s = parseProcStat(statLine(), 100, 4096, 1.7e9);
  ASSERT_TRUE(s.has_value());
  EXPECT_DOUBLE_EQ(s->cpu_seconds, 3.0);  // (250 + 50) / 100
  EXPECT_DOUBLE_EQ(s->start_time_seconds, 1.7e9 + 10.0);
  EXPECT_DOUBLE_EQ(s->virtual_bytes, 123456789.0);
  EXPECT_DOUBLE_EQ(s->resident_bytes, 2000.0 * 4096);
}

TEST(ProcessMetrics, ATruncatedOrGarbledStatIsRefused) {
  EXPECT_FALSE(parseProcStat("", 100, 4096, 0).has_value());
  EXPECT_FALSE(parseProcStat("4242 (nidevo) S 1 2 3", 100, 4096, 0).has_value());
  std::string garbled = statLine();
  garbled.replace(garbled.find(" 250 "), 5, " x50 ");
  EXPECT_FALSE(parseProcStat(garbled, 100, 4096, 0).has_value());
  EXPECT_FALSE(parseProcStat(statLine(), 0, 4096, 0).has_value());
}

TEST(ProcessMetrics, BootTimeIsTheBtimeLine) {
  EXPECT_EQ(parseBootTime("cpu  1 2 3\nintr 5\nbtime 1764547200\nprocesses 9\n"), 1764547200.0);
  EXPECT_FALSE(parseBootTime("cpu  1 2 3\n").has_value());
  EXPECT_FALSE(parseBootTime("btime soon\n").has_value());
}

TEST(ProcessMetrics, ThisProcessHasPlausibleFiguresAndItsCpuTimeGrows) {
  const auto before = readProcessStats();
  ASSERT_TRUE(before.has_value());
  volatile double sink = 0;
  const auto until = std::chrono::steady_clock::now() + std::chrono::milliseconds(200);
  while (std::chrono::steady_clock::now() < until) sink = sink + std::sqrt(double(sink) + 1);
  const auto after = readProcessStats();
  ASSERT_TRUE(after.has_value());
  EXPECT_GT(after->cpu_seconds, before->cpu_seconds);  // 200 ms busy: at least a clock tick
  EXPECT_GT(after->resident_bytes, 1e6);
  EXPECT_GE(after->virtual_bytes, after->resident_bytes);
  EXPECT_GE(after->open_fds, 3);  // stdin, stdout, stderr
  EXPECT_GE(after->max_fds, after->open_fds);
  const double now = double(std::time(nullptr));
  EXPECT_LE(after->start_time_seconds, now + 1);
  EXPECT_GT(after->start_time_seconds, now - 24 * 3600.0);  // this test started recently
}

TEST(ProcessMetrics, TheCollectorExportsTheSixStandardFamilies) {
  const auto families = ProcessCollector().Collect();
  std::set<std::string> names;
  for (const auto& f : families) {
    names.insert(f.name);
    ASSERT_EQ(f.metric.size(), 1u) << f.name;
  }
  EXPECT_EQ(names,
            (std::set<std::string>{"process_cpu_seconds_total", "process_resident_memory_bytes",
                                   "process_virtual_memory_bytes", "process_start_time_seconds",
                                   "process_open_fds", "process_max_fds"}));
}

// The heap gauge follows what this process allocates and frees, to within a few pages.
TEST(HeapMetrics, AllocatedBytesFollowAnAllocationAndItsRelease) {
  const std::optional<double> before = heapAllocatedBytes();
  if (!kGlibcHeap) {
    EXPECT_FALSE(before.has_value()) << "a sanitizer's malloc: glibc's count means nothing";
    EXPECT_TRUE(HeapCollector().Collect().empty());
    return;
  }
  ASSERT_TRUE(before.has_value()) << "glibc: mallinfo2 is there";
  constexpr size_t kBytes = 64u << 20;
  auto block = std::make_unique<std::vector<char>>(kBytes, 1);
  const double held = *heapAllocatedBytes();
  EXPECT_NEAR(held - *before, double(kBytes), 1 << 20);
  block.reset();
  EXPECT_NEAR(*heapAllocatedBytes(), *before, 1 << 20);
  const auto families = HeapCollector().Collect();
  ASSERT_EQ(families.size(), 1u);
  EXPECT_EQ(families[0].name, "nidevo_heap_allocated_bytes");
  EXPECT_NEAR(families[0].metric.at(0).gauge.value, *before, 1 << 20);
}

}  // namespace
}  // namespace nidevo::server
