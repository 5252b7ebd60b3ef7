// replay: streams a sequence to the server and evaluates what comes back.
#include <unistd.h>

#include <algorithm>
#include <atomic>
#include <chrono>
#include <cstdio>
#include <iostream>
#include <mutex>
#include <thread>

#include "absl/flags/flag.h"
#include "client_flags.hpp"
#include "commands.hpp"
#include "frame_encoder.hpp"
#include "nidevo/cli/cli.hpp"
#include "nidevo/eval/evaluation_report.hpp"
#include "nidevo/loader/frame_loader.hpp"
#include "nidevo/loader/sequence_flags.hpp"
#include "reconnecting_session.hpp"

NIDEVO_FLAG_HEADING("replay");
ABSL_FLAG(double, rate, 0,
          "Frames per second to send (0: as fast as the server takes them; see --pace)");
ABSL_FLAG(bool, pace, false, "Send at the sequence's recorded timestamps (real time)");
ABSL_FLAG(std::string, out, "",
          "replay: write the estimated trajectory (TUM format) here, each pose as it arrives");
ABSL_FLAG(std::string, plot, "", "replay: write a PNG plot against ground truth here");
ABSL_FLAG(int, reconnect_attempts, nidevo::client::ReconnectOptions{}.max_attempts,
          "replay: when the stream ends UNAVAILABLE, reconnect this many times in a row (0: "
          "never), continuing from the last trusted pose and resending unanswered frames");
ABSL_FLAG(double, reconnect_backoff_s, nidevo::client::ReconnectOptions{}.initial_backoff_s,
          "replay: wait before the first reconnect, doubled after each failed one (up to 4 s)");

namespace nidevo::client {

namespace {

using Clock = std::chrono::steady_clock;

// "FRAME_STATUS_DEGRADED" -> "DEGRADED"
std::string shortName(v1::FrameStatus s) { return v1::FrameStatus_Name(s).substr(13); }

bool hasPose(const v1::TrackResponse& r) {
  return r.status() >= v1::FRAME_STATUS_OK && r.status() <= v1::FRAME_STATUS_LOST;
}

// What the replay has done so far; printed on every way out.
struct ReplayTally {
  std::mutex mutex;
  std::vector<v1::TrackResponse> responses;
  std::atomic<size_t> sent{0};
  size_t written = 0;
  std::string out_path;
  std::FILE* out = nullptr;  // poses appended and flushed as they arrive

