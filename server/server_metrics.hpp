#pragma once
// The server's Prometheus metrics. Families and children are created once; recording is a few
// atomic operations. No per-session label: sessions are counted, never named.
#include <array>
#include <memory>
#include <string>

#include "prometheus/counter.h"
#include "prometheus/family.h"
#include "prometheus/gauge.h"
#include "prometheus/histogram.h"
#include "prometheus/registry.h"

namespace nidevo::server {

enum class FrameOutcome { kOk, kDegraded, kLost, kDropped, kError };
enum class Stage { kDecode, kQueue, kNormals, kRotation, kTranslation };

class ServerMetrics {
 public:
  explicit ServerMetrics(const std::string& version);

  std::shared_ptr<prometheus::Registry> registry() const { return registry_; }

  void frame(FrameOutcome outcome) { frames_[size_t(outcome)]->Increment(); }
  void frameLatency(double seconds) { frame_latency_->Observe(seconds); }
  void stage(Stage s, double seconds) { stages_[size_t(s)]->Observe(seconds); }
  void psr(double value) { psr_->Observe(value); }
  // The pose check of a frame: `hypothesis` as in PoseVerification ("method", "prediction",
  // "last pose"; anything else is not counted), whether it passed, its surface residual.
  void poseCheck(const char* hypothesis, bool passed, double residual_rms_m);
  void rotationKeyframe() { rotation_keyframes_->Increment(); }
  void translationKeyframe() { translation_keyframes_->Increment(); }
  // `code` is a grpc::StatusCode value.
  void sessionEnded(int code);
  void activeSessions(double delta) { active_sessions_->Increment(delta); }
  // A call refused for its bearer token: missing (or not "Bearer ...") or not accepted.
  void unauthenticated(bool missing) { unauthenticated_[missing ? 0 : 1]->Increment(); }
  void queuedFrames(double delta) { queued_frames_->Increment(delta); }
  // The service gave freed heap memory back to the system (once the last open session ended).
  void memoryReleased() { memory_releases_->Increment(); }

 private:
  std::shared_ptr<prometheus::Registry> registry_;
  std::array<prometheus::Counter*, 5> frames_{};
  prometheus::Histogram* frame_latency_ = nullptr;
  std::array<prometheus::Histogram*, 5> stages_{};
  prometheus::Histogram* psr_ = nullptr;
  std::array<std::array<prometheus::Counter*, 2>, 4> checks_{};  // [hypothesis][passed]
  prometheus::Histogram* check_residual_ = nullptr;
  prometheus::Counter* rotation_keyframes_ = nullptr;
  prometheus::Counter* translation_keyframes_ = nullptr;
  prometheus::Family<prometheus::Counter>* sessions_family_ = nullptr;
  std::array<prometheus::Counter*, 17> sessions_by_code_{};
  std::array<prometheus::Counter*, 2> unauthenticated_{};  // [missing, wrong]
  prometheus::Gauge* active_sessions_ = nullptr;
  prometheus::Gauge* queued_frames_ = nullptr;
  prometheus::Counter* memory_releases_ = nullptr;
};

}  // namespace nidevo::server
