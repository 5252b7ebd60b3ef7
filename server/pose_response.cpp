#include "pose_response.hpp"

#include <Eigen/Geometry>
#include <cmath>
#include <string>

namespace nidevo::server {

namespace {

v1::FrameStatus toProto(TrackingState s) {
  switch (s) {
    case TrackingState::kOk:
      return v1::FRAME_STATUS_OK;
    case TrackingState::kDegraded:
      return v1::FRAME_STATUS_DEGRADED;
    case TrackingState::kLost:
      return v1::FRAME_STATUS_LOST;
  }
  return v1::FRAME_STATUS_UNSPECIFIED;
}

v1::RotationSource toProto(RotationSource s) {
  switch (s) {
    case RotationSource::kInitial:
      return v1::ROTATION_SOURCE_INITIAL;
    case RotationSource::kPlanes:
      return v1::ROTATION_SOURCE_PLANES;
    case RotationSource::kOnePlane:
      return v1::ROTATION_SOURCE_ONE_PLANE;
    case RotationSource::kPrediction:
      return v1::ROTATION_SOURCE_PREDICTION;
  }
  return v1::ROTATION_SOURCE_UNSPECIFIED;
}

}  // namespace

std::string validateInitialPose(const v1::SessionConfig& config) {
  if (!config.has_initial_pose()) return "";
  const v1::Pose& p = config.initial_pose();
  for (double x : {p.tx(), p.ty(), p.tz(), p.qw(), p.qx(), p.qy(), p.qz()})
    if (!std::isfinite(x)) return "config.initial_pose: every value must be finite";
  const double norm = Eigen::Vector4d(p.qw(), p.qx(), p.qy(), p.qz()).norm();
  if (std::abs(norm - 1) > 1e-3)
    return "config.initial_pose: the quaternion must be unit length, its norm is " +
           std::to_string(norm);
  return "";
}

Eigen::Isometry3d initialPoseOf(const v1::SessionConfig& config) {
  Eigen::Isometry3d T = Eigen::Isometry3d::Identity();
  if (!config.has_initial_pose()) return T;
  const v1::Pose& p = config.initial_pose();
  T.linear() = Eigen::Quaterniond(p.qw(), p.qx(), p.qy(), p.qz()).normalized().toRotationMatrix();
  T.translation() = Eigen::Vector3d(p.tx(), p.ty(), p.tz());
  return T;
}

void fillPoseResponse(const v1::Frame& frame, const PoseEstimate& pose,
                      const Eigen::Isometry3d& world_from_first, v1::TrackResponse* out) {
  out->set_sequence(frame.sequence());
  out->set_timestamp(frame.timestamp());
  out->set_status(toProto(pose.state));
  out->set_reason(pose.reason);
  const Eigen::Isometry3d T_world_cam = world_from_first * pose.T_world_cam;
  const Eigen::Vector3d t = T_world_cam.translation();
  const Eigen::Quaterniond q(T_world_cam.rotation());
  auto* p = out->mutable_pose();
  p->set_tx(t.x());
  p->set_ty(t.y());
  p->set_tz(t.z());
  p->set_qw(q.w());
  p->set_qx(q.x());
  p->set_qy(q.y());
  p->set_qz(q.z());
  out->set_psr(pose.psr);
  out->set_planes_used(pose.planes_used);
  out->set_rotation_source(toProto(pose.rotation_source));
  out->set_rotation_keyframe(pose.rotation_keyframe);
  out->set_translation_keyframe(pose.translation_keyframe);
  const PoseVerification& v = pose.verification;
  if (v.hypothesis[0] != '\0') {
    auto* check = out->mutable_check();
    check->set_hypothesis(v.hypothesis);
    check->set_passed(v.passed);
    check->set_inlier_fraction(v.inlier_fraction);
    check->set_overlap_fraction(v.overlap_fraction);
    check->set_residual_rms_m(v.residual_rms_m);
    check->set_ncc(v.ncc);
    check->set_constrained_directions(v.constrained_directions);
    check->set_depth_constrained_directions(v.depth_constrained_directions);
    check->set_confirmed_directions(v.confirmed_directions);
    check->set_predicted_directions(v.predicted_directions);
    check->set_grey_depth_gap_deg(v.grey_depth_gap_deg);
    check->set_sigma_rotation_deg(v.sigma_rotation_deg);
    check->set_sigma_translation_m(v.sigma_translation_m);
  } else {
    out->clear_check();
  }
  auto* times = out->mutable_timings();
  times->set_normals(pose.times.normals_s);
  times->set_rotation(pose.times.rotation_s);
  times->set_translation(pose.times.translation_s);
}

v1::TrackResponse rejectionResponse(const v1::Frame& frame, v1::FrameStatus status,
                                    const std::string& reason) {
  v1::TrackResponse r;
  r.set_sequence(frame.sequence());
  r.set_timestamp(frame.timestamp());
  r.set_status(status);
  r.set_reason(reason);
  return r;
}

}  // namespace nidevo::server
