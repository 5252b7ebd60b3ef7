#include "odometry_stages.hpp"

#include <exception>

#include "pose_response.hpp"

namespace nidevo::server {

namespace {

double secondsBetween(Clock::time_point a, Clock::time_point b) {
  return std::chrono::duration<double>(b - a).count();
}

}  // namespace

OdometryStages::OdometryStages(std::shared_ptr<const FrameDecoder> decoder,
                               std::unique_ptr<Odometry> odometry, ServerMetrics* metrics,
                               const Eigen::Isometry3d& world_from_first)
    : decoder_(std::move(decoder)),
      odometry_(std::move(odometry)),
      metrics_(metrics),
      world_from_first_(world_from_first) {}

void OdometryStages::prepare(FrameJob* job) {
  const Clock::time_point start = Clock::now();
  job->queue_s = secondsBetween(job->arrival, start);
  // The decoded pixels (1.5 MB at VGA) are read by stage 1 only, so one image per worker thread
  // serves every session rather than one per frame in flight.
  thread_local RgbdFrame image;
  job->error = decoder_->decode(job->frame, &image);
  job->decode_s = secondsBetween(start, Clock::now());
  if (!job->error.empty()) return;
  try {
    odometry_->computeNormals(image, &job->state);
  } catch (const std::exception& e) {
    job->error = std::string("frame: ") + e.what();
  }
}

void OdometryStages::rotate(FrameJob* job) { odometry_->estimateRotation(&job->state); }

void OdometryStages::translate(FrameJob* job) {
  const PoseEstimate pose = odometry_->estimateTranslation(&job->state);
  v1::TrackResponse& response = job->response;
  fillPoseResponse(job->frame, pose, world_from_first_, &response);
  auto* t = response.mutable_timings();
  t->set_queue(job->queue_s);
  t->set_decode(job->decode_s);
  const double total = secondsBetween(job->arrival, Clock::now());
  t->set_total(total);
  observe(*job, pose, total);
}

void OdometryStages::observe(const FrameJob& job, const PoseEstimate& pose, double total_s) {
  ServerMetrics& m = *metrics_;
  m.frameLatency(total_s);
  m.stage(Stage::kQueue, job.queue_s);
  m.stage(Stage::kDecode, job.decode_s);
  m.stage(Stage::kNormals, pose.times.normals_s);
  m.stage(Stage::kRotation, pose.times.rotation_s);
  m.stage(Stage::kTranslation, pose.times.translation_s);
  if (pose.state != TrackingState::kLost) m.psr(pose.psr);
  m.poseCheck(pose.verification.hypothesis, pose.verification.passed,
              pose.verification.residual_rms_m);
  if (pose.rotation_keyframe) m.rotationKeyframe();
  if (pose.translation_keyframe) m.translationKeyframe();
}

}  // namespace nidevo::server
