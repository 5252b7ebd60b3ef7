#pragma once
// The standard process metrics of Prometheus clients (process_cpu_seconds_total,
// process_resident_memory_bytes, ...), which prometheus-cpp does not export itself, read from
// /proc at each scrape.
#include <optional>
#include <string>
#include <vector>

#include "prometheus/collectable.h"
#include "prometheus/metric_family.h"

namespace nidevo::server {

struct ProcessStats {
  double cpu_seconds = 0;  // user + system
  double resident_bytes = 0;
  double virtual_bytes = 0;
  double start_time_seconds = 0;  // since the Unix epoch
  double open_fds = 0;
  double max_fds = 0;  // the soft limit
};

// The fields of /proc/<pid>/stat that ProcessStats needs, from its text; `boot_time_s` is the
// `btime` of /proc/stat. Empty when the text is not such a line.
std::optional<ProcessStats> parseProcStat(const std::string& stat, double ticks_per_second,
                                          double page_bytes, double boot_time_s);
// The `btime` line of /proc/stat; empty when absent.
std::optional<double> parseBootTime(const std::string& proc_stat);

// This process, now. Empty where /proc is not there (the metrics are then left out).
std::optional<ProcessStats> readProcessStats();

class ProcessCollector : public prometheus::Collectable {
 public:
  std::vector<prometheus::MetricFamily> Collect() const override;
};

}  // namespace nidevo::server
