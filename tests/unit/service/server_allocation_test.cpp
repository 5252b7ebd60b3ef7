// The server's path for raw frames allocates nothing per frame in steady state: the frame
// pipeline, the raw decoder and the odometry stages, with the answers, over 100 frames after
// warm-up. gRPC is left out (its own buffers are its own); the incoming message is a reused
// v1::Frame, as the session's reused request is. Its own binary: it replaces operator new.
#include <gtest/gtest.h>

#include <deque>
#include <functional>
#include <mutex>

#include "../counting_new.hpp"
#include "frame_decoder.hpp"
#include "frame_encoder.hpp"
#include "frame_pipeline.hpp"
#include "nidevo/io/camera_io.hpp"
#include "nidevo/sim/sequence.hpp"
#include "odometry_stages.hpp"
#include "response_queue.hpp"
#include "server_metrics.hpp"

using nidevo::test::allocations;
using nidevo::test::counting;

namespace nidevo::server {
namespace {

TEST(ServerAllocation, RawFramesThroughThePipelineAllocateNothingPerFrame) {
  synth::SequenceConfig c;
  c.frames = 30;
  c.camera = cameraPreset("icl")->subsampled(2);
  const synth::SyntheticSequence seq(c);
  v1::SessionConfig config;
  auto* camera = config.mutable_camera();
  camera->set_width(uint32_t(c.camera.width));
  camera->set_height(uint32_t(c.camera.height));
  camera->set_fx(c.camera.fx);
  camera->set_fy(c.camera.fy);
  camera->set_cx(c.camera.cx);
  camera->set_cy(c.camera.cy);
  config.set_color_encoding(v1::COLOR_ENCODING_GRAY8);
  config.set_depth_encoding(v1::DEPTH_ENCODING_UINT16);
  config.set_depth_scale(5000);
  ASSERT_EQ(FrameDecoder::validate(config), "");
  const auto raw = client::parseFrameEncoding("raw");
  std::vector<v1::Frame> encoded(size_t(seq.size()));
  for (int i = 0; i < seq.size(); ++i)
    client::encodeFrame(seq.renderFrame(i), 5000, raw, &encoded[size_t(i)]);

  ServerMetrics metrics("test");
  auto decoder = std::make_shared<const FrameDecoder>(config);
  OdometryStages stages(decoder, std::make_unique<Odometry>(decoder->camera(), OdometryConfig{}),
                        &metrics);
  std::mutex mutex;
  std::vector<std::function<void()>> tasks, running;
  tasks.reserve(16);
  running.reserve(16);
  long answers = 0;
  ResponseQueue out;  // the session's queue of answers to write
  FramePipelineHooks hooks;
  hooks.run_task = [&](std::function<void()> task) { tasks.push_back(std::move(task)); };
  hooks.answer = [&](v1::TrackResponse* r) {
    answers += r->status() == v1::FRAME_STATUS_OK;
    out.push(r);
    out.popFront();  // written
  };
  hooks.queue_changed = [](int) {};
  hooks.queue_drained = [] {};
  std::unique_ptr<FramePipeline> pipeline;
  hooks.task_done = [&](std::unique_lock<std::mutex> lock) {
    pipeline->schedule();
    lock.unlock();
  };
  pipeline = std::make_unique<FramePipeline>(&mutex, &stages, FramePipeline::Policy::kBlock, 4, 3,
                                             std::move(hooks));
  v1::Frame incoming;
  auto frame = [&](int k) -> const v1::Frame& {  // back and forth through the sequence
    const int period = 2 * (seq.size() - 1);
    const int i = k % period;
    return encoded[size_t(i < seq.size() ? i : period - i)];
  };
  auto step = [&](int k) {
    {
      std::lock_guard<std::mutex> lock(mutex);
      incoming.CopyFrom(frame(k));  // what parsing into the reused request does
      incoming.set_sequence(uint64_t(k));
      incoming.set_timestamp(k / 30.0);
      pipeline->admit(&incoming, Clock::now());
      pipeline->schedule();
    }
    while (true) {
      {
        std::lock_guard<std::mutex> lock(mutex);
        if (tasks.empty()) break;
        running.swap(tasks);
      }
      for (auto& t : running) t();
      running.clear();
    }
  };
  int k = 0;
  for (; k < 60; ++k) step(k);
  allocations = 0;
  counting = true;
  for (int end = k + 100; k < end; ++k) step(k);
  counting = false;
  EXPECT_EQ(allocations.load(), 0) << "per frame: " << double(allocations.load()) / 100;
  EXPECT_GT(answers, 150);
}

}  // namespace
}  // namespace nidevo::server
