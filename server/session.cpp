#include "session.hpp"

#include <cmath>
#include <exception>
#include <iostream>
#include <sstream>

#include "absl/status/status.h"
#include "pose_response.hpp"

namespace nidevo::server {

namespace {

// Frames in stage processing at once per session: one per stage keeps all three busy.
constexpr size_t kSlots = 3;

double secondsBetween(Clock::time_point a, Clock::time_point b) {
  return std::chrono::duration<double>(b - a).count();
}

}  // namespace

Session::Session(grpc::CallbackServerContext* context, SessionEnvironment env)
    : context_(context), env_(std::move(env)), last_activity_(Clock::now()) {
  std::lock_guard<std::mutex> lock(mutex_);
  reading_ = true;
  StartRead(&read_msg_);
}

void Session::OnReadDone(bool ok) {
  std::lock_guard<std::mutex> lock(mutex_);
  reading_ = false;
  if (!ok) {
    read_closed_ = true;
    // A failed read is a half-close, or a cancel whose OnCancel has not come yet.
    if (context_->IsCancelled())
      finish(grpc::Status(grpc::StatusCode::CANCELLED, "cancelled"));
    else
      maybeFinishOk();
    return;
  }
  const Clock::time_point now = Clock::now();
  last_activity_ = now;
  if (finish_pending_ || finish_called_) return;
  if (!configured_) {
    if (read_msg_.kind_case() != v1::TrackRequest::kConfig) {
      finish(grpc::Status(grpc::StatusCode::INVALID_ARGUMENT,
                          "config: the first message of a stream must be a SessionConfig"));
      return;
    }
    configure(read_msg_.config());
    return;
  }
  if (read_msg_.kind_case() == v1::TrackRequest::kConfig) {
    finish(grpc::Status(grpc::StatusCode::INVALID_ARGUMENT,
                        "config: only the first message of a stream may be a SessionConfig"));
    return;
  }
  if (read_msg_.kind_case() != v1::TrackRequest::kFrame) {
    finish(grpc::Status(grpc::StatusCode::INVALID_ARGUMENT,
                        "frame: message carries neither a config nor a frame"));
    return;
  }
  admit(read_msg_.mutable_frame(), now);
  schedule();
  startReadIfWanted();
}

void Session::configure(const v1::SessionConfig& config) {
  if (std::string e = FrameDecoder::validate(config); !e.empty()) {
    finish(grpc::Status(grpc::StatusCode::INVALID_ARGUMENT, e));
    return;
  }
  const ServerConfig& sc = *env_.config;
  if (config.queue_capacity() > uint32_t(sc.max_queue_capacity)) {
    finish(grpc::Status(grpc::StatusCode::INVALID_ARGUMENT,
                        "config.queue_capacity: at most " + std::to_string(sc.max_queue_capacity) +
                            " on this server, got " + std::to_string(config.queue_capacity())));
    return;
  }
  queue_capacity_ =
      config.queue_capacity() > 0 ? config.queue_capacity() : size_t(sc.default_queue_capacity);
  policy_ = config.overload_policy() == v1::OVERLOAD_POLICY_LATEST ? v1::OVERLOAD_POLICY_LATEST
                                                                   : v1::OVERLOAD_POLICY_BLOCK;
  client_name_ = config.client_name().substr(0, 64);
  // Building the odometry allocates every per-session buffer and FFTW plan: worker's job.
  auto decoder = std::make_shared<const FrameDecoder>(config);
  runTask([this, decoder] {
    std::unique_ptr<Odometry> odometry;
    std::string error;
    try {
      odometry = std::make_unique<Odometry>(decoder->camera(), env_.config->odometry);
    } catch (const std::exception& e) {
      error = std::string("config.camera: ") + e.what();
    }
    std::unique_lock<std::mutex> lock(mutex_);
    if (!error.empty()) {
      finish(grpc::Status(grpc::StatusCode::INVALID_ARGUMENT, error));
    } else {
      decoder_ = decoder;
      odometry_ = std::move(odometry);
      for (size_t i = 0; i < kSlots; ++i) slots_.push_back(std::make_unique<Slot>());
      configured_ = true;
      last_activity_ = Clock::now();
      startReadIfWanted();
    }
    taskDone(std::move(lock));
  });
}

void Session::admit(v1::Frame* frame, Clock::time_point arrival) {
  const double t = frame->timestamp();
  if (!std::isfinite(t) || (have_timestamp_ && !(t > last_timestamp_))) {
    std::ostringstream why;
    why.precision(17);
    why << "frame.timestamp: " << t << " does not increase (previous " << last_timestamp_ << ")";
    env_.metrics->frame(FrameOutcome::kError);
    pushResponse(rejection(*frame, v1::FRAME_STATUS_ERROR, why.str()));
    return;
  }
  have_timestamp_ = true;
  last_timestamp_ = t;
  if (queue_.size() >= queue_capacity_) {  // only under LATEST: BLOCK stops reading first
    env_.metrics->frame(FrameOutcome::kDropped);
    pushResponse(rejection(queue_.front().frame, v1::FRAME_STATUS_DROPPED,
                           "dropped: session queue full (overload policy LATEST)"));
    queue_.pop_front();
    env_.metrics->queuedFrames(-1);
  }
  queue_.emplace_back();
  queue_.back().frame.Swap(frame);
  queue_.back().arrival = arrival;
  env_.metrics->queuedFrames(+1);
}

Session::Slot* Session::slotWithTicket(uint64_t ticket, SlotStage stage) {
  for (auto& s : slots_)
    if (s->stage == stage && s->ticket == ticket) return s.get();
  return nullptr;
}

void Session::schedule() {
  if (finish_pending_ || finish_called_ || !configured_) return;
  for (auto& s : slots_) {
    if (queue_.empty()) break;
    if (s->stage != SlotStage::kFree) continue;
    Slot* slot = s.get();
    slot->pending.frame.Swap(&queue_.front().frame);
    slot->pending.arrival = queue_.front().arrival;
    queue_.pop_front();
    env_.metrics->queuedFrames(-1);
    slot->ticket = next_ticket_++;
    slot->state.frame_index = slot->ticket;
    slot->stage = SlotStage::kNormals;
    runTask([this, slot] { runNormals(slot); });
  }
  // Stage 2 in ticket order; frames that failed to decode pass straight through.
  while (!rotation_running_) {
    Slot* slot = slotWithTicket(next_rotation_, SlotStage::kNormalsDone);
    if (!slot) break;
    if (!slot->error.empty()) {
      slot->stage = SlotStage::kRotationDone;
      ++next_rotation_;
      continue;
    }
    slot->stage = SlotStage::kRotation;
    rotation_running_ = true;
    runTask([this, slot] { runRotation(slot); });
  }
  while (!translation_running_) {
    Slot* slot = slotWithTicket(next_translation_, SlotStage::kRotationDone);
    if (!slot) break;
    if (!slot->error.empty()) {
      env_.metrics->frame(FrameOutcome::kError);
      pushResponse(rejection(slot->pending.frame, v1::FRAME_STATUS_ERROR, slot->error));
      slot->stage = SlotStage::kFree;
      ++next_translation_;
      schedule();  // the freed slot can take a queued frame
      return;
    }
    slot->stage = SlotStage::kTranslation;
    translation_running_ = true;
    runTask([this, slot] { runTranslation(slot); });
  }
}

void Session::runTask(std::function<void()> work) {
  ++tasks_in_flight_;
  env_.pool->submit(std::move(work));
}

// A frame whose turn it is goes on to its next stage on the same worker: no queue hop, which
// keeps a lone session's latency close to its compute time. Other frames are dispatched too.
bool Session::claimNextStage(Slot* slot) {
  if (finish_pending_ || finish_called_ || !slot->error.empty()) return false;
  if (slot->stage == SlotStage::kNormalsDone && !rotation_running_ &&
      slot->ticket == next_rotation_) {
    slot->stage = SlotStage::kRotation;
    rotation_running_ = true;
  } else if (slot->stage == SlotStage::kRotationDone && !translation_running_ &&
             slot->ticket == next_translation_) {
    slot->stage = SlotStage::kTranslation;
    translation_running_ = true;
  } else {
    return false;
  }
  schedule();
  startReadIfWanted();
  return true;
}

void Session::runNormals(Slot* slot) {
  const Clock::time_point start = Clock::now();
  slot->queue_s = secondsBetween(slot->pending.arrival, start);
  slot->error = decoder_->decode(slot->pending.frame, &slot->image);
  slot->decode_s = secondsBetween(start, Clock::now());
  if (slot->error.empty()) {
    try {
      odometry_->computeNormals(slot->image, &slot->state);
    } catch (const std::exception& e) {
      slot->error = std::string("frame: ") + e.what();
    }
  }
  std::unique_lock<std::mutex> lock(mutex_);
  slot->stage = SlotStage::kNormalsDone;
  if (claimNextStage(slot)) {
    lock.unlock();
    runRotation(slot);
    return;
  }
  taskDone(std::move(lock));
}

void Session::runRotation(Slot* slot) {
  odometry_->estimateRotation(&slot->state);
  std::unique_lock<std::mutex> lock(mutex_);
  slot->stage = SlotStage::kRotationDone;
  rotation_running_ = false;
  ++next_rotation_;
  if (claimNextStage(slot)) {
    lock.unlock();
    runTranslation(slot);
    return;
  }
  taskDone(std::move(lock));
}

void Session::runTranslation(Slot* slot) {
  const PoseEstimate pose = odometry_->estimateTranslation(&slot->state);
  v1::TrackResponse response;
  fillPoseResponse(slot->pending.frame, pose, &response);
  auto* t = response.mutable_timings();
  t->set_queue(slot->queue_s);
  t->set_decode(slot->decode_s);
  const double total = secondsBetween(slot->pending.arrival, Clock::now());
  t->set_total(total);

  ServerMetrics& m = *env_.metrics;
  m.frame(pose.state == TrackingState::kOk         ? FrameOutcome::kOk
          : pose.state == TrackingState::kDegraded ? FrameOutcome::kDegraded
                                                   : FrameOutcome::kLost);
  m.frameLatency(total);
  m.stage(Stage::kQueue, slot->queue_s);
  m.stage(Stage::kDecode, slot->decode_s);
  m.stage(Stage::kNormals, pose.times.normals_s);
  m.stage(Stage::kRotation, pose.times.rotation_s);
  m.stage(Stage::kTranslation, pose.times.translation_s);
  if (pose.state != TrackingState::kLost) m.psr(pose.psr);
  if (pose.rotation_keyframe) m.rotationKeyframe();
  if (pose.translation_keyframe) m.translationKeyframe();

  std::unique_lock<std::mutex> lock(mutex_);
  slot->stage = SlotStage::kFree;
  translation_running_ = false;
  ++next_translation_;
  pushResponse(std::move(response));
  taskDone(std::move(lock));
}

void Session::taskDone(std::unique_lock<std::mutex> lock) {
  --tasks_in_flight_;
  schedule();
  startReadIfWanted();
  maybeFinishOk();
  const bool destroy = done_ && tasks_in_flight_ == 0;
  lock.unlock();
  if (destroy) delete this;
}

void Session::startReadIfWanted() {
  if (reading_ || read_closed_ || finish_pending_ || finish_called_ || !configured_) return;
  if (policy_ == v1::OVERLOAD_POLICY_BLOCK && queue_.size() >= queue_capacity_) return;
  reading_ = true;
  StartRead(&read_msg_);
}

v1::TrackResponse Session::rejection(const v1::Frame& frame, v1::FrameStatus status,
                                     const std::string& reason) const {
  v1::TrackResponse r;
  r.set_sequence(frame.sequence());
  r.set_timestamp(frame.timestamp());
  r.set_status(status);
  r.set_reason(reason);
  return r;
}

void Session::pushResponse(v1::TrackResponse response) {
  if (finish_pending_ || finish_called_) return;
  ++answered_;
  out_.push_back(std::move(response));
  pumpWrites();
}

void Session::pumpWrites() {
  if (writing_ || out_.empty() || finish_called_) return;
  writing_ = true;
  StartWrite(&out_.front());  // deque: the element stays put until OnWriteDone pops it
}

void Session::OnWriteDone(bool ok) {
  std::lock_guard<std::mutex> lock(mutex_);
  writing_ = false;
  if (!out_.empty()) out_.pop_front();
  if (!ok) {  // the stream broke; OnCancel follows
    out_.clear();
    read_closed_ = true;
    finish(grpc::Status(grpc::StatusCode::CANCELLED, "stream broken while writing"));
  }
  if (finish_pending_ && !finish_called_) {
    callFinish();
    return;
  }
  pumpWrites();
  maybeFinishOk();
}

void Session::finish(grpc::Status status) {
  if (finish_pending_ || finish_called_) return;
  finish_pending_ = status;
  env_.metrics->queuedFrames(-double(queue_.size()));
  queue_.clear();
  if (writing_) {
    out_.erase(out_.begin() + 1, out_.end());  // the first is being written
    return;                                    // OnWriteDone finishes
  }
  out_.clear();
  callFinish();
}

void Session::callFinish() {
  finish_called_ = true;
  env_.metrics->sessionEnded(finish_pending_->error_code());
  std::ostringstream line;  // one line per session, for operators; never per frame
  line << "nidevo-server: session" << (client_name_.empty() ? "" : " '" + client_name_ + "'")
       << " ended "
       << absl::StatusCodeToString(static_cast<absl::StatusCode>(finish_pending_->error_code()))
       << " after " << answered_ << " answers";
  if (!finish_pending_->ok()) line << ": " << finish_pending_->error_message();
  std::cerr << line.str() + "\n";
  Finish(*finish_pending_);
}

bool Session::idle() const {
  if (!queue_.empty() || !out_.empty() || writing_ || tasks_in_flight_ > 0) return false;
  for (const auto& s : slots_)
    if (s->stage != SlotStage::kFree) return false;
  return true;
}

void Session::maybeFinishOk() {
  if (read_closed_ && idle()) finish(grpc::Status::OK);
}

void Session::OnCancel() {
  std::lock_guard<std::mutex> lock(mutex_);
  read_closed_ = true;
  finish(grpc::Status(grpc::StatusCode::CANCELLED, "cancelled"));
}

void Session::expireIfIdle(Clock::time_point now) {
  std::lock_guard<std::mutex> lock(mutex_);
  if (finish_pending_ || finish_called_ || !reading_ || !idle()) return;
  const double quiet_s = secondsBetween(last_activity_, now);
  if (quiet_s <= env_.config->idle_timeout_s) return;
  std::ostringstream why;
  why << "session idle: no message for " << env_.config->idle_timeout_s
      << " s (server's idle timeout)";
  finish(grpc::Status(grpc::StatusCode::DEADLINE_EXCEEDED, why.str()));
}

void Session::OnDone() {
  if (env_.on_done) env_.on_done(this);
  std::unique_lock<std::mutex> lock(mutex_);
  done_ = true;
  const bool destroy = tasks_in_flight_ == 0;
  lock.unlock();
  if (destroy) delete this;
}

}  // namespace nidevo::server
