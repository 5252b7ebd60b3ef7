#include "reconnecting_session.hpp"

#include <algorithm>
#include <chrono>
#include <iostream>
#include <stdexcept>
#include <thread>

namespace nidevo::client {

ReconnectingSession::ReconnectingSession(Client* client, SessionOptions options,
                                         ReconnectOptions reconnect, ResponseCallback callback)
    : client_(client),
      options_(std::move(options)),
      reconnect_(reconnect),
      callback_(std::move(callback)) {
  session_ = openSession();
}

ReconnectingSession::~ReconnectingSession() = default;  // the Session cancels if still open

std::unique_ptr<Session> ReconnectingSession::openSession() {
  SessionOptions options = options_;
  {
    std::lock_guard<std::mutex> lock(mutex_);
    if (!kept_.empty() && kept_.front().anchor_pose)
      options.initial_pose = kept_.front().anchor_pose;
  }
  return client_->open(options, [this](const v1::TrackResponse& r) { onAnswer(r); });
}

void ReconnectingSession::onAnswer(const v1::TrackResponse& response) {
  {
    std::lock_guard<std::mutex> lock(mutex_);
    auto it = std::find_if(kept_.begin(), kept_.end(), [&](const Sent& s) {
      return s.frame.sequence() == response.sequence();
    });
    // Not kept: answered before the anchor. Answered: a frame resent after a reconnect.
    if (it == kept_.end() || it->answered) return;
    it->answered = true;
    const bool has_pose = response.status() == v1::FRAME_STATUS_OK ||
                          response.status() == v1::FRAME_STATUS_DEGRADED ||
                          response.status() == v1::FRAME_STATUS_LOST;
    const auto answered_before =
        size_t(std::count_if(kept_.begin(), it, [](const Sent& s) { return s.answered; }));
    if (response.status() == v1::FRAME_STATUS_OK) {
      it->anchor_pose = toIsometry(response.pose());
      trimToWarmup();
    } else if (has_pose && answered_before > reconnect_.max_replay_frames) {
      it->anchor_pose = toIsometry(response.pose());
      kept_.erase(kept_.begin(), it);  // earlier frames are all answered (answers keep order)
    }
  }
  callback_(response);
}

void ReconnectingSession::trimToWarmup() {
  auto anchors = size_t(
      std::count_if(kept_.begin(), kept_.end(), [](const Sent& s) { return bool(s.anchor_pose); }));
  // Frames before an anchor are all answered: answers come in the order frames were sent.
  while (anchors > reconnect_.warmup_frames + 1) {
    kept_.pop_front();
    while (!kept_.front().anchor_pose) kept_.pop_front();
    --anchors;
  }
}

bool ReconnectingSession::send(const v1::Frame& frame) {
  if (final_status_) return false;
  {
    std::lock_guard<std::mutex> lock(mutex_);
    kept_.push_back({frame, false, std::nullopt});
  }
  if (session_->send(frame)) return true;
  return recover(session_->finish());
}

bool ReconnectingSession::anyUnanswered() {
  std::lock_guard<std::mutex> lock(mutex_);
  return std::any_of(kept_.begin(), kept_.end(), [](const Sent& s) { return !s.answered; });
}

bool ReconnectingSession::resend() {
  std::vector<v1::Frame> frames;
  {
    std::lock_guard<std::mutex> lock(mutex_);
    for (const Sent& s : kept_) frames.push_back(s.frame);
  }
  for (const v1::Frame& f : frames) {
    if (!session_->send(f)) return false;
    ++resent_;
  }
  return true;
}

bool ReconnectingSession::recover(grpc::Status status) {
  double backoff = reconnect_.initial_backoff_s;
  for (int attempt = 1;; ++attempt) {
    if (status.error_code() != grpc::StatusCode::UNAVAILABLE || attempt > reconnect_.max_attempts) {
      final_status_ = status;
      return false;
    }
    std::cerr << "stream ended with UNAVAILABLE (" << status.error_message() << "): reconnect "
              << attempt << " of " << reconnect_.max_attempts << " in " << backoff << " s\n";
    std::this_thread::sleep_for(std::chrono::duration<double>(backoff));
    backoff = std::min(2 * backoff, reconnect_.max_backoff_s);
    try {
      session_ = openSession();
    } catch (const std::runtime_error& e) {
      status = grpc::Status(grpc::StatusCode::UNAVAILABLE, e.what());
      continue;
    }
    if (resend()) {
      ++reconnects_;
      return true;
    }
    status = session_->finish();
  }
}

grpc::Status ReconnectingSession::finish() {
  while (!final_status_) {
    const grpc::Status status = session_->finish();
    if (status.ok() || !anyUnanswered()) {
      final_status_ = status;
      break;
    }
    if (recover(status)) continue;
  }
  return *final_status_;
}

int ReconnectingSession::reconnects() const { return reconnects_; }
uint64_t ReconnectingSession::resentFrames() const { return resent_; }

}  // namespace nidevo::client
