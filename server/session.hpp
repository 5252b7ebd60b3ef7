#pragma once
// One stream = one odometry session. A gRPC callback reactor: reactions only move messages
// under the session's mutex and never block; the frame pipeline (frame_pipeline.hpp) schedules
// decoding and the three odometry stages on the shared worker pool; one write is in flight at a
// time. The session is deleted when gRPC is done with it and no task of it is left.
#include <grpcpp/grpcpp.h>

#include <chrono>
#include <functional>
#include <memory>
#include <mutex>
#include <optional>
#include <string>

#include "frame_decoder.hpp"
#include "frame_pipeline.hpp"
#include "nidevo/odometry/odometry.hpp"
#include "nidevo/v1/odometry.grpc.pb.h"
#include "odometry_stages.hpp"
#include "response_queue.hpp"
#include "server_config.hpp"
#include "server_metrics.hpp"
#include "worker_pool.hpp"

namespace nidevo::server {

struct SessionEnvironment {
  const ServerConfig* config = nullptr;
  WorkerPool* pool = nullptr;
  ServerMetrics* metrics = nullptr;
  // Called once from OnDone, before the session is deleted; must not call back into it.
  std::function<void(class Session*)> on_done;
};

class Session final : public grpc::ServerBidiReactor<v1::TrackRequest, v1::TrackResponse> {
 public:
  Session(grpc::CallbackServerContext* context, SessionEnvironment env);

  void OnReadDone(bool ok) override;
  void OnWriteDone(bool ok) override;
  void OnCancel() override;
  void OnDone() override;

  // Ends the stream with DEADLINE_EXCEEDED if the client sent nothing for the idle timeout
  // while the session had nothing to do.
  void expireIfIdle(Clock::time_point now);

 private:
  // All below with mutex_ held.
  void configure(const v1::SessionConfig& config);
  void startPipeline(std::shared_ptr<const FrameDecoder> decoder,
                     std::unique_ptr<Odometry> odometry);
  void startReadIfWanted();
  void answer(v1::TrackResponse* response);
  void pumpWrites();
  void finish(grpc::Status status);
  void callFinish();  // Finish(*finish_pending_), counted and logged
  void maybeFinishOk();
  bool idle() const;
  void runTask(std::function<void()> work);
  // Bookkeeping after any task; may delete the session, so the caller returns right after.
  void taskDone(std::unique_lock<std::mutex> lock);

  grpc::CallbackServerContext* context_;
  SessionEnvironment env_;
  std::mutex mutex_;
  v1::TrackRequest read_msg_;
  bool reading_ = false;
  bool read_closed_ = false;  // the client half-closed or the stream broke
  bool finish_called_ = false;
  std::optional<grpc::Status> finish_pending_;
  bool done_ = false;
  int tasks_in_flight_ = 0;
  Clock::time_point last_activity_;
  std::string client_name_;  // for the log line only
  uint64_t answered_ = 0;
  v1::OverloadPolicy policy_ = v1::OVERLOAD_POLICY_BLOCK;
  size_t queue_capacity_ = 0;
  Eigen::Isometry3d world_from_first_ = Eigen::Isometry3d::Identity();  // config.initial_pose

  // Set once the config is accepted and the odometry built (the session is then configured).
  std::unique_ptr<OdometryStages> stages_;
  std::unique_ptr<FramePipeline> pipeline_;

  ResponseQueue out_;
  bool writing_ = false;
};

// Answers a stream that cannot be served (session limit) with `status` at once.
class RejectedStream final : public grpc::ServerBidiReactor<v1::TrackRequest, v1::TrackResponse> {
 public:
  explicit RejectedStream(const grpc::Status& status) { Finish(status); }
  void OnDone() override { delete this; }
};

}  // namespace nidevo::server
