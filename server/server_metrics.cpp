#include "server_metrics.hpp"

#include <grpcpp/support/status_code_enum.h>

#include <cstring>

#include "absl/status/status.h"

namespace nidevo::server {

namespace {

// Latency buckets from 0.5 ms to 1 s: a frame takes a few ms, a queued one tens of ms.
prometheus::Histogram::BucketBoundaries latencyBuckets() {
  return {0.0005, 0.001, 0.002, 0.003, 0.004, 0.005, 0.0075, 0.01, 0.015,
          0.02,   0.033, 0.05,  0.075, 0.1,   0.25,  0.5,    1.0};
}

}  // namespace

// One declaration per metric family, in the order of the README's metrics table: long, but a
// list; split, it would only be scattered.
ServerMetrics::ServerMetrics(const std::string& version)
    : registry_(std::make_shared<prometheus::Registry>()) {
  using prometheus::BuildCounter;
  using prometheus::BuildGauge;
  using prometheus::BuildHistogram;
  auto& frames = BuildCounter()
                     .Name("nidevo_frames_total")
                     .Help("Frames answered, by outcome (ok, degraded, lost, dropped, error)")
                     .Register(*registry_);
  const char* outcomes[] = {"ok", "degraded", "lost", "dropped", "error"};
  for (size_t i = 0; i < frames_.size(); ++i) frames_[i] = &frames.Add({{"outcome", outcomes[i]}});

  frame_latency_ = &BuildHistogram()
                        .Name("nidevo_frame_latency_seconds")
                        .Help(
                            "Server-side time from a frame's arrival to its answer, processed "
                            "frames only")
                        .Register(*registry_)
                        .Add({}, latencyBuckets());
  auto& stages = BuildHistogram()
                     .Name("nidevo_stage_duration_seconds")
                     .Help(
                         "Time a processed frame spent in each stage (decode, queue, normals, "
                         "rotation, translation)")
                     .Register(*registry_);
  const char* stage_names[] = {"decode", "queue", "normals", "rotation", "translation"};
  for (size_t i = 0; i < stages_.size(); ++i)
    stages_[i] = &stages.Add({{"stage", stage_names[i]}}, latencyBuckets());
  psr_ = &BuildHistogram()
              .Name("nidevo_frame_psr")
              .Help("Peak-to-sidelobe ratio of the translation match of tracked frames")
              .Register(*registry_)
              .Add({}, prometheus::Histogram::BucketBoundaries{5, 8, 10, 15, 20, 30, 50, 75, 100,
                                                               150, 200, 300});
  auto& checks = BuildCounter()
                     .Name("nidevo_pose_checks_total")
                     .Help(
                         "Pose checks of tracked frames, by the hypothesis kept (method, "
                         "prediction, last_pose, coarse_to_fine) and the verdict (passed, failed)")
                     .Register(*registry_);
  const char* hypotheses[] = {"method", "prediction", "last_pose", "coarse_to_fine"};
  for (size_t h = 0; h < checks_.size(); ++h)
    for (size_t passed = 0; passed < 2; ++passed)
      checks_[h][passed] =
          &checks.Add({{"hypothesis", hypotheses[h]}, {"result", passed ? "passed" : "failed"}});
  check_residual_ = &BuildHistogram()
                         .Name("nidevo_pose_check_residual_meters")
                         .Help("Point-to-plane RMS of the checked pose against the reference frame")
                         .Register(*registry_)
                         .Add({}, prometheus::Histogram::BucketBoundaries{
                                      0.002, 0.004, 0.006, 0.008, 0.01, 0.015, 0.02, 0.03, 0.05});
  auto& keyframes = BuildCounter()
                        .Name("nidevo_keyframes_total")
                        .Help("Keyframes made, by kind (rotation, translation)")
                        .Register(*registry_);
  rotation_keyframes_ = &keyframes.Add({{"kind", "rotation"}});
  translation_keyframes_ = &keyframes.Add({{"kind", "translation"}});
  sessions_family_ = &BuildCounter()
                          .Name("nidevo_sessions_total")
                          .Help("Sessions ended, by final gRPC status code")
                          .Register(*registry_);
  // Every code up front (17, bounded): rates start from zero and recording never adds a child.
  for (size_t code = 0; code < sessions_by_code_.size(); ++code)
    sessions_by_code_[code] = &sessions_family_->Add(
        {{"code", absl::StatusCodeToString(static_cast<absl::StatusCode>(code))}});
  auto& unauthenticated = BuildCounter()
                              .Name("nidevo_unauthenticated_calls_total")
                              .Help("Calls refused for their bearer token, by reason")
                              .Register(*registry_);
  unauthenticated_ = {&unauthenticated.Add({{"reason", "missing"}}),
                      &unauthenticated.Add({{"reason", "wrong"}})};
  active_sessions_ = &BuildGauge()
                          .Name("nidevo_active_sessions")
                          .Help("Sessions (streams) currently open")
                          .Register(*registry_)
                          .Add({});
  queued_frames_ = &BuildGauge()
                        .Name("nidevo_queued_frames")
                        .Help("Frames received and waiting for a worker, over all sessions")
                        .Register(*registry_)
                        .Add({});
  memory_releases_ = &BuildCounter()
                          .Name("nidevo_memory_releases_total")
                          .Help(
                              "Times freed heap memory went back to the system, each when the "
                              "last open session had ended")
                          .Register(*registry_)
                          .Add({});
  BuildGauge()
      .Name("nidevo_build_info")
      .Help("Always 1; the labels say which build is running")
      .Register(*registry_)
      .Add({{"version", version}, {"api", "nidevo.v1"}})
      .Set(1);
}

void ServerMetrics::poseCheck(const char* hypothesis, bool passed, double residual_rms_m) {
  size_t h = 0;
  if (std::strcmp(hypothesis, "method") == 0) {
    h = 0;
  } else if (std::strcmp(hypothesis, "prediction") == 0) {
    h = 1;
  } else if (std::strcmp(hypothesis, "last pose") == 0) {
    h = 2;
  } else if (std::strcmp(hypothesis, "prediction coarse to fine") == 0) {
    h = 3;
  } else {
    return;  // not checked (first frame, no depth)
  }
  checks_[h][passed ? 1 : 0]->Increment();
  check_residual_->Observe(residual_rms_m);
}

void ServerMetrics::sessionEnded(int code) {
  if (code < 0 || code >= int(sessions_by_code_.size())) code = grpc::StatusCode::UNKNOWN;
  sessions_by_code_[size_t(code)]->Increment();
}

}  // namespace nidevo::server
