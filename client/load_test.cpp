#include "load_test.hpp"

#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <limits>
#include <memory>
#include <mutex>
#include <random>
#include <sstream>
#include <thread>
#include <unordered_map>

#include "cpu_affinity.hpp"

namespace nidevo::client {

namespace {

using Clock = std::chrono::steady_clock;

double seconds(Clock::duration d) { return std::chrono::duration<double>(d).count(); }

struct SessionRun {
  std::mutex mutex;
  std::unordered_map<uint64_t, Clock::time_point> in_flight;  // sequence -> send time
  uint64_t sent = 0, ok = 0, degraded = 0, lost = 0, dropped = 0, error = 0;
  std::vector<FrameTiming> timings;            // tracked, sent in the window, with server timings
  std::vector<std::vector<double>> thirds{3};  // their send to answer, by third of the window
  uint64_t window_tracked = 0, window_dropped = 0;
  grpc::Status status;
};

struct Window {
  Clock::time_point start, end;
};

// `shared`: the one channel of every session, or null for a channel of the session's own.
void runSession(const LoadTestConfig& config, const std::vector<v1::Frame>& frames,
                Clock::time_point first_send, const Window& window, Client* shared,
                SessionRun* run) {
  std::unique_ptr<Client> own;
  if (!shared) own = std::make_unique<Client>(config.channel);
  Client& client = shared ? *shared : *own;
  auto on_answer = [run, &window](const v1::TrackResponse& r) {
    const Clock::time_point now = Clock::now();
    std::lock_guard<std::mutex> lock(run->mutex);
    auto it = run->in_flight.find(r.sequence());
    if (it == run->in_flight.end()) {  // a sequence never sent: the accounting will not close
      ++run->error;
      return;
    }
    const Clock::time_point sent_at = it->second;
    run->in_flight.erase(it);
    const bool tracked = r.status() == v1::FRAME_STATUS_OK ||
                         r.status() == v1::FRAME_STATUS_DEGRADED ||
                         r.status() == v1::FRAME_STATUS_LOST;
    switch (r.status()) {
      case v1::FRAME_STATUS_OK:
        ++run->ok;
        break;
      case v1::FRAME_STATUS_DEGRADED:
        ++run->degraded;
        break;
      case v1::FRAME_STATUS_LOST:
        ++run->lost;
        break;
      case v1::FRAME_STATUS_DROPPED:
        ++run->dropped;
        break;
      default:
        ++run->error;
        break;
    }
    if (sent_at < window.start || sent_at >= window.end) return;
    if (tracked) {
      const double latency = seconds(now - sent_at);
      const v1::ServerTimings& t = r.timings();
      run->timings.push_back({latency, t.total(), t.queue(), t.decode(),
                              t.normals() + t.rotation() + t.translation()});
      const double f = seconds(sent_at - window.start) / seconds(window.end - window.start);
      run->thirds[std::min<size_t>(2, size_t(f * 3))].push_back(latency);
      ++run->window_tracked;
    } else if (r.status() == v1::FRAME_STATUS_DROPPED) {
      ++run->window_dropped;
    }
  };
  std::unique_ptr<Session> session;
  try {
    session = client.open(config.session, on_answer);
  } catch (const std::exception& e) {
    run->status = grpc::Status(grpc::StatusCode::UNAVAILABLE, e.what());
    return;
  }
  v1::Frame frame;
  for (uint64_t i = 0;; ++i) {
    if (config.rate_hz > 0)
      std::this_thread::sleep_until(
          first_send + std::chrono::microseconds(int64_t(1e6 * double(i) / config.rate_hz)));
    const Clock::time_point now = Clock::now();
    if (now >= window.end) break;
    frame = frames[i % frames.size()];
    frame.set_sequence(i);
    frame.set_timestamp(double(i) / (config.rate_hz > 0 ? config.rate_hz : 30.0));
    {
      std::lock_guard<std::mutex> lock(run->mutex);
      run->in_flight[i] = now;
      ++run->sent;
    }
    if (!session->send(&frame)) break;
  }
  run->status = session->finish();
}

double delta(const MetricSamples& after, const MetricSamples& before, const std::string& s) {
  return valueOf(after, s) - valueOf(before, s);
}

}  // namespace

double sessionPhaseS(LoadTestConfig::Phase phase, int session, double rate_hz) {
  if (phase == LoadTestConfig::Phase::kAligned || !(rate_hz > 0)) return 0;
  std::mt19937 random(uint32_t(session) + 1);
  return std::uniform_real_distribution<double>(0, 1 / rate_hz)(random);
}

LatencySummary summarize(std::vector<double> v) {
  LatencySummary s;
  s.count = v.size();
  if (v.empty()) return s;
  std::sort(v.begin(), v.end());
  // Nearest-rank percentiles: every figure is a latency that was really observed.
  auto rank = [&](double q) {
    const size_t k = size_t(std::ceil(q * double(v.size())));
    return v[std::min(v.size(), std::max<size_t>(k, 1)) - 1];
  };
  s.p50 = rank(0.50);
  s.p90 = rank(0.90);
  s.p95 = rank(0.95);
  s.p99 = rank(0.99);
  s.max = v.back();
  return s;
}

LatencyBreakdown breakdownOf(const std::vector<FrameTiming>& frames) {
  LatencyBreakdown b;
  b.count = frames.size();
  if (frames.empty()) return b;
  auto median = [&](auto part) {
    std::vector<double> v;
    v.reserve(frames.size());
    for (const FrameTiming& f : frames) v.push_back(part(f));
    return summarize(std::move(v)).p50;
  };
  b.send_to_answer = median([](const FrameTiming& f) { return f.send_to_answer; });
  b.outside_server = median([](const FrameTiming& f) { return f.send_to_answer - f.server_total; });
  b.server_total = median([](const FrameTiming& f) { return f.server_total; });
  b.queue = median([](const FrameTiming& f) { return f.queue; });
  b.decode = median([](const FrameTiming& f) { return f.decode; });
  b.stages = median([](const FrameTiming& f) { return f.stages; });
  b.hand_offs =
      median([](const FrameTiming& f) { return f.server_total - f.queue - f.decode - f.stages; });
  return b;
}

double histogramQuantile(double q, const std::map<double, double>& buckets) {
  if (buckets.empty()) return 0;
  const double total = buckets.rbegin()->second;
  if (total <= 0) return 0;
  const double rank = q * total;
  double lower = 0, below = 0;
  for (const auto& [upper, count] : buckets) {
    if (count >= rank) {
      if (std::isinf(upper)) return lower;  // like histogram_quantile: the highest finite bound
      const double in_bucket = count - below;
      return in_bucket > 0 ? lower + (upper - lower) * (rank - below) / in_bucket : upper;
    }
    lower = upper;
    below = count;
  }
  return lower;
}

LoadTestResult runLoadTest(const LoadTestConfig& config, const std::vector<v1::Frame>& frames) {
  if (frames.empty()) throw std::invalid_argument("load test: no frames");
  if (config.sessions < 1) throw std::invalid_argument("sessions: must be at least 1");
  if (!(config.duration_s > 0)) throw std::invalid_argument("duration_s: must be positive");
  MetricSamples before;
  if (!config.metrics_url.empty()) before = parsePrometheusText(httpGet(config.metrics_url));
  const double tester_cpu_before = processCpuSeconds();
  const Clock::time_point step_start = Clock::now();
  std::unique_ptr<Client> shared;
  if (config.shared_channel) shared = std::make_unique<Client>(config.channel);

  std::vector<SessionRun> runs(size_t(config.sessions));
  const Clock::time_point t0 = Clock::now() + std::chrono::milliseconds(100);
  Window window;
  window.start = t0 + std::chrono::microseconds(int64_t(config.warmup_s * 1e6));
  window.end = window.start + std::chrono::microseconds(int64_t(config.duration_s * 1e6));
  std::vector<std::thread> threads;
  for (size_t k = 0; k < runs.size(); ++k) {
    const auto phase = std::chrono::microseconds(
        int64_t(1e6 * sessionPhaseS(config.phase, int(k), config.rate_hz)));
    threads.emplace_back(
        [&, k, phase] { runSession(config, frames, t0 + phase, window, shared.get(), &runs[k]); });
  }
  for (auto& t : threads) t.join();

  LoadTestResult result;
  result.tester_cpu_s = processCpuSeconds() - tester_cpu_before;
  result.step_s = seconds(Clock::now() - step_start);
  result.sessions = config.sessions;
  result.window_s = config.duration_s;
  std::vector<FrameTiming> timings;
  std::vector<std::vector<double>> thirds(3);
  uint64_t window_tracked = 0;
  for (auto& run : runs) {
    result.sent += run.sent;
    result.ok += run.ok;
    result.degraded += run.degraded;
    result.lost += run.lost;
    result.dropped += run.dropped;
    result.error += run.error;
    result.unanswered += run.in_flight.size();
    ++result.session_status[statusCodeName(run.status.error_code())];
    timings.insert(timings.end(), run.timings.begin(), run.timings.end());
    for (size_t k = 0; k < 3; ++k)
      thirds[k].insert(thirds[k].end(), run.thirds[k].begin(), run.thirds[k].end());
    window_tracked += run.window_tracked;
    result.window_dropped += double(run.window_dropped);
  }
  const uint64_t answered =
      result.ok + result.degraded + result.lost + result.dropped + result.error;
  result.accounting_closed = result.sent == answered + result.unanswered;
  std::vector<double> latencies;
  latencies.reserve(timings.size());
  for (const FrameTiming& f : timings) latencies.push_back(f.send_to_answer);
  result.latency = summarize(std::move(latencies));
  result.breakdown = breakdownOf(timings);
  result.poses_per_s = double(window_tracked) / config.duration_s;
  double lo = std::numeric_limits<double>::infinity(), hi = 0;
  for (auto& third : thirds) {
    const double p50 = summarize(third).p50;
    result.sub_window_p50.push_back(p50);
    lo = std::min(lo, p50);
    hi = std::max(hi, p50);
  }
  result.stable = lo > 0 && hi <= 1.2 * lo;

  if (!config.metrics_url.empty()) {
    const MetricSamples after = parsePrometheusText(httpGet(config.metrics_url));
    result.have_server_view = true;
    result.server_frames =
        sumOf(after, "nidevo_frames_total") - sumOf(before, "nidevo_frames_total");
    const double count = delta(after, before, "nidevo_frame_latency_seconds_count");
    if (count > 0)
      result.server_mean_latency_s =
          delta(after, before, "nidevo_frame_latency_seconds_sum") / count;
    std::map<double, double> buckets;
    const std::string prefix = "nidevo_frame_latency_seconds_bucket{le=\"";
    for (const auto& [series, value] : after) {
      if (series.compare(0, prefix.size(), prefix) != 0) continue;
      const std::string le = series.substr(prefix.size(), series.size() - prefix.size() - 2);
      const double bound = le == "+Inf" ? std::numeric_limits<double>::infinity() : std::stod(le);
      buckets[bound] = value - valueOf(before, series);
    }
    result.server_p99_latency_s = histogramQuantile(0.99, buckets);
    // Everything the server process did in the interval, dropped frames' reception included,
    // over the frames it tracked.
    result.server_cpu_s = delta(after, before, "process_cpu_seconds_total");
    if (count > 0) result.server_cpu_s_per_tracked_frame = result.server_cpu_s / count;
  }
  return result;
}

std::string formatTable(const std::vector<LoadTestResult>& steps) {
  std::ostringstream out;
  char line[512];
  std::snprintf(line, sizeof(line), "%8s %10s %8s %8s %8s %8s %8s %8s %8s %7s %6s %s\n", "sessions",
                "poses/s", "p50 ms", "p90 ms", "p95 ms", "p99 ms", "max ms", "dropped", "errors",
                "stable", "books", "sessions ended");
  out << line;
  for (const auto& r : steps) {
    std::string ended;
    for (const auto& [code, n] : r.session_status) ended += code + " x" + std::to_string(n) + " ";
    std::snprintf(line, sizeof(line),
                  "%8d %10.1f %8.2f %8.2f %8.2f %8.2f %8.2f %8llu %8llu %7s %6s %s\n", r.sessions,
                  r.poses_per_s, 1e3 * r.latency.p50, 1e3 * r.latency.p90, 1e3 * r.latency.p95,
                  1e3 * r.latency.p99, 1e3 * r.latency.max, (unsigned long long)r.dropped,
                  (unsigned long long)r.error, r.stable ? "yes" : "no",
                  r.accounting_closed ? "closed" : "OPEN", ended.c_str());
    out << line;
  }
  for (const auto& r : steps) {
    std::snprintf(line, sizeof(line),
                  "accounting, %d sessions: sent %llu = ok %llu + degraded %llu + lost %llu + "
                  "dropped %llu + error %llu + unanswered %llu%s\n",
                  r.sessions, (unsigned long long)r.sent, (unsigned long long)r.ok,
                  (unsigned long long)r.degraded, (unsigned long long)r.lost,
                  (unsigned long long)r.dropped, (unsigned long long)r.error,
                  (unsigned long long)r.unanswered,
                  r.accounting_closed ? "" : "  <-- DOES NOT ADD UP");
    out << line;
    std::snprintf(line, sizeof(line),
                  "load tester, %d sessions: %.2f CPU s in %.1f s (%.2f cores)\n", r.sessions,
                  r.tester_cpu_s, r.step_s, r.step_s > 0 ? r.tester_cpu_s / r.step_s : 0.0);
    out << line;
    const LatencyBreakdown& b = r.breakdown;
    if (b.count > 0) {
      std::snprintf(line, sizeof(line),
                    "time per frame, %d sessions (medians of %zu): send to answer %.2f ms = "
                    "outside the server %.2f + server %.2f (queue %.2f, decode %.2f, stages %.2f, "
                    "hand-offs %.2f)\n",
                    r.sessions, b.count, 1e3 * b.send_to_answer, 1e3 * b.outside_server,
                    1e3 * b.server_total, 1e3 * b.queue, 1e3 * b.decode, 1e3 * b.stages,
                    1e3 * b.hand_offs);
      out << line;
    }
    if (r.have_server_view) {
      std::snprintf(line, sizeof(line),
                    "server view, %d sessions: %.0f frames answered, mean %.2f ms, p99 %.2f ms "
                    "(arrival to answer, from /metrics); CPU %.2f s, %.2f ms per tracked frame\n",
                    r.sessions, r.server_frames, 1e3 * r.server_mean_latency_s,
                    1e3 * r.server_p99_latency_s, r.server_cpu_s,
                    1e3 * r.server_cpu_s_per_tracked_frame);
      out << line;
    }
  }
  return out.str();
}

std::string formatCsv(const std::vector<LoadTestResult>& steps) {
  std::ostringstream out;
  out << "sessions,window_s,poses_per_s,p50_s,p90_s,p95_s,p99_s,max_s,sent,ok,degraded,lost,"
         "dropped,error,unanswered,accounting_closed,stable,server_frames,server_mean_s,"
         "server_p99_s,server_cpu_s,server_cpu_s_per_tracked_frame,tester_cpu_s,step_s,"
         "median_outside_server_s,median_server_total_s,median_queue_s,median_decode_s,"
         "median_stages_s,median_hand_offs_s\n";
  for (const auto& r : steps)
    out << r.sessions << ',' << r.window_s << ',' << r.poses_per_s << ',' << r.latency.p50 << ','
        << r.latency.p90 << ',' << r.latency.p95 << ',' << r.latency.p99 << ',' << r.latency.max
        << ',' << r.sent << ',' << r.ok << ',' << r.degraded << ',' << r.lost << ',' << r.dropped
        << ',' << r.error << ',' << r.unanswered << ',' << (r.accounting_closed ? 1 : 0) << ','
        << (r.stable ? 1 : 0) << ',' << r.server_frames << ',' << r.server_mean_latency_s << ','
        << r.server_p99_latency_s << ',' << r.server_cpu_s << ','
        << r.server_cpu_s_per_tracked_frame << ',' << r.tester_cpu_s << ',' << r.step_s << ','
        << r.breakdown.outside_server << ',' << r.breakdown.server_total << ',' << r.breakdown.queue
        << ',' << r.breakdown.decode << ',' << r.breakdown.stages << ',' << r.breakdown.hand_offs
        << '\n';
  return out.str();
}

std::string formatJson(const std::vector<LoadTestResult>& steps) {
  std::ostringstream out;
  out.precision(9);
  out << "[\n";
  for (size_t i = 0; i < steps.size(); ++i) {
    const auto& r = steps[i];
    out << "  {\"sessions\": " << r.sessions << ", \"window_s\": " << r.window_s
        << ", \"poses_per_s\": " << r.poses_per_s << ", \"latency_s\": {\"p50\": " << r.latency.p50
        << ", \"p90\": " << r.latency.p90 << ", \"p95\": " << r.latency.p95
        << ", \"p99\": " << r.latency.p99 << ", \"max\": " << r.latency.max
        << ", \"count\": " << r.latency.count << "}, \"sent\": " << r.sent << ", \"ok\": " << r.ok
        << ", \"degraded\": " << r.degraded << ", \"lost\": " << r.lost
        << ", \"dropped\": " << r.dropped << ", \"error\": " << r.error
        << ", \"unanswered\": " << r.unanswered
        << ", \"accounting_closed\": " << (r.accounting_closed ? "true" : "false")
        << ", \"stable\": " << (r.stable ? "true" : "false")
        << ", \"tester_cpu_s\": " << r.tester_cpu_s << ", \"step_s\": " << r.step_s
        << ", \"median_s\": {\"send_to_answer\": " << r.breakdown.send_to_answer
        << ", \"outside_server\": " << r.breakdown.outside_server
        << ", \"server_total\": " << r.breakdown.server_total
        << ", \"queue\": " << r.breakdown.queue << ", \"decode\": " << r.breakdown.decode
        << ", \"stages\": " << r.breakdown.stages << ", \"hand_offs\": " << r.breakdown.hand_offs
        << "}, \"sessions_ended\": {";
    size_t k = 0;
    for (const auto& [code, n] : r.session_status)
      out << (k++ ? ", " : "") << '"' << code << "\": " << n;
    out << "}";
    if (r.have_server_view)
      out << ", \"server\": {\"frames\": " << r.server_frames
          << ", \"mean_latency_s\": " << r.server_mean_latency_s
          << ", \"p99_latency_s\": " << r.server_p99_latency_s << ", \"cpu_s\": " << r.server_cpu_s
          << ", \"cpu_s_per_tracked_frame\": " << r.server_cpu_s_per_tracked_frame << "}";
    out << "}" << (i + 1 < steps.size() ? "," : "") << "\n";
  }
  out << "]\n";
  return out.str();
}

}  // namespace nidevo::client
