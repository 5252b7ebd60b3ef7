#include "process_metrics.hpp"

#include <sys/resource.h>
#include <unistd.h>

#include <filesystem>
#include <fstream>
#include <iterator>
#include <sstream>

namespace nidevo::server {
namespace {

std::string readWhole(const char* path) {
  std::ifstream in(path);
  return std::string(std::istreambuf_iterator<char>(in), std::istreambuf_iterator<char>());
}

prometheus::MetricFamily family(const std::string& name, const std::string& help,
                                prometheus::MetricType type, double value) {
  prometheus::ClientMetric metric;
  if (type == prometheus::MetricType::Counter) {
    metric.counter.value = value;
  } else {
    metric.gauge.value = value;
  }
  return {name, help, type, {metric}};
}

}  // namespace

std::optional<ProcessStats> parseProcStat(const std::string& stat, double ticks_per_second,
                                          double page_bytes, double boot_time_s) {
  // The command name (field 2) is in parentheses and may hold spaces or ')': fields are counted
  // from the last ')'. After it come field 3 (state) onwards.
  const size_t close = stat.rfind(')');
  if (close == std::string::npos || ticks_per_second <= 0) return std::nullopt;
  std::istringstream in(stat.substr(close + 1));
  std::vector<std::string> fields{std::istream_iterator<std::string>(in),
                                  std::istream_iterator<std::string>()};
  // Fields 14 (utime), 15 (stime), 22 (starttime), 23 (vsize), 24 (rss) are at 11, 12, 19, 20,
  // 21 here.
  if (fields.size() < 22) return std::nullopt;
  try {
    ProcessStats s;
    s.cpu_seconds = (std::stod(fields[11]) + std::stod(fields[12])) / ticks_per_second;
    s.start_time_seconds = boot_time_s + std::stod(fields[19]) / ticks_per_second;
    s.virtual_bytes = std::stod(fields[20]);
    s.resident_bytes = std::stod(fields[21]) * page_bytes;
    return s;
  } catch (const std::exception&) {  // not numbers where numbers belong
    return std::nullopt;
  }
}

std::optional<double> parseBootTime(const std::string& proc_stat) {
  std::istringstream in(proc_stat);
  std::string line;
  while (std::getline(in, line)) {
    if (line.rfind("btime ", 0) != 0) continue;
    try {
      return std::stod(line.substr(6));
    } catch (const std::exception&) {
      return std::nullopt;
    }
  }
  return std::nullopt;
}

std::optional<ProcessStats> readProcessStats() {
  const auto boot = parseBootTime(readWhole("/proc/stat"));
  if (!boot) return std::nullopt;
  auto stats = parseProcStat(readWhole("/proc/self/stat"), double(sysconf(_SC_CLK_TCK)),
                             double(sysconf(_SC_PAGESIZE)), *boot);
  if (!stats) return std::nullopt;
  std::error_code error;
  for (auto it = std::filesystem::directory_iterator("/proc/self/fd", error);
       !error && it != std::filesystem::directory_iterator(); it.increment(error))
    stats->open_fds += 1;
  rlimit limit{};
  if (getrlimit(RLIMIT_NOFILE, &limit) == 0) stats->max_fds = double(limit.rlim_cur);
  return stats;
}

std::vector<prometheus::MetricFamily> ProcessCollector::Collect() const {
  const auto s = readProcessStats();
  if (!s) return {};
  using prometheus::MetricType;
  return {
      family("process_cpu_seconds_total", "Total user and system CPU time spent in seconds.",
             MetricType::Counter, s->cpu_seconds),
      family("process_resident_memory_bytes", "Resident memory size in bytes.", MetricType::Gauge,
             s->resident_bytes),
      family("process_virtual_memory_bytes", "Virtual memory size in bytes.", MetricType::Gauge,
             s->virtual_bytes),
      family("process_start_time_seconds", "Start time of the process since unix epoch in seconds.",
             MetricType::Gauge, s->start_time_seconds),
      family("process_open_fds", "Number of open file descriptors.", MetricType::Gauge,
             s->open_fds),
      family("process_max_fds", "Maximum number of open file descriptors.", MetricType::Gauge,
             s->max_fds),
  };
}

}  // namespace nidevo::server