  void record(const v1::TrackResponse& r) {
    std::lock_guard<std::mutex> lock(mutex);
    responses.push_back(r);
    if (out && hasPose(r)) {
      const std::string line =
          formatTumLine(StampedPose::fromPose(r.timestamp(), toIsometry(r.pose())));
      std::fprintf(out, "%s\n", line.c_str());
      std::fflush(out);
      ++written;
    }
  }
  void printCounts(const char* how) {
    std::lock_guard<std::mutex> lock(mutex);
    std::printf("replay %s: %zu frames sent, %zu answered, %zu poses written%s%s\n", how,
                sent.load(), responses.size(), written, out ? " to " : "", out_path.c_str());
    std::fflush(stdout);
  }
  ~ReplayTally() {
    if (out) std::fclose(out);
  }
};

void openTrajectory(const std::string& path, ReplayTally* tally) {
  if (path.empty()) return;
  tally->out = std::fopen(path.c_str(), "w");
  if (!tally->out) throw std::runtime_error("--out: cannot write " + path);
  tally->out_path = path;
  std::fprintf(tally->out, "# timestamp tx ty tz qx qy qz qw\n");
  std::fflush(tally->out);
}

ReconnectOptions reconnectOptionsFromFlags() {
  ReconnectOptions r;
  r.max_attempts = absl::GetFlag(FLAGS_reconnect_attempts);
  r.initial_backoff_s = absl::GetFlag(FLAGS_reconnect_backoff_s);
  if (r.max_attempts < 0) throw std::invalid_argument("--reconnect_attempts: must not be negative");
  if (!(r.initial_backoff_s >= 0))
    throw std::invalid_argument("--reconnect_backoff_s: must not be negative");
  return r;
}

int replayWith(const cli::LoadedSequence& sequence, ReplayTally* tally) {
  const FrameEncoding encoding = frameEncodingFromFlags();
  const double rate = absl::GetFlag(FLAGS_rate);
  const bool pace = absl::GetFlag(FLAGS_pace);
  SessionOptions options = sessionOptionsFromFlags(sequence.camera);
  options.client_name = "nidevo-client replay " + sequence.name;
  Client client(channelOptionsFromFlags());
  ReconnectingSession session(&client, options, reconnectOptionsFromFlags(),
                              [tally](const v1::TrackResponse& r) { tally->record(r); });

  const size_t total = sequence.frames.size();
  const Clock::time_point start = Clock::now();
  std::atomic<bool> done{false};
  std::thread progress;
  if (isatty(STDERR_FILENO)) {  // quiet when logged or piped
    progress = std::thread([&] {
      while (!done) {
        std::this_thread::sleep_for(std::chrono::milliseconds(200));
        std::lock_guard<std::mutex> lock(tally->mutex);
        const double secs = std::chrono::duration<double>(Clock::now() - start).count();
        const auto& responses = tally->responses;
        const v1::TrackResponse* last = responses.empty() ? nullptr : &responses.back();
        std::fprintf(stderr, "\r%zu/%zu sent, %zu answered, %.1f frames/s, PSR %.1f, %-8s",
                     tally->sent.load(), total, responses.size(), double(responses.size()) / secs,
                     last ? last->psr() : 0.0, last ? shortName(last->status()).c_str() : "");
      }
      std::fprintf(stderr, "\n");
    });
  }
  v1::Frame frame;
  const double t_first = sequence.frames.front().timestamp;
  for (size_t i = 0; i < total; ++i) {
    if (pace)
      std::this_thread::sleep_until(start + std::chrono::microseconds(int64_t(
                                                1e6 * (sequence.frames[i].timestamp - t_first))));
    else if (rate > 0)
      std::this_thread::sleep_until(start +
                                    std::chrono::microseconds(int64_t(1e6 * double(i) / rate)));
    encodeFrame(sequence.frames[i], sequence.camera.depth_scale, encoding, &frame);
    frame.set_sequence(i);
    if (!session.send(frame)) break;
    ++tally->sent;
  }
  const grpc::Status status = session.finish();
  const double secs = std::chrono::duration<double>(Clock::now() - start).count();
  done = true;
  if (progress.joinable()) progress.join();

  std::lock_guard<std::mutex> lock(tally->mutex);
  auto& responses = tally->responses;
  int counts[6] = {0, 0, 0, 0, 0, 0};
  Trajectory estimate;
  std::vector<double> server_ms;
  std::sort(responses.begin(), responses.end(),
            [](const auto& a, const auto& b) { return a.sequence() < b.sequence(); });
  for (const auto& r : responses) {
    ++counts[std::clamp(int(r.status()), 0, 5)];
    if (r.status() == v1::FRAME_STATUS_ERROR)
      std::fprintf(stderr, "frame %llu: %s\n", (unsigned long long)r.sequence(),
                   r.reason().c_str());
    if (!hasPose(r)) continue;
    estimate.push_back(StampedPose::fromPose(r.timestamp(), toIsometry(r.pose())));
    server_ms.push_back(1e3 * r.timings().total());
  }
  std::sort(server_ms.begin(), server_ms.end());
  std::printf("sequence: %s, %zu frames %dx%d, encoding %s\n", sequence.name.c_str(), total,
              sequence.camera.width, sequence.camera.height, encodingName().c_str());
  std::printf("replay: %zu frames sent, %zu answered in %.2f s = %.1f frames/s\n",
              tally->sent.load(), responses.size(), secs, double(responses.size()) / secs);
  if (session.reconnects() > 0)
    std::printf("reconnects: %d, %llu frames resent\n", session.reconnects(),
                (unsigned long long)session.resentFrames());
  std::printf("answers: %d OK, %d DEGRADED, %d LOST, %d DROPPED, %d ERROR\n", counts[1], counts[2],
              counts[3], counts[4], counts[5]);
  if (!server_ms.empty())
    std::printf("server time per frame (arrival to answer): median %.2f ms, max %.2f ms\n",
                server_ms[server_ms.size() / 2], server_ms.back());
  if (!status.ok()) {
    std::printf("stream ended with %s: %s\n", statusCodeName(status.error_code()).c_str(),
                status.error_message().c_str());
    return 1;
  }
  if (!tally->out_path.empty()) std::printf("trajectory written to %s\n", tally->out_path.c_str());
  if (!sequence.ground_truth.empty() && estimate.size() >= 3) {
    std::printf("\n");
    cli::printEvaluation(estimate, sequence.ground_truth, 0.005, 1, absl::GetFlag(FLAGS_plot),
                         sequence.name + " via server: ");
  }
  return 0;
}

}  // namespace

int replayCommand() {
  const double rate = absl::GetFlag(FLAGS_rate);
  if (rate < 0) throw std::invalid_argument("--rate: must not be negative");
  if (absl::GetFlag(FLAGS_pace) && rate > 0)
    throw std::invalid_argument("--pace and --rate exclude each other");
  const auto sequence = cli::loadSequence(cli::sequenceSourceFromFlags());
  if (sequence.frames.empty()) throw std::runtime_error("the sequence has no frames");
  ReplayTally tally;
  openTrajectory(absl::GetFlag(FLAGS_out), &tally);
  int code = 1;
  try {
    code = replayWith(sequence, &tally);
  } catch (...) {
    tally.printCounts("stopped");
    throw;
  }
  tally.printCounts(code == 0 ? "done" : "failed");
  return code;
}

}  // namespace nidevo::client
