#pragma once
// One session's frames from admission to answer, apart from gRPC: a bounded queue under the
// session's overload policy, a few slots that carry frames through the three odometry stages,
// stage 1 of several frames at once, stages 2 and 3 each one frame at a time in admission order,
// and exactly one answer per admitted frame.
//
// Locking: the pipeline shares its owner's mutex. Every public method is called with it held;
// the stage work runs without it, in tasks the owner's executor runs later.
#include <chrono>
#include <cstdint>
#include <functional>
#include <memory>
#include <mutex>
#include <string>
#include <vector>

#include "nidevo/odometry/odometry.hpp"
#include "nidevo/v1/odometry.pb.h"
#include "recycling_queue.hpp"

namespace nidevo::server {

using Clock = std::chrono::steady_clock;

// One frame on its way through the stages; the stage work reads and fills it.
struct FrameJob {
  uint64_t ticket = 0;  // order of entry into the stages, from 0
  v1::Frame frame;
  Clock::time_point arrival;
  FrameState state;
  std::string error;  // set by stage 1 when the frame cannot be used: answered ERROR
  double queue_s = 0;
  double decode_s = 0;
  v1::TrackResponse response;  // stage 3's answer; reused from frame to frame
};

// The per-frame work, run without the lock. prepare() may run for several jobs at once;
// rotate() and translate() each for one job at a time, in ticket order.
class FrameStages {
 public:
  virtual ~FrameStages() = default;
  virtual void prepare(FrameJob* job) = 0;    // stage 1 (decode, normals); job->error if unusable
  virtual void rotate(FrameJob* job) = 0;     // stage 2
  virtual void translate(FrameJob* job) = 0;  // stage 3: the frame's answer in job->response
};

struct FramePipelineHooks {
  // Runs `task` later on some thread; never inline, the caller holds the lock.
  std::function<void(std::function<void()>)> run_task;
  // With the lock held: one answer per admitted frame (also DROPPED and ERROR ones). The owner
  // may swap the message's contents out (ResponseQueue::push) and leave others in their place.
  std::function<void(v1::TrackResponse*)> answer;
  // With the lock held: the queue's length changed by `delta`.
  std::function<void(int delta)> queue_changed;
  // With the lock held: the queue shrank while a task goes on (a BLOCK reader may resume).
  std::function<void()> queue_drained;
  // With the lock held, the last step of every task: the owner's bookkeeping. It must release
  // the lock and may destroy the pipeline.
  std::function<void(std::unique_lock<std::mutex>)> task_done;
};

// Slots for a session whose stages run on `workers` threads: one per stage keeps all three busy
// where three threads can run them, and no more than the threads, since a slot beyond them only
// holds a frame (about 5 MB at VGA, kept for reuse) that waits.
size_t slotsForWorkers(int workers);

class FramePipeline {
 public:
  enum class Policy { kBlock, kLatest };

  FramePipeline(std::mutex* mutex, FrameStages* stages, Policy policy, size_t queue_capacity,
                size_t slots, FramePipelineHooks hooks);

  // Queues the frame (its contents are moved out) or answers it ERROR (timestamp not finite or
  // not increasing). Under LATEST a full queue first answers its oldest frame DROPPED; under
  // BLOCK nothing is ever dropped, the owner stops reading while acceptsMore() is false.
  void admit(v1::Frame* frame, Clock::time_point arrival);
  bool acceptsMore() const;
  // Starts every stage that may run now.
  void schedule();
  // From now on no stage starts and the queue is emptied unanswered; running stages still end
  // in task_done (their answers too go to `answer`, for the owner to discard).
  void stop();
  // Nothing queued and no frame in any stage.
  bool idle() const;

 private:
  enum class SlotStage { kFree, kPreparing, kPrepared, kRotating, kRotated, kTranslating };
  struct Slot {
    SlotStage stage = SlotStage::kFree;
    FrameJob job;
  };
  struct Queued {
    v1::Frame frame;
    Clock::time_point arrival;
  };

  void startFreeSlots();
  void startRotation();
  bool startTranslation();
  Slot* slotAt(uint64_t ticket, SlotStage stage);
  bool claimNextStage(Slot* slot);
  void runPrepare(Slot* slot);
  void runRotate(Slot* slot);
  void runTranslate(Slot* slot);
  void continueOrEnd(Slot* slot, std::unique_lock<std::mutex> lock);

  std::mutex* mutex_;
  FrameStages* stages_;
  const Policy policy_;
  const size_t queue_capacity_;
  FramePipelineHooks hooks_;

  bool stopped_ = false;
  bool have_timestamp_ = false;
  double last_timestamp_ = 0;
  // Its frames' byte buffers go round: no allocation per frame. A session's first frames, while
  // its odometry is built, fill every entry (1.5 MB each at VGA raw), and a steady 30 Hz stream
  // then needs one: entries unused for this many frames give their buffers back.
  static constexpr uint64_t kQueueIdlePushes = 64;
  RecyclingQueue<Queued> queue_;
  std::vector<std::unique_ptr<Slot>> slots_;
  uint64_t next_ticket_ = 0;       // given to the next frame entering stage 1
  uint64_t next_rotation_ = 0;     // ticket stage 2 takes next
  uint64_t next_translation_ = 0;  // ticket stage 3 takes next
  bool rotation_running_ = false;
  bool translation_running_ = false;
};

}  // namespace nidevo::server
