#pragma once
// Network load tester: N concurrent sessions each stream a pre-encoded sequence in a loop at a
// given rate (or as fast as the server takes it); per-frame latency from send to answer,
// matched by sequence number, over a measurement window after a warm-up.
#include <map>
#include <string>
#include <vector>

#include "metrics_scrape.hpp"
#include "odometry_client.hpp"

namespace nidevo::client {

struct LoadTestConfig {
  ChannelOptions channel;
  SessionOptions session;  // camera, encodings, overload policy
  int sessions = 1;
  double rate_hz = 30;  // per session; 0: as fast as the server takes frames
  double warmup_s = 2;
  double duration_s = 10;   // measurement window after the warm-up
  std::string metrics_url;  // optional: the server's /metrics, scraped before and after
  // All sessions on one channel (one HTTP/2 connection), as one client process with many
  // streams; otherwise one channel each, as separate devices.
  bool shared_channel = false;
  // When in its frame period each session sends. Independent cameras are not synchronised:
  // kRandom gives each session its own phase, uniform over the period and the same in every run
  // (seeded by the session's index). kAligned sends every session's frame at the same instant,
  // the worst case, and what this tester did before the choice existed.
  enum class Phase { kRandom, kAligned };
  Phase phase = Phase::kRandom;
};

// Session k's send offset within the frame period, seconds (0 when aligned or unpaced).
double sessionPhaseS(LoadTestConfig::Phase phase, int session, double rate_hz);

struct LatencySummary {
  size_t count = 0;
  double p50 = 0, p90 = 0, p95 = 0, p99 = 0, max = 0;  // seconds
};
LatencySummary summarize(std::vector<double> latencies);

// Where a tracked frame's send-to-answer time went, as medians over the window's frames, from the
// server's timings in each answer: the parts need not add up exactly (medians of different
// frames). `outside_server`: each frame's send to answer minus its server total, i.e. the client
// library, gRPC on both ends and the transport, both ways.
struct LatencyBreakdown {
  size_t count = 0;
  double send_to_answer = 0, outside_server = 0, server_total = 0;  // seconds
  double queue = 0, decode = 0, stages = 0;                         // within the server total
  double hand_offs = 0;  // server total minus queue, decode and stages: scheduling, response
};
struct FrameTiming {  // one tracked frame, seconds
  double send_to_answer = 0, server_total = 0, queue = 0, decode = 0, stages = 0;
};
LatencyBreakdown breakdownOf(const std::vector<FrameTiming>& frames);

struct LoadTestResult {
  int sessions = 0;
  double window_s = 0;
  // Whole run (warm-up included): the accounting.
  uint64_t sent = 0;
  uint64_t ok = 0, degraded = 0, lost = 0, dropped = 0, error = 0;
  uint64_t unanswered = 0;                    // sent but never answered (only when a stream failed)
  std::map<std::string, int> session_status;  // final status code name -> sessions
  bool accounting_closed = false;             // sent == answered + unanswered
  // Measurement window: frames sent inside it.
  LatencySummary latency;              // tracked frames (ok/degraded/lost), send to answer
  LatencyBreakdown breakdown;          // the same frames, send to answer taken apart
  double poses_per_s = 0;              // tracked answers per second, all sessions
  double window_dropped = 0;           // dropped answers in the window
  std::vector<double> sub_window_p50;  // p50 of each third of the window
  bool stable = false;                 // the thirds' p50 agree within 20%
  // Server's view (when metrics_url is set): deltas over the run.
  bool have_server_view = false;
  double server_frames = 0;
  double server_mean_latency_s = 0;
  double server_p99_latency_s = 0;  // from histogram buckets, as histogram_quantile does
  double server_cpu_s = 0;          // process_cpu_seconds_total
  double server_cpu_s_per_tracked_frame = 0;
  // The load tester's own cost over the step (warm-up included), to see how much of a shared
  // machine it took.
  double tester_cpu_s = 0;
  double step_s = 0;  // wall time of the step
};

// Runs one step. `frames` are pre-encoded; sequence numbers and timestamps are rewritten.
LoadTestResult runLoadTest(const LoadTestConfig& config, const std::vector<v1::Frame>& frames);

// Quantile of a Prometheus histogram given cumulative bucket counts by upper bound.
double histogramQuantile(double q, const std::map<double, double>& cumulative_buckets);

// Human table, and machine formats with one row/object per step.
std::string formatTable(const std::vector<LoadTestResult>& steps);
std::string formatCsv(const std::vector<LoadTestResult>& steps);
std::string formatJson(const std::vector<LoadTestResult>& steps);

}  // namespace nidevo::client
