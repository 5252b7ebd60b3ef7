#include "frame_pipeline.hpp"

#include <algorithm>
#include <cmath>
#include <sstream>

#include "pose_response.hpp"

namespace nidevo::server {

size_t slotsForWorkers(int workers) { return size_t(std::clamp(workers, 1, 3)); }

FramePipeline::FramePipeline(std::mutex* mutex, FrameStages* stages, Policy policy,
                             size_t queue_capacity, size_t slots, FramePipelineHooks hooks)
    : mutex_(mutex),
      stages_(stages),
      policy_(policy),
      queue_capacity_(queue_capacity),
      hooks_(std::move(hooks)) {
  for (size_t i = 0; i < slots; ++i) slots_.push_back(std::make_unique<Slot>());
}

void FramePipeline::admit(v1::Frame* frame, Clock::time_point arrival) {
  const double t = frame->timestamp();
  if (!std::isfinite(t) || (have_timestamp_ && !(t > last_timestamp_))) {
    std::ostringstream why;
    why.precision(17);
    why << "frame.timestamp: " << t << " does not increase (previous " << last_timestamp_ << ")";
    v1::TrackResponse rejection = rejectionResponse(*frame, v1::FRAME_STATUS_ERROR, why.str());
    hooks_.answer(&rejection);
    return;
  }
  have_timestamp_ = true;
  last_timestamp_ = t;
  if (policy_ == Policy::kLatest && !queue_.empty() && queue_.size() >= queue_capacity_) {
    v1::TrackResponse dropped =
        rejectionResponse(queue_.front().frame, v1::FRAME_STATUS_DROPPED,
                          "dropped: session queue full (overload policy LATEST)");
    hooks_.answer(&dropped);
    queue_.popFront();
    hooks_.queue_changed(-1);
  }
  Queued& entry = queue_.pushBack();
  entry.frame.Swap(frame);  // `frame` takes the entry's old buffers, for its next message
  entry.arrival = arrival;
  hooks_.queue_changed(+1);
  queue_.releaseIdle(kQueueIdlePushes, [](Queued& idle) { v1::Frame().Swap(&idle.frame); });
}

bool FramePipeline::acceptsMore() const {
  return policy_ == Policy::kLatest || queue_.size() < queue_capacity_;
}

void FramePipeline::schedule() {
  if (stopped_) return;
  // A frame that failed to decode leaves stage 3 at once, and its slot can take a queued frame.
  do {
    startFreeSlots();
    startRotation();
  } while (startTranslation());
}

void FramePipeline::stop() {
  stopped_ = true;
  hooks_.queue_changed(-int(queue_.size()));
  queue_.clear();
}

bool FramePipeline::idle() const {
  if (!queue_.empty()) return false;
  for (const auto& s : slots_)
    if (s->stage != SlotStage::kFree) return false;
  return true;
}

void FramePipeline::startFreeSlots() {
  for (auto& s : slots_) {
    if (queue_.empty()) return;
    if (s->stage != SlotStage::kFree) continue;
    Slot* slot = s.get();
    FrameJob& job = slot->job;
    job.frame.Swap(&queue_.front().frame);
    job.arrival = queue_.front().arrival;
    queue_.popFront();
    hooks_.queue_changed(-1);
    job.ticket = next_ticket_++;
    job.state.frame_index = job.ticket;
    job.error.clear();
    slot->stage = SlotStage::kPreparing;
    hooks_.run_task([this, slot] { runPrepare(slot); });
  }
}

// Stage 2 in ticket order; frames that failed stage 1 pass straight through.
void FramePipeline::startRotation() {
  while (!rotation_running_) {
    Slot* slot = slotAt(next_rotation_, SlotStage::kPrepared);
    if (!slot) return;
    if (!slot->job.error.empty()) {
      slot->stage = SlotStage::kRotated;
      ++next_rotation_;
      continue;
    }
    slot->stage = SlotStage::kRotating;
    rotation_running_ = true;
    hooks_.run_task([this, slot] { runRotate(slot); });
  }
}

// Stage 3 in ticket order; a frame that failed stage 1 is answered ERROR here, in its turn.
// Returns true when that freed a slot.
bool FramePipeline::startTranslation() {
  if (translation_running_) return false;
  Slot* slot = slotAt(next_translation_, SlotStage::kRotated);
  if (!slot) return false;
  if (!slot->job.error.empty()) {
    v1::TrackResponse rejection =
        rejectionResponse(slot->job.frame, v1::FRAME_STATUS_ERROR, slot->job.error);
    hooks_.answer(&rejection);
    slot->stage = SlotStage::kFree;
    ++next_translation_;
    return true;
  }
  slot->stage = SlotStage::kTranslating;
  translation_running_ = true;
  hooks_.run_task([this, slot] { runTranslate(slot); });
  return false;
}

FramePipeline::Slot* FramePipeline::slotAt(uint64_t ticket, SlotStage stage) {
  for (auto& s : slots_)
    if (s->stage == stage && s->job.ticket == ticket) return s.get();
  return nullptr;
}

// A frame whose turn it is goes on to its next stage on the same worker: no queue hop, which
// keeps a lone session's latency close to its compute time. Other frames are dispatched too.
bool FramePipeline::claimNextStage(Slot* slot) {
  if (stopped_ || !slot->job.error.empty()) return false;
  if (slot->stage == SlotStage::kPrepared && !rotation_running_ &&
      slot->job.ticket == next_rotation_) {
    slot->stage = SlotStage::kRotating;
    rotation_running_ = true;
  } else if (slot->stage == SlotStage::kRotated && !translation_running_ &&
             slot->job.ticket == next_translation_) {
    slot->stage = SlotStage::kTranslating;
    translation_running_ = true;
  } else {
    return false;
  }
  schedule();
  hooks_.queue_drained();
  return true;
}

void FramePipeline::continueOrEnd(Slot* slot, std::unique_lock<std::mutex> lock) {
  if (!claimNextStage(slot)) {
    hooks_.task_done(std::move(lock));  // may destroy the pipeline: nothing after this
    return;
  }
  const SlotStage next = slot->stage;
  lock.unlock();
  if (next == SlotStage::kRotating)
    runRotate(slot);
  else
    runTranslate(slot);
}

void FramePipeline::runPrepare(Slot* slot) {
  stages_->prepare(&slot->job);
  std::unique_lock<std::mutex> lock(*mutex_);
  slot->stage = SlotStage::kPrepared;
  continueOrEnd(slot, std::move(lock));
}

void FramePipeline::runRotate(Slot* slot) {
  stages_->rotate(&slot->job);
  std::unique_lock<std::mutex> lock(*mutex_);
  slot->stage = SlotStage::kRotated;
  rotation_running_ = false;
  ++next_rotation_;
  continueOrEnd(slot, std::move(lock));
}

void FramePipeline::runTranslate(Slot* slot) {
  stages_->translate(&slot->job);
  std::unique_lock<std::mutex> lock(*mutex_);
  slot->stage = SlotStage::kFree;
  translation_running_ = false;
  ++next_translation_;
  hooks_.answer(&slot->job.response);
  hooks_.task_done(std::move(lock));
}

}  // namespace nidevo::server
