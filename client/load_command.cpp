// load: a sweep over session counts, each a warm-up plus a measurement window.
#include <cstdio>
#include <fstream>
#include <iostream>

#include "absl/flags/flag.h"
#include "absl/strings/numbers.h"
#include "absl/strings/str_split.h"
#include "client_flags.hpp"
#include "commands.hpp"
#include "cpu_affinity.hpp"
#include "frame_encoder.hpp"
#include "load_test.hpp"
#include "nidevo/cli/cli.hpp"
#include "nidevo/loader/frame_loader.hpp"
#include "nidevo/loader/sequence_flags.hpp"

NIDEVO_FLAG_HEADING("load");
ABSL_FLAG(std::string, sessions, "1", "load: concurrent sessions; a list (1,2,4,8) sweeps");
ABSL_FLAG(double, session_rate, 30, "load: frames per second per session (0: as fast as possible)");
ABSL_FLAG(double, warmup_s, 2, "load: seconds before the measurement window");
ABSL_FLAG(double, duration_s, 10, "load: measurement window per step, seconds");
ABSL_FLAG(int, load_frames, 60, "load: frames of the sequence kept in memory and looped");
ABSL_FLAG(std::string, metrics_url, "",
          "load: the server's /metrics URL, scraped before and after each step");
ABSL_FLAG(std::string, csv, "", "load: also write the results as CSV here");
ABSL_FLAG(std::string, json, "", "load: also write the results as JSON here");
ABSL_FLAG(bool, shared_channel, false,
          "load: every session on one channel (one HTTP/2 connection) instead of one channel each");
ABSL_FLAG(std::string, session_phase, "random",
          "load: when in the frame period each session sends: random (a phase of its own, as "
          "independent cameras; the same in every run) or aligned (all at once, the worst case)");
ABSL_FLAG(std::string, cpus, "",
          "load: pin the load tester to these CPUs (e.g. 0 or 0,2-3), to keep it off the server's");

namespace nidevo::client {

namespace {

std::vector<int> parseSessionList(const std::string& text) {
  std::vector<int> counts;
  for (absl::string_view part : absl::StrSplit(text, ',')) {
    int n = 0;
    if (!absl::SimpleAtoi(part, &n) || n < 1)
      throw std::invalid_argument("--sessions: '" + std::string(part) +
                                  "' is not a positive count (example: 1,2,4)");
    counts.push_back(n);
  }
  return counts;
}

void writeFile(const std::string& path, const std::string& text) {
  std::ofstream out(path);
  out << text;
  if (!out) throw std::runtime_error("cannot write " + path);
}

}  // namespace

int loadCommand() {
  const std::vector<int> steps = parseSessionList(absl::GetFlag(FLAGS_sessions));
  if (const std::string cpus = absl::GetFlag(FLAGS_cpus); !cpus.empty()) {
    pinProcessToCpus(parseCpuList(cpus));  // before any thread starts: all of them inherit it
    std::printf("load: pinned to CPUs %s\n", formatCpuList(allowedCpus()).c_str());
  }
  const FrameEncoding encoding = frameEncodingFromFlags();
  cli::SequenceSource source = cli::sequenceSourceFromFlags();
  const int keep = absl::GetFlag(FLAGS_load_frames);
  if (keep < 1) throw std::invalid_argument("--load_frames: must be at least 1");
  if (source.dataset.empty()) source.frames = std::min(source.frames, keep);
  source.max_frames = size_t(keep);
  const auto sequence = cli::loadSequence(source);
  std::vector<v1::Frame> frames(sequence.frames.size());
  for (size_t i = 0; i < frames.size(); ++i)
    encodeFrame(sequence.frames[i], sequence.camera.depth_scale, encoding, &frames[i]);

  LoadTestConfig config;
  config.channel = channelOptionsFromFlags();
  config.session = sessionOptionsFromFlags(sequence.camera);
  config.rate_hz = absl::GetFlag(FLAGS_session_rate);
  config.warmup_s = absl::GetFlag(FLAGS_warmup_s);
  config.duration_s = absl::GetFlag(FLAGS_duration_s);
  config.metrics_url = absl::GetFlag(FLAGS_metrics_url);
  config.shared_channel = absl::GetFlag(FLAGS_shared_channel);
  const std::string phase = absl::GetFlag(FLAGS_session_phase);
  if (phase != "random" && phase != "aligned")
    throw std::invalid_argument("--session_phase: 'random' or 'aligned', got '" + phase + "'");
  config.phase =
      phase == "aligned" ? LoadTestConfig::Phase::kAligned : LoadTestConfig::Phase::kRandom;
  std::printf(
      "load: %zu frames of %s (%dx%d, %s) looped, %s per session (%s phases), %s, %.0f s "
      "warm-up + %.0f s window per step\n",
      frames.size(), sequence.name.c_str(), sequence.camera.width, sequence.camera.height,
      encodingName().c_str(),
      config.rate_hz > 0 ? (std::to_string(int(config.rate_hz)) + " Hz").c_str()
                         : "as fast as possible",
      phase.c_str(), config.shared_channel ? "one shared channel" : "a channel per session",
      config.warmup_s, config.duration_s);
  std::fflush(stdout);

  std::vector<LoadTestResult> results;
  bool all_closed = true;
  for (int n : steps) {
    config.session.client_name = "nidevo-client load";
    config.sessions = n;
    results.push_back(runLoadTest(config, frames));
    all_closed = all_closed && results.back().accounting_closed;
    std::fprintf(stderr, "step %d sessions: %.1f poses/s, p99 %.2f ms\n", n,
                 results.back().poses_per_s, 1e3 * results.back().latency.p99);
  }
  std::printf("%s", formatTable(results).c_str());
  if (!absl::GetFlag(FLAGS_csv).empty()) writeFile(absl::GetFlag(FLAGS_csv), formatCsv(results));
  if (!absl::GetFlag(FLAGS_json).empty()) writeFile(absl::GetFlag(FLAGS_json), formatJson(results));
  return all_closed ? 0 : 1;
}

}  // namespace nidevo::client
