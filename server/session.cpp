#include "session.hpp"

#include <cmath>
#include <exception>
#include <iostream>
#include <sstream>

#include "absl/status/status.h"
#include "pose_response.hpp"

namespace nidevo::server {

namespace {

double secondsBetween(Clock::time_point a, Clock::time_point b) {
  return std::chrono::duration<double>(b - a).count();
}

FrameOutcome outcomeOf(v1::FrameStatus status) {
  switch (status) {
    case v1::FRAME_STATUS_OK:
      return FrameOutcome::kOk;
    case v1::FRAME_STATUS_DEGRADED:
      return FrameOutcome::kDegraded;
    case v1::FRAME_STATUS_LOST:
      return FrameOutcome::kLost;
    case v1::FRAME_STATUS_DROPPED:
      return FrameOutcome::kDropped;
    default:
      return FrameOutcome::kError;
  }
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
  if (!pipeline_) {
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
  pipeline_->admit(read_msg_.mutable_frame(), now);
  pipeline_->schedule();
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
  world_from_first_ = initialPoseOf(config);
  runTask([this, decoder] {
    std::unique_ptr<Odometry> odometry;
    std::string error;
    try {
      odometry = std::make_unique<Odometry>(decoder->camera(), env_.config->odometry);
    } catch (const std::exception& e) {
      error = std::string("config.camera: ") + e.what();
    }
    std::unique_lock<std::mutex> lock(mutex_);
    if (!error.empty())
      finish(grpc::Status(grpc::StatusCode::INVALID_ARGUMENT, error));
    else
      startPipeline(decoder, std::move(odometry));
    taskDone(std::move(lock));
  });
}

void Session::startPipeline(std::shared_ptr<const FrameDecoder> decoder,
                            std::unique_ptr<Odometry> odometry) {
  stages_ = std::make_unique<OdometryStages>(std::move(decoder), std::move(odometry), env_.metrics,
                                             world_from_first_);
  FramePipelineHooks hooks;
  hooks.run_task = [this](std::function<void()> task) { runTask(std::move(task)); };
  hooks.answer = [this](v1::TrackResponse* response) { answer(response); };
  hooks.queue_changed = [this](int delta) { env_.metrics->queuedFrames(delta); };
  hooks.queue_drained = [this] { startReadIfWanted(); };
  hooks.task_done = [this](std::unique_lock<std::mutex> lock) { taskDone(std::move(lock)); };
  pipeline_ = std::make_unique<FramePipeline>(
      &mutex_, stages_.get(),
      policy_ == v1::OVERLOAD_POLICY_LATEST ? FramePipeline::Policy::kLatest
                                            : FramePipeline::Policy::kBlock,
      queue_capacity_, slotsForWorkers(env_.pool->size()), std::move(hooks));
  last_activity_ = Clock::now();
  startReadIfWanted();
}

void Session::runTask(std::function<void()> work) {
  ++tasks_in_flight_;
  env_.pool->submit(std::move(work));
}

void Session::taskDone(std::unique_lock<std::mutex> lock) {
  --tasks_in_flight_;
  if (pipeline_) pipeline_->schedule();
  startReadIfWanted();
  maybeFinishOk();
  const bool destroy = done_ && tasks_in_flight_ == 0;
  lock.unlock();
  if (destroy) delete this;
}

void Session::startReadIfWanted() {
  if (reading_ || read_closed_ || finish_pending_ || finish_called_ || !pipeline_) return;
  if (!pipeline_->acceptsMore()) return;
  reading_ = true;
  StartRead(&read_msg_);
}

void Session::answer(v1::TrackResponse* response) {
  env_.metrics->frame(outcomeOf(response->status()));
  if (finish_pending_ || finish_called_) return;
  ++answered_;
  out_.push(response);
  pumpWrites();
}

void Session::pumpWrites() {
  if (writing_ || out_.empty() || finish_called_) return;
  writing_ = true;
  StartWrite(&out_.front());  // it stays put until OnWriteDone pops it
}

void Session::OnWriteDone(bool ok) {
  std::lock_guard<std::mutex> lock(mutex_);
  writing_ = false;
  if (!out_.empty()) out_.popFront();
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
  if (pipeline_) pipeline_->stop();
  if (writing_) {
    out_.keepFront();  // the first is being written
    return;            // OnWriteDone finishes
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
  return out_.empty() && !writing_ && tasks_in_flight_ == 0 && (!pipeline_ || pipeline_->idle());
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
