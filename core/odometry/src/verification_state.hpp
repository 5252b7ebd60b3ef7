#pragma once
// Odometry's private state for the pose check: the reference frame's surface sample and poses.
#include "nidevo/odometry/depth_alignment.hpp"
#include "nidevo/odometry/motion_model.hpp"
#include "nidevo/odometry/odometry.hpp"
#include "nidevo/odometry/pose_check.hpp"

namespace nidevo {

struct Odometry::VerificationState {
  VerificationState(const OdometryConfig& c, const Camera& camera)
      : params(alignmentParams(c)), map_camera(camera.subsampled(c.normal_stride)) {
    // At most every step-th map pixel in u and v, so that no later frame grows a buffer.
    const size_t step = size_t(c.verify_sample_step);
    const size_t most = ((size_t(camera.width / c.normal_stride) + step - 1) / step) *
                        ((size_t(camera.height / c.normal_stride) + step - 1) / step);
    reference.point.reserve(most);
    reference.normal.reserve(most);
    reference.intensity.reserve(most);
    aligner.reserve(most);
    coarse.reserve(c.align_coarse_levels, map_camera);
  }
  const AlignmentParams params;
  const Camera map_camera;
  bool has_reference = false;
  SurfaceSample reference;
  Eigen::Isometry3d T_out_ref = Eigen::Isometry3d::Identity();     // as reported
  Eigen::Isometry3d T_method_ref = Eigen::Isometry3d::Identity();  // the method's own chain
  int frames_since_reference = 0;
  int degraded_frames = 0;  // consecutive; LOST beyond max_degraded_frames
  bool recovering = false;  // a frame was LOST, and the prediction not yet reliable since
  // The last frame's depth and grey values disagreed on the rotation (the grey-depth gap rule):
  // its pose is off by up to that gap, and so is the motion of the next frame since it.
  bool previous_out_of_step = false;
  // An OK frame has measured the motion without the prediction's help (depth fixed every
  // direction, or the method's own pose was kept): before that, the prediction is only the
  // assumption that the camera stands still.
  bool motion_measured = false;
  // A frame before the first with depth was answered (LOST, predicted): the first with depth
  // then becomes the reference without anything to check the motion since that answer by.
  bool answered_without_reference = false;
  // The last frame had no depth: its pose was the prediction's, so the motion since it, what a
  // frame-to-frame error and a client's velocity read, carries that prediction's error.
  bool previous_without_depth = false;
  MotionModel motion;  // of the reported poses; measured: verified
  PredictionRecord prediction;
  DepthAligner aligner;
  AlignmentTarget target;   // the current frame, shared by the hypotheses
  AlignmentPyramid coarse;  // of target: built only when no hypothesis passed
};

// The hypothesis the check chose for a frame, in the reference's frame, and how it fared.
struct Odometry::CheckedPose {
  AlignmentResult best;
  CheckVerdict verdict;
  HypothesisChoice choice;
  HypothesisOrigin origin;
  // which: "method", "prediction", "last pose" or "prediction coarse to fine"
  const char* hypothesis = "method";
  Eigen::Isometry3d T_ref_predicted = Eigen::Isometry3d::Identity();
  bool tie_beyond_ok_bounds = false;  // tieBeyondOkBounds among the hypotheses tried
};

}  // namespace nidevo
