#include "frame_pipeline.hpp"

#include <gtest/gtest.h>

#include <algorithm>
#include <atomic>
#include <condition_variable>
#include <limits>
#include <map>
#include <optional>
#include <thread>

#include "worker_pool.hpp"

namespace nidevo::server {
namespace {

using namespace std::chrono_literals;

// Holds the tasks the pipeline submits until the test runs them, in any order it likes.
class ManualExecutor {
 public:
  void submit(std::function<void()> task) {
    std::lock_guard<std::mutex> lock(mutex_);
    tasks_.push_back(std::move(task));
  }
  size_t pending() {
    std::lock_guard<std::mutex> lock(mutex_);
    return tasks_.size();
  }
  void runAt(size_t i) {
    std::function<void()> task;
    {
      std::lock_guard<std::mutex> lock(mutex_);
      task = std::move(tasks_.at(i));
      tasks_.erase(tasks_.begin() + long(i));
    }
    task();
  }
  void runAll() {
    while (pending() > 0) runAt(0);
  }

 private:
  std::mutex mutex_;
  std::deque<std::function<void()>> tasks_;
};

// Records which stage ran for which frame; a frame whose colour is "bad" fails stage 1.
class RecordingStages final : public FrameStages {
 public:
  void prepare(FrameJob* job) override {
    const int inside = ++preparing_;
    int seen = max_preparing_.load();
    while (inside > seen && !max_preparing_.compare_exchange_weak(seen, inside)) {
    }
    if (prepare_gate) prepare_gate();
    record("prepare", *job);
    if (job->frame.color() == "bad") job->error = "frame.color: bad";
    --preparing_;
  }
  void rotate(FrameJob* job) override {
    EXPECT_EQ(++rotating_, 1) << "two stage-2 calls at once";
    record("rotate", *job);
    --rotating_;
  }
  void translate(FrameJob* job) override {
    EXPECT_EQ(++translating_, 1) << "two stage-3 calls at once";
    record("translate", *job);
    --translating_;
    job->response.set_sequence(job->frame.sequence());
    job->response.set_status(v1::FRAME_STATUS_OK);
  }
  std::vector<uint64_t> sequencesOf(const std::string& stage) {
    std::lock_guard<std::mutex> lock(mutex_);
    std::vector<uint64_t> out;
    for (const auto& [name, sequence] : events_)
      if (name == stage) out.push_back(sequence);
    return out;
  }
  int maxPreparing() const { return max_preparing_.load(); }

  std::function<void()> prepare_gate;  // runs inside prepare(), e.g. to hold it

 private:
  void record(const char* stage, const FrameJob& job) {
    std::lock_guard<std::mutex> lock(mutex_);
    events_.emplace_back(stage, job.frame.sequence());
  }
  std::mutex mutex_;
  std::vector<std::pair<std::string, uint64_t>> events_;
  std::atomic<int> preparing_{0}, max_preparing_{0}, rotating_{0}, translating_{0};
};

// A pipeline with its owner's side: the mutex, the answers, the count of ended tasks.
struct Harness {
  Harness(FramePipeline::Policy policy, size_t capacity, size_t slots,
          std::function<void(std::function<void()>)> run_task) {
    FramePipelineHooks hooks;
    hooks.run_task = std::move(run_task);
    hooks.answer = [this](v1::TrackResponse* r) {
      answers.push_back(*r);
      changed.notify_all();
    };
    hooks.queue_changed = [this](int delta) { queued += delta; };
    hooks.queue_drained = [] {};
    hooks.task_done = [this](std::unique_lock<std::mutex> lock) {
      ++tasks_done;
      pipeline->schedule();
      changed.notify_all();
      lock.unlock();
    };
    pipeline =
        std::make_unique<FramePipeline>(&mutex, &stages, policy, capacity, slots, std::move(hooks));
  }

  // Admits frame `sequence` (timestamp = sequence) and schedules; colour "bad" fails stage 1.
  void admit(uint64_t sequence, const std::string& color = "ok",
             std::optional<double> timestamp = std::nullopt) {
    v1::Frame frame;
    frame.set_sequence(sequence);
    frame.set_timestamp(timestamp.value_or(double(sequence)));
    frame.set_color(color);
    std::lock_guard<std::mutex> lock(mutex);
    pipeline->admit(&frame, Clock::now());
    pipeline->schedule();
  }
  bool acceptsMore() {
    std::lock_guard<std::mutex> lock(mutex);
    return pipeline->acceptsMore();
  }
  // Waits until `n` answers arrived and the pipeline is idle; false on a 20 s timeout.
  bool waitForAnswers(size_t n) {
    std::unique_lock<std::mutex> lock(mutex);
    return changed.wait_for(lock, 20s, [&] { return answers.size() >= n && pipeline->idle(); });
  }
  std::vector<std::pair<uint64_t, v1::FrameStatus>> answered() {
    std::lock_guard<std::mutex> lock(mutex);
    std::vector<std::pair<uint64_t, v1::FrameStatus>> out;
    for (const auto& a : answers) out.emplace_back(a.sequence(), a.status());
    return out;
  }

