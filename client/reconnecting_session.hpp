#pragma once
// A session that outlives its stream: when the stream ends with UNAVAILABLE (the server died,
// the connection dropped, the pod moved), it opens a new session, with backoff and a limit, that
// starts from the last trusted pose (SessionConfig.initial_pose) and resends the frames the old
// one did not answer. The caller sees one answer per frame and one world frame throughout.
//
// How: every frame sent is kept from the anchor on. The anchor is the warmup_frames-th last frame
// answered OK (warmup_frames OK frames later than it are kept too), so that a new session that
// starts with the anchor frame at the anchor's pose re-tracks a few known frames, and has its
// motion model and keyframes back, before it reaches the first unanswered frame. Answers to
// frames already answered are not passed on. When more than max_replay_frames answered frames
// follow the anchor (tracking not OK for long), the newest answered frame with a pose becomes the
// anchor, so that memory stays bounded.
#include <cstdint>
#include <deque>
#include <memory>
#include <mutex>
#include <optional>

#include "odometry_client.hpp"

namespace nidevo::client {

struct ReconnectOptions {
  int max_attempts = 5;             // failed reconnects in a row before giving up; 0: never
  double initial_backoff_s = 0.25;  // wait before the first attempt, doubled after each failure
  double max_backoff_s = 4;
  size_t warmup_frames = 8;
  size_t max_replay_frames = 64;
};

class ReconnectingSession {
 public:
  // Opens the first session (throws std::runtime_error if it cannot connect, as Client::open).
  ReconnectingSession(Client* client, SessionOptions options, ReconnectOptions reconnect,
                      ResponseCallback callback);
  ~ReconnectingSession();
  ReconnectingSession(const ReconnectingSession&) = delete;
  ReconnectingSession& operator=(const ReconnectingSession&) = delete;

  // False when the session has ended for good; finish() says why.
  bool send(const v1::Frame& frame);
  // Half-closes and waits for every answer, reconnecting while frames are unanswered.
  grpc::Status finish();

  int reconnects() const;
  uint64_t resentFrames() const;

 private:
  struct Sent {
    v1::Frame frame;
    bool answered = false;
    std::optional<Eigen::Isometry3d> anchor_pose;  // set: a new session may start here
  };

  void onAnswer(const v1::TrackResponse& response);  // on the stream's reader thread
  void trimToWarmup();                               // with mutex_ held
  std::unique_ptr<Session> openSession();
  // After `status` ended the stream: new sessions until one takes every kept frame. False when
  // the status is not UNAVAILABLE or the attempts ran out (final_status_ says why).
  bool recover(grpc::Status status);
  bool resend();
  bool anyUnanswered();

  Client* client_;
  SessionOptions options_;
  const ReconnectOptions reconnect_;
  ResponseCallback callback_;
  std::unique_ptr<Session> session_;
  std::optional<grpc::Status> final_status_;
  int reconnects_ = 0;
  uint64_t resent_ = 0;

  mutable std::mutex mutex_;  // guards what the reader thread touches
  std::deque<Sent> kept_;     // from the anchor, kept_.front() when it has an anchor_pose, on
};

}  // namespace nidevo::client
