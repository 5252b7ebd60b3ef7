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

NIDEVO_FLAG_HEADING("replay");
ABSL_FLAG(double, rate, 0,
          "Frames per second to send (0: as fast as the server takes them; see --pace)");
ABSL_FLAG(bool, pace, false, "Send at the sequence's recorded timestamps (real time)");
ABSL_FLAG(std::string, out, "", "replay: write the estimated trajectory (TUM format) here");
ABSL_FLAG(std::string, plot, "", "replay: write a PNG plot against ground truth here");

namespace nidevo::client {

namespace {

using Clock = std::chrono::steady_clock;

// "FRAME_STATUS_DEGRADED" -> "DEGRADED"
std::string shortName(v1::FrameStatus s) { return v1::FrameStatus_Name(s).substr(13); }

}  // namespace

int replayCommand() {
  const FrameEncoding encoding = frameEncodingFromFlags();
  const double rate = absl::GetFlag(FLAGS_rate);
  const bool pace = absl::GetFlag(FLAGS_pace);
  if (rate < 0) throw std::invalid_argument("--rate: must not be negative");
  if (pace && rate > 0) throw std::invalid_argument("--pace and --rate exclude each other");
  const auto sequence = cli::loadSequence(cli::sequenceSourceFromFlags());
  if (sequence.frames.empty()) throw std::runtime_error("the sequence has no frames");

  SessionOptions options = sessionOptionsFromFlags(sequence.camera);
  options.client_name = "nidevo-client replay " + sequence.name;

  std::mutex mutex;
  std::vector<v1::TrackResponse> responses;
  responses.reserve(sequence.frames.size());
  std::atomic<size_t> sent{0};
  Client client(channelOptionsFromFlags());
  auto session = client.open(options, [&](const v1::TrackResponse& r) {
    std::lock_guard<std::mutex> lock(mutex);
    responses.push_back(r);
  });

  const size_t total = sequence.frames.size();
  const Clock::time_point start = Clock::now();
  std::atomic<bool> done{false};
  std::thread progress;
  if (isatty(STDERR_FILENO)) {  // quiet when logged or piped
    progress = std::thread([&] {
      while (!done) {
        std::this_thread::sleep_for(std::chrono::milliseconds(200));
        std::lock_guard<std::mutex> lock(mutex);
        const double secs = std::chrono::duration<double>(Clock::now() - start).count();
        const v1::TrackResponse* last = responses.empty() ? nullptr : &responses.back();
        std::fprintf(stderr, "\r%zu/%zu sent, %zu answered, %.1f frames/s, PSR %.1f, %-8s",
                     sent.load(), total, responses.size(), double(responses.size()) / secs,
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
    if (!session->send(frame)) break;
    ++sent;
  }
  const grpc::Status status = session->finish();
  const double secs = std::chrono::duration<double>(Clock::now() - start).count();
  done = true;
  if (progress.joinable()) progress.join();

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
    if (r.status() < v1::FRAME_STATUS_OK || r.status() > v1::FRAME_STATUS_LOST) continue;
    estimate.push_back(StampedPose::fromPose(r.timestamp(), toIsometry(r.pose())));
    server_ms.push_back(1e3 * r.timings().total());
  }
  std::sort(server_ms.begin(), server_ms.end());
  std::printf("sequence: %s, %zu frames %dx%d, encoding %s\n", sequence.name.c_str(), total,
              sequence.camera.width, sequence.camera.height, encodingName().c_str());
  std::printf("replay: %zu frames sent, %zu answered in %.2f s = %.1f frames/s\n", sent.load(),
              responses.size(), secs, double(responses.size()) / secs);
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
  const std::string out = absl::GetFlag(FLAGS_out);
  if (!out.empty()) {
    writeTumTrajectory(out, estimate);
    std::printf("trajectory written to %s\n", out.c_str());
  }
  if (!sequence.ground_truth.empty() && estimate.size() >= 3) {
    std::printf("\n");
    cli::printEvaluation(estimate, sequence.ground_truth, 0.005, 1, absl::GetFlag(FLAGS_plot),
                         sequence.name + " via server: ");
  }
  return 0;
}

}  // namespace nidevo::client
