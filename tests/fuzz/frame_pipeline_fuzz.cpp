// A session's stream of frames driven through the real frame pipeline and odometry stages, with
// an executor that runs the submitted tasks in an order the input chooses. Frames are well-formed
// (a textured tilted plane), malformed (wrong sizes, arbitrary bytes) or out of order in time; the
// pipeline may be stopped at any point. Checked: every admitted frame is answered exactly once
// (unless the pipeline was stopped), never a frame that was not admitted, and every answer has a
// valid status with a finite pose when it has one.
#include <fuzzer/FuzzedDataProvider.h>

#include <cmath>
#include <cstddef>
#include <cstdint>
#include <cstring>
#include <deque>
#include <functional>
#include <map>
#include <memory>
#include <mutex>
#include <string>

#include "frame_decoder.hpp"
#include "frame_pipeline.hpp"
#include "fuzz_check.hpp"
#include "odometry_stages.hpp"
#include "server_metrics.hpp"

namespace nidevo::server {
namespace {

constexpr int kSide = 64;  // the smallest image the default odometry config accepts
// A well-formed frame costs milliseconds under the sanitizers; more frames per input add little.
constexpr uint64_t kMaxFrames = 10;

v1::SessionConfig sessionConfig(FuzzedDataProvider* fdp) {
  v1::SessionConfig config;
  auto* camera = config.mutable_camera();
  camera->set_width(kSide);
  camera->set_height(kSide);
  camera->set_fx(60);
  camera->set_fy(60);
  camera->set_cx(31.5);
  camera->set_cy(31.5);
  config.set_color_encoding(fdp->PickValueInArray(
      {v1::COLOR_ENCODING_GRAY8, v1::COLOR_ENCODING_RGB8, v1::COLOR_ENCODING_BGR8}));
  config.set_depth_encoding(
      fdp->PickValueInArray({v1::DEPTH_ENCODING_FLOAT32, v1::DEPTH_ENCODING_UINT16}));
  config.set_depth_scale(5000);
  return config;
}

// A textured plane 1-2 m away, moved a little per frame, in the session's encodings.
void wellFormedFrame(const v1::SessionConfig& config, double t, v1::Frame* frame) {
  const size_t pixels = size_t(kSide) * kSide;
  const int channels = config.color_encoding() == v1::COLOR_ENCODING_GRAY8 ? 1 : 3;
  std::string color(pixels * size_t(channels), '\0');
  std::string depth;
  std::vector<float> metres(pixels);
  for (int v = 0; v < kSide; ++v) {
    for (int u = 0; u < kSide; ++u) {
      const size_t i = size_t(v) * kSide + size_t(u);
      const double x = u + 20 * t, y = v;
      const auto grey = uint8_t(128 + 100 * std::sin(0.4 * x) * std::cos(0.3 * y));
      for (int c = 0; c < channels; ++c) color[i * size_t(channels) + size_t(c)] = char(grey);
      metres[i] = float(1.5 + 0.004 * (u - 32) + 0.002 * (v - 32) + 0.05 * t);
    }
  }
  if (config.depth_encoding() == v1::DEPTH_ENCODING_FLOAT32) {
    depth.resize(4 * pixels);
    std::memcpy(depth.data(), metres.data(), depth.size());
  } else {
    depth.resize(2 * pixels);
    for (size_t i = 0; i < pixels; ++i) {
      const auto raw = uint16_t(std::lround(metres[i] * config.depth_scale()));
      depth[2 * i] = char(raw & 0xff);
      depth[2 * i + 1] = char(raw >> 8);
    }
  }
  frame->set_color(std::move(color));
  frame->set_depth(std::move(depth));
}

struct Owner {
  std::mutex mutex;
  std::deque<std::function<void()>> tasks;
  std::map<uint64_t, int> answers;  // sequence -> times answered
  std::unique_ptr<FramePipeline> pipeline;
};

void checkAnswer(const v1::TrackResponse& r) {
  NIDEVO_FUZZ_CHECK(v1::FrameStatus_IsValid(r.status()) &&
                    r.status() != v1::FRAME_STATUS_UNSPECIFIED);
  if (r.has_pose()) {
    const auto& p = r.pose();
    for (double x : {p.tx(), p.ty(), p.tz(), p.qx(), p.qy(), p.qz(), p.qw()})
      NIDEVO_FUZZ_CHECK(std::isfinite(x));
  }
}

void runTask(Owner* owner, size_t index) {
  std::function<void()> task;
  {
    std::lock_guard<std::mutex> lock(owner->mutex);
    if (owner->tasks.empty()) return;
    index %= owner->tasks.size();
    task = std::move(owner->tasks[index]);
    owner->tasks.erase(owner->tasks.begin() + long(index));
  }
  task();
}

}  // namespace
}  // namespace nidevo::server

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
  using namespace nidevo::server;
  namespace v1 = nidevo::v1;
  static ServerMetrics metrics("fuzz");
  FuzzedDataProvider fdp(data, size);
  const v1::SessionConfig config = sessionConfig(&fdp);
  const auto policy =
      fdp.ConsumeBool() ? FramePipeline::Policy::kLatest : FramePipeline::Policy::kBlock;
  const size_t capacity = fdp.ConsumeIntegralInRange<size_t>(1, 6);
  const size_t slots = fdp.ConsumeIntegralInRange<size_t>(1, 3);

  NIDEVO_FUZZ_CHECK(FrameDecoder::validate(config).empty());
  auto decoder = std::make_shared<const FrameDecoder>(config);
  OdometryStages stages(
      decoder, std::make_unique<nidevo::Odometry>(decoder->camera(), nidevo::OdometryConfig{}),
      &metrics);
  Owner owner;
  FramePipelineHooks hooks;
  hooks.run_task = [&owner](std::function<void()> task) { owner.tasks.push_back(std::move(task)); };
  hooks.answer = [&owner](v1::TrackResponse* r) {
    checkAnswer(*r);
    ++owner.answers[r->sequence()];
  };
  hooks.queue_changed = [](int) {};
  hooks.queue_drained = [] {};
  hooks.task_done = [&owner](std::unique_lock<std::mutex> lock) {
    owner.pipeline->schedule();
    lock.unlock();
  };
  owner.pipeline = std::make_unique<FramePipeline>(&owner.mutex, &stages, policy, capacity, slots,
                                                   std::move(hooks));

  uint64_t admitted = 0;
  bool stopped = false;
  double t = 0;
  while (fdp.remaining_bytes() > 0) {
    switch (fdp.ConsumeIntegralInRange(0, 5)) {
      case 0:
      case 1: {  // a frame, if the session reads (BLOCK stops reading while the queue is full)
        std::lock_guard<std::mutex> lock(owner.mutex);
        if (stopped || admitted >= kMaxFrames || !owner.pipeline->acceptsMore()) break;
        v1::Frame frame;
        frame.set_sequence(admitted);
        t = fdp.ConsumeBool() ? t + 0.033 : fdp.ConsumeFloatingPoint<double>();
        frame.set_timestamp(t);
        wellFormedFrame(config, std::isfinite(t) ? std::fmod(t, 1.0) : 0.0, &frame);
        if (fdp.ConsumeIntegralInRange(0, 7) == 0)
          frame.set_color(fdp.ConsumeRandomLengthString(64));
        if (fdp.ConsumeIntegralInRange(0, 7) == 0)
          frame.set_depth(fdp.ConsumeRandomLengthString(64));
        owner.pipeline->admit(&frame, Clock::now());
        owner.pipeline->schedule();
        ++admitted;
        break;
      }
      case 2:
      case 3:
        runTask(&owner, fdp.ConsumeIntegral<size_t>());
        break;
      case 4:
        while (!owner.tasks.empty()) runTask(&owner, 0);
        break;
      case 5: {
        std::lock_guard<std::mutex> lock(owner.mutex);
        if (fdp.ConsumeIntegralInRange(0, 3) == 0 && !stopped) {
          owner.pipeline->stop();
          stopped = true;
        }
        break;
      }
    }
  }
  while (!owner.tasks.empty()) runTask(&owner, 0);

  std::lock_guard<std::mutex> lock(owner.mutex);
  NIDEVO_FUZZ_CHECK(owner.pipeline->idle() || stopped);
  for (const auto& [sequence, times] : owner.answers) {
    NIDEVO_FUZZ_CHECK(sequence < admitted);
    NIDEVO_FUZZ_CHECK(times == 1);
  }
  if (!stopped) NIDEVO_FUZZ_CHECK(owner.answers.size() == admitted);
  return 0;
}