  std::mutex mutex;
  std::condition_variable changed;
  RecordingStages stages;
  std::vector<v1::TrackResponse> answers;
  int queued = 0;
  int tasks_done = 0;
  std::unique_ptr<FramePipeline> pipeline;
};

using Answers = std::vector<std::pair<uint64_t, v1::FrameStatus>>;
constexpr auto kOk = v1::FRAME_STATUS_OK;
constexpr auto kDropped = v1::FRAME_STATUS_DROPPED;
constexpr auto kError = v1::FRAME_STATUS_ERROR;

TEST(FramePipeline, StagesTwoAndThreeTakeFramesInAdmissionOrderWhenStageOneEndsOutOfOrder) {
  ManualExecutor executor;
  Harness h(FramePipeline::Policy::kBlock, 8, 3, [&](auto t) { executor.submit(std::move(t)); });
  for (uint64_t i = 0; i < 3; ++i) h.admit(i);
  ASSERT_EQ(executor.pending(), 3u);  // stage 1 of all three frames at once
  executor.runAt(2);                  // stage 1 of frame 2 ends first, then frame 1, then 0
  executor.runAt(1);
  executor.runAt(0);
  executor.runAll();
  EXPECT_EQ(h.stages.sequencesOf("prepare"), (std::vector<uint64_t>{2, 1, 0}));
  EXPECT_EQ(h.stages.sequencesOf("rotate"), (std::vector<uint64_t>{0, 1, 2}));
  EXPECT_EQ(h.stages.sequencesOf("translate"), (std::vector<uint64_t>{0, 1, 2}));
  EXPECT_EQ(h.answered(), (Answers{{0, kOk}, {1, kOk}, {2, kOk}}));
}

TEST(FramePipeline, StageOneOfSeveralFramesRunsAtOnceOnThreads) {
  WorkerPool pool(3);
  Harness h(FramePipeline::Policy::kBlock, 8, 3, [&](auto t) { pool.submit(std::move(t)); });
  // Each stage 1 waits (up to 5 s) until three are inside at once.
  std::atomic<int> entered{0};
  h.stages.prepare_gate = [&] {
    ++entered;
    const auto until = Clock::now() + 5s;
    while (entered.load() < 3 && Clock::now() < until) std::this_thread::sleep_for(1ms);
  };
  for (uint64_t i = 0; i < 3; ++i) h.admit(i);
  ASSERT_TRUE(h.waitForAnswers(3));
  EXPECT_EQ(h.stages.maxPreparing(), 3);
  EXPECT_EQ(h.stages.sequencesOf("translate"), (std::vector<uint64_t>{0, 1, 2}));
}

TEST(FramePipeline, SlotsFollowTheWorkersUpToOnePerStage) {
  EXPECT_EQ(slotsForWorkers(1), 1u);  // one thread runs a session's stages one after another
  EXPECT_EQ(slotsForWorkers(2), 2u);
  EXPECT_EQ(slotsForWorkers(3), 3u);
  EXPECT_EQ(slotsForWorkers(16), 3u);  // a session has three stages to keep busy, no more
  EXPECT_EQ(slotsForWorkers(0), 1u);
}

TEST(FramePipeline, LatestDropsTheOldestQueuedFrame) {
  ManualExecutor executor;
  Harness h(FramePipeline::Policy::kLatest, 2, 1, [&](auto t) { executor.submit(std::move(t)); });
  h.admit(0);  // into the only slot
  h.admit(1);  // queued
  h.admit(2);  // queued: the queue is full
  EXPECT_TRUE(h.acceptsMore());
  h.admit(3);  // drops 1, the oldest queued
  EXPECT_EQ(h.answered(), (Answers{{1, kDropped}}));
  EXPECT_EQ(h.queued, 2);
  executor.runAll();
  EXPECT_EQ(h.answered(), (Answers{{1, kDropped}, {0, kOk}, {2, kOk}, {3, kOk}}));
  EXPECT_EQ(h.queued, 0);
}

TEST(FramePipeline, BlockNeverDropsEvenPastItsCapacity) {
  ManualExecutor executor;
  Harness h(FramePipeline::Policy::kBlock, 2, 1, [&](auto t) { executor.submit(std::move(t)); });
  h.admit(0);
  h.admit(1);
  EXPECT_TRUE(h.acceptsMore());
  h.admit(2);
  EXPECT_FALSE(h.acceptsMore());                 // the owner stops reading here...
  for (uint64_t i = 3; i < 10; ++i) h.admit(i);  // ...and if it does not, still nothing drops
  EXPECT_TRUE(h.answered().empty());
  executor.runAll();
  Answers expected;
  for (uint64_t i = 0; i < 10; ++i) expected.emplace_back(i, kOk);
  EXPECT_EQ(h.answered(), expected);
  EXPECT_TRUE(h.acceptsMore());
}

TEST(FramePipeline, ADecodeErrorIsAnsweredInItsTurnWithoutStallingLaterFrames) {
  ManualExecutor executor;
  Harness h(FramePipeline::Policy::kBlock, 8, 3, [&](auto t) { executor.submit(std::move(t)); });
  h.admit(0);
  h.admit(1, "bad");
  h.admit(2);
  h.admit(3, "bad");
  h.admit(4);
  executor.runAt(1);  // the bad frame's stage 1 ends first
  executor.runAll();
  EXPECT_EQ(h.answered(), (Answers{{0, kOk}, {1, kError}, {2, kOk}, {3, kError}, {4, kOk}}));
  EXPECT_EQ(h.answers[1].reason(), "frame.color: bad");
  EXPECT_EQ(h.stages.sequencesOf("rotate"), (std::vector<uint64_t>{0, 2, 4}));
  EXPECT_EQ(h.stages.sequencesOf("translate"), (std::vector<uint64_t>{0, 2, 4}));
  std::lock_guard<std::mutex> lock(h.mutex);
  EXPECT_TRUE(h.pipeline->idle());
}

TEST(FramePipeline, ATimestampThatDoesNotIncreaseIsAnsweredErrorAtOnce) {
  ManualExecutor executor;
  Harness h(FramePipeline::Policy::kBlock, 8, 3, [&](auto t) { executor.submit(std::move(t)); });
  h.admit(0, "ok", 5.0);
  h.admit(1, "ok", 5.0);
  h.admit(2, "ok", std::nan(""));
  h.admit(3, "ok", 6.0);
  ASSERT_EQ(h.answered(), (Answers{{1, kError}, {2, kError}}));
  EXPECT_NE(h.answers[0].reason().find("frame.timestamp: 5 does not increase"), std::string::npos)
      << h.answers[0].reason();
  executor.runAll();
  EXPECT_EQ(h.answered(), (Answers{{1, kError}, {2, kError}, {0, kOk}, {3, kOk}}));
}

TEST(FramePipeline, ANonFiniteFirstTimestampIsAnsweredError) {
  ManualExecutor executor;
  Harness h(FramePipeline::Policy::kBlock, 8, 3, [&](auto t) { executor.submit(std::move(t)); });
  h.admit(0, "ok", std::numeric_limits<double>::infinity());
  h.admit(1, "ok", 1.0);
  executor.runAll();
  EXPECT_EQ(h.answered(), (Answers{{0, kError}, {1, kOk}}));
}

TEST(FramePipeline, StopEmptiesTheQueueAndStartsNoFurtherStage) {
  ManualExecutor executor;
  Harness h(FramePipeline::Policy::kBlock, 8, 1, [&](auto t) { executor.submit(std::move(t)); });
  for (uint64_t i = 0; i < 4; ++i) h.admit(i);
  EXPECT_EQ(h.queued, 3);
  {
    std::lock_guard<std::mutex> lock(h.mutex);
    h.pipeline->stop();
  }
  EXPECT_EQ(h.queued, 0);
  executor.runAll();  // frame 0's stage 1 ends; nothing more starts
  EXPECT_EQ(h.stages.sequencesOf("prepare"), (std::vector<uint64_t>{0}));
  EXPECT_TRUE(h.stages.sequencesOf("rotate").empty());
  EXPECT_EQ(h.tasks_done, 1);
}

// Many frames, some bad, through worker threads under each policy: one answer for each.
void expectEveryFrameAnsweredOnce(FramePipeline::Policy policy) {
  WorkerPool pool(2);
  Harness h(policy, 2, 3, [&](auto t) { pool.submit(std::move(t)); });
  constexpr uint64_t kFrames = 300;
  for (uint64_t i = 0; i < kFrames; ++i) {
    while (!h.acceptsMore()) std::this_thread::yield();  // as the session's reader does
    h.admit(i, i % 7 == 3 ? "bad" : "ok");
  }
  ASSERT_TRUE(h.waitForAnswers(kFrames));
  std::map<uint64_t, int> count;
  int dropped = 0;
  for (const auto& [sequence, status] : h.answered()) {
    ++count[sequence];
    dropped += status == kDropped;
    if (status != kDropped) {
      EXPECT_EQ(status == kError, sequence % 7 == 3) << sequence;
    }
  }
  EXPECT_EQ(count.size(), kFrames);
  for (const auto& [sequence, n] : count) EXPECT_EQ(n, 1) << "frame " << sequence;
  if (policy == FramePipeline::Policy::kBlock) {
    EXPECT_EQ(dropped, 0);
  }
  // Stage 3 saw the frames it processed in admission order.
  const auto translated = h.stages.sequencesOf("translate");
  EXPECT_TRUE(std::is_sorted(translated.begin(), translated.end()));
  EXPECT_EQ(h.queued, 0);
}

TEST(FramePipeline, EveryAdmittedFrameIsAnsweredExactlyOnceUnderBlock) {
  expectEveryFrameAnsweredOnce(FramePipeline::Policy::kBlock);
}

TEST(FramePipeline, EveryAdmittedFrameIsAnsweredExactlyOnceUnderLatest) {
  expectEveryFrameAnsweredOnce(FramePipeline::Policy::kLatest);
}

}  // namespace
}  // namespace nidevo::server
