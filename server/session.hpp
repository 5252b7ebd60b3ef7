#pragma once
// One stream = one odometry session. A gRPC callback reactor: reactions only move messages
// between queues under the session's mutex; decoding and the three odometry stages run on the
// shared worker pool. Stage 1 (decode + normals) of several frames may run at once, stages 2
// and 3 each take frames in arrival order, and one write is in flight at a time.
#include <grpcpp/grpcpp.h>

#include <chrono>
#include <deque>
#include <functional>
#include <memory>
#include <mutex>
#include <optional>
#include <string>
#include <vector>

#include "frame_decoder.hpp"
#include "nidevo/odometry/odometry.hpp"
#include "nidevo/v1/odometry.grpc.pb.h"
#include "server_config.hpp"
#include "server_metrics.hpp"
#include "worker_pool.hpp"

namespace nidevo::server {

using Clock = std::chrono::steady_clock;

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
  enum class SlotStage { kFree, kNormals, kNormalsDone, kRotation, kRotationDone, kTranslation };
  struct Pending {
    v1::Frame frame;
    Clock::time_point arrival;
  };
  struct Slot {
    SlotStage stage = SlotStage::kFree;
    uint64_t ticket = 0;
    Pending pending;
    RgbdFrame image;
    FrameState state;
    std::string error;  // decode error, or empty
    double queue_s = 0, decode_s = 0;
  };

  // All below with mutex_ held.
  void configure(const v1::SessionConfig& config);
  void admit(v1::Frame* frame, Clock::time_point arrival);
  void schedule();
  void startReadIfWanted();
  void pushResponse(v1::TrackResponse response);
  void pumpWrites();
  void finish(grpc::Status status);
  void callFinish();  // Finish(*finish_pending_), counted and logged
  void maybeFinishOk();
  bool idle() const;
  Slot* slotWithTicket(uint64_t ticket, SlotStage stage);
  v1::TrackResponse rejection(const v1::Frame& frame, v1::FrameStatus status,
                              const std::string& reason) const;
  void runTask(std::function<void()> work);

  // With mutex_ held: moves the slot into its next stage if it may run now.
  bool claimNextStage(Slot* slot);
  // Worker-side stage bodies: run without mutex_ on one slot.
  void runNormals(Slot* slot);
  void runRotation(Slot* slot);
  void runTranslation(Slot* slot);
  // Bookkeeping after any task; may delete the session, so the caller returns right after.
  void taskDone(std::unique_lock<std::mutex> lock);

  grpc::CallbackServerContext* context_;
  SessionEnvironment env_;
  std::mutex mutex_;
  v1::TrackRequest read_msg_;
  bool reading_ = false;
  bool read_closed_ = false;  // the client half-closed or the stream broke
  bool configured_ = false;
  bool finish_called_ = false;
  std::optional<grpc::Status> finish_pending_;
  bool done_ = false;
  int tasks_in_flight_ = 0;
  Clock::time_point last_activity_;

  std::shared_ptr<const FrameDecoder> decoder_;
  std::unique_ptr<Odometry> odometry_;
  v1::OverloadPolicy policy_ = v1::OVERLOAD_POLICY_BLOCK;
  size_t queue_capacity_ = 0;
  std::string client_name_;  // for the log line only
  uint64_t answered_ = 0;
  bool have_timestamp_ = false;
  double last_timestamp_ = 0;

  std::deque<Pending> queue_;
  std::vector<std::unique_ptr<Slot>> slots_;
  uint64_t next_ticket_ = 0;       // given to the next frame entering stage 1
  uint64_t next_rotation_ = 0;     // ticket stage 2 takes next
  uint64_t next_translation_ = 0;  // ticket stage 3 takes next
  bool rotation_running_ = false;
  bool translation_running_ = false;

  std::deque<v1::TrackResponse> out_;
  bool writing_ = false;
};

// Answers a stream that cannot be served (session limit) with `status` at once.
class RejectedStream final : public grpc::ServerBidiReactor<v1::TrackRequest, v1::TrackResponse> {
 public:
  explicit RejectedStream(const grpc::Status& status) { Finish(status); }
  void OnDone() override { delete this; }
};

}  // namespace nidevo::server
