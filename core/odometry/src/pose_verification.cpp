// The pose check of Odometry (stage 3's last step): the method's pose is a hypothesis, refined
// and verified against the reference frame's surface; the prediction is the fallback.
#include <algorithm>
#include <cmath>
#include <string_view>

#include "nidevo/odometry/odometry.hpp"
#include "nidevo/odometry/pose_check.hpp"
#include "verification_state.hpp"

namespace nidevo {

using Eigen::Isometry3d;

namespace {

PoseVerification summary(const AlignmentResult& a, const char* hypothesis, bool passed) {
  PoseVerification v;
  v.hypothesis = hypothesis;
  v.inlier_fraction = a.inlierFraction();
  v.overlap_fraction = a.overlapFraction();
  v.residual_rms_m = a.rms_m;
  v.ncc = a.ncc;
  v.constrained_directions = a.constrained;
  v.depth_constrained_directions = a.depth_constrained;
  v.confirmed_directions = a.confirmed;
  v.free_rotation = a.free_rotation;
  v.free_translation = a.free_translation;
  v.passed = passed;
  v.grey_depth_gap_deg = a.grey_depth_gap_rad * 180.0 / M_PI;
  v.grey_depth_gap_m = a.grey_depth_gap_m;
  v.sigma_rotation_deg = a.sigma_rotation_rad * 180.0 / M_PI;
  v.sigma_translation_m = a.sigma_translation_m;
  v.normal_noise_deg = std::sqrt(a.normal_noise_var) * 180.0 / M_PI;
  v.depth_eigenvalues = a.depth_eigenvalues;
  v.eigenvalues = a.eigenvalues;
  return v;
}

// Depth and grey values measured turns too far apart for the frame's pose to be called right.
bool outOfStep(const AlignmentResult& a, const OdometryConfig& c) {
  return c.verify_max_grey_depth_gap_rad > 0 &&
         a.grey_depth_gap_rad > c.verify_max_grey_depth_gap_rad;
}

// The status again with `told` as the check's result and without the method's own value vouching:
// along a direction the data cannot tell, it is all there is.
bool okWhereUntold(const AlignmentResult& told, StatusEvidence evidence, const OdometryConfig& c) {
  evidence.best = &told;
  evidence.origin.from_method = false;
  return decideStatus(evidence, c).ok;
}

}  // namespace

void Odometry::renewReference(const FrameState& s, const Isometry3d& T_out,
                              const Isometry3d& T_method) {
  VerificationState& v = *verify_;
  sampleSurface(s.normals, s.map_intensity, config_.verify_sample_step, &v.reference);
  v.T_out_ref = T_out;
  v.T_method_ref = T_method;
  v.frames_since_reference = 0;
  v.has_reference = true;
}

void Odometry::verifyPose(const FrameState& s, const Isometry3d& T_method,
                          const char* method_problem, bool translation_measured,
                          const KccRidges& ridges, PoseEstimate* out) {
  VerificationState& v = *verify_;
  out->state = TrackingState::kOk;
  out->reason = "";
  if (!s.depth_ok) {
    reportLostWithoutDepth(s, T_method, method_problem, out);
    return;
  }
  if (!v.has_reference) {
    out->T_world_cam = T_method;
    renewReference(s, T_method, T_method);
    v.motion.update(T_method, true, s.timestamp);
    // The session's first pose defines the world and is right by definition; after frames
    // without depth it is the last answer's, and the motion since was never measured.
    v.previous_without_depth = false;
    if (v.answered_without_reference) {
      out->state = TrackingState::kDegraded;
      out->reason =
          "the first frame with depth after frames without it: the motion since the last pose "
          "is not measured";
      ++v.degraded_frames;
    }
    return;
  }
  const CheckedPose checked = checkHypotheses(s, T_method, method_problem, translation_measured);
  out->T_world_cam = v.T_out_ref * checked.best.T_ref_cur;
  out->verification = summary(checked.best, checked.hypothesis, checked.verdict.passed);
  StatusEvidence evidence;
  evidence.best = &checked.best;
  evidence.verdict = checked.verdict;
  evidence.choice = checked.choice;
  evidence.origin = checked.origin;
  evidence.T_ref_predicted = checked.T_ref_predicted;
  evidence.ridges = ridges;
  evidence.prediction_reliable = v.prediction.reliable(config_);
  evidence.method_problem = method_problem;
  const StatusDecision status = decideStatus(evidence, config_);
  out->verification.predicted_directions = status.predicted_directions;
  if (!status.ok) {
    out->state = TrackingState::kDegraded;
    out->reason = status.reason;
  }
  LateEvidence late;
  late.weak_direction_untold =
      status.ok && !status.predicted_directions && weakDirectionUntold(checked, evidence);
  late.grey_fixed_untold = status.ok && !status.predicted_directions &&
                           !late.weak_direction_untold && greyFixedUntold(checked, evidence);
  if (out->state == TrackingState::kDegraded && ++v.degraded_frames > config_.max_degraded_frames)
    out->state = TrackingState::kLost;
  if (out->state == TrackingState::kOk) v.degraded_frames = 0;
  if (out->state == TrackingState::kLost) v.recovering = true;
  // A settled tie is refined as it would be unsettled, so that the status rule changes no pose.
  if (out->state != TrackingState::kOk || status.tie_settled) refineUnverified(checked, out);
  updateMotion(s, checked, T_method, out);
  applyLateStatusRules(checked, late, out);
}

bool Odometry::weakDirectionUntold(const CheckedPose& c, const StatusEvidence& evidence) {
  VerificationState& v = *verify_;
  if (c.best.weak_count == 0 || c.best.depth_constrained == 6 || config_.align_confirm_shift_m <= 0)
    return false;
  const DepthAligner::Untold untold =
      v.aligner.untoldWeakDirections(v.reference, v.target, v.map_camera, c.best, v.params);
  if (untold.directions == 0) return false;
  // Without the confirmations the data cannot tell apart.
  AlignmentResult told = c.best;
  told.confirmed -= untold.confirmed;
  return !okWhereUntold(told, evidence, config_);
}

bool Odometry::greyFixedUntold(const CheckedPose& c, const StatusEvidence& evidence) {
  VerificationState& v = *verify_;
  if (!config_.verify_grey_fixed_told || config_.align_confirm_shift_m <= 0) return false;
  Eigen::Matrix<double, 6, 1> axis;
  if (!v.aligner.greyFixedDirectionUntold(v.reference, v.target, v.map_camera, c.best, v.params,
                                          &axis))
    return false;
  // With that direction free.
  AlignmentResult told = c.best;
  --told.constrained;
  (axis.head<3>().squaredNorm() > 0.5 ? told.free_rotation : told.free_translation) = true;
  return !okWhereUntold(told, evidence, config_);
}

void Odometry::reportLostWithoutDepth(const FrameState& s, const Isometry3d& T_method,
                                      const char* method_problem, PoseEstimate* out) {
  VerificationState& v = *verify_;
  out->T_world_cam = v.has_reference ? v.motion.predict(s.timestamp) : T_method;
  out->state = TrackingState::kLost;
  out->reason = method_problem;
  ++v.degraded_frames;
  v.motion.update(out->T_world_cam, false, s.timestamp);
  v.prediction.unverified();
  v.recovering = true;
  v.previous_out_of_step = false;
  if (!v.has_reference) v.answered_without_reference = true;
  v.previous_without_depth = true;
}

Odometry::CheckedPose Odometry::checkHypotheses(const FrameState& s, const Isometry3d& T_method,
                                                const char* method_problem,
                                                bool translation_measured) {
  VerificationState& v = *verify_;
  // Hypotheses in the reference's frame, the method's first: on the common path it passes and
  // the others are never tried.
  const Isometry3d hypotheses[] = {v.T_method_ref.inverse() * T_method,
                                   v.T_out_ref.inverse() * v.motion.predict(s.timestamp),
                                   v.T_out_ref.inverse() * v.motion.last()};
  const char* const names[] = {"method", "prediction", "last pose", "prediction coarse to fine"};
  constexpr int kHypotheses = 4;
  const Isometry3d& predicted = hypotheses[1];
  AlignmentResult results[kHypotheses];
  CheckVerdict verdicts[kHypotheses];
  int tried = 0;
  // A later hypothesis that reaches a passing one's pose ends there (AlignmentParams::join_m).
  const AlignmentResult* passed[kHypotheses];
  int passed_count = 0;
  buildAlignmentTarget(s.normals, s.map_intensity, &v.target);
  for (int h = 0; h < 3; ++h) {
    results[h] = v.aligner.align(v.reference, v.target, v.map_camera, hypotheses[h], v.params,
                                 passed, passed_count);
    verdicts[h] = judgeAlignment(results[h], config_);
    if (verdicts[h].passed) passed[passed_count++] = &results[h];
    tried = h + 1;
    // The common path: the method's pose passes, unhurt, near the prediction.
    if (h == 0 && verdicts[0].passed && method_problem == nullptr &&
        !farApart(results[0].T_ref_cur, predicted, config_))
      break;
  }
  // None passed: the motion may have left every hypothesis outside the data's basin.
  if (tried == 3 && !verdicts[0].passed && !verdicts[1].passed && !verdicts[2].passed &&
      !v.coarse.level.empty()) {
    v.coarse.build(v.target);
    results[3] = v.aligner.alignCoarseToFine(v.reference, v.target, v.map_camera, v.coarse,
                                             predicted, v.params);
    verdicts[3] = judgeAlignment(results[3], config_);
    tried = 4;
  }
  const bool rotation_measured = s.rotation_source == RotationSource::kPlanes;
  HypothesisOrigin origins[kHypotheses];
  for (int h = 0; h < tried; ++h) origins[h] = {h == 0, rotation_measured, translation_measured};
  CheckedPose c;
  c.choice = chooseHypothesis(results, verdicts, origins, tried, predicted, config_);
  c.best = results[c.choice.index];
  c.verdict = verdicts[c.choice.index];
  c.hypothesis = names[c.choice.index];
  c.T_ref_predicted = predicted;
  c.tie_beyond_ok_bounds = tieBeyondOkBounds(results, verdicts, tried, c.choice.index, config_);
  if (c.best.overlapFraction() < config_.verify_min_overlap) {
    // No hypothesis keeps the reference in view (a fast turn away from it): the check measured
    // nothing, and the method's pose, from its own keyframes, is the better guess than an
    // extrapolation, where its rotation was measured (two planes) or agrees with the prediction:
    // one plane's correction of the prediction can pair two different planes (a fit through a
    // strip of points) and turn the camera by the angle between them. Unverified, it is not OK.
    const bool keep_method = !config_.unseen_reference_needs_measured_rotation ||
                             rotation_measured || !farApart(hypotheses[0], predicted, config_);
    const int guess = keep_method ? 0 : 1;
    c.best.T_ref_cur = hypotheses[guess];
    c.hypothesis = names[guess];
  }
  c.origin = {c.hypothesis == names[0], rotation_measured, translation_measured};
  return c;
}

void Odometry::refineUnverified(const CheckedPose& c, PoseEstimate* out) {
  VerificationState& v = *verify_;
  if (c.best.overlapFraction() < config_.verify_min_overlap) return;
  // A pose already reported unverified may still be bettered along what it leaves free: the
  // status stays, the pose and so the next prediction improve, and the figures are the pose's.
  const AlignmentResult refined =
      v.aligner.refineAlongWeakDirections(v.reference, v.target, v.map_camera, c.best, v.params);
  if (refined.T_ref_cur.matrix() == c.best.T_ref_cur.matrix()) return;
  out->T_world_cam = v.T_out_ref * refined.T_ref_cur;
  const bool predicted_directions = out->verification.predicted_directions;
  out->verification = summary(refined, c.hypothesis, judgeAlignment(refined, config_).passed);
  out->verification.predicted_directions = predicted_directions;
}

void Odometry::updateMotion(const FrameState& s, const CheckedPose& c, const Isometry3d& T_method,
                            const PoseEstimate* out) {
  VerificationState& v = *verify_;
  // Only a pose the data fixed measures the motion; one that took the prediction's value would
  // confirm the prediction by itself.
  const bool verified = out->state == TrackingState::kOk && !out->verification.predicted_directions;
  if (verified)
    v.prediction.verified(c.T_ref_predicted, c.best.T_ref_cur);
  else
    v.prediction.unverified();
  // Yet a pose refined from the prediction that passed measured the directions depth fixed, and
  // holds the prediction's value (or the grey values') along the rest: without it the velocity
  // would decay to standing still over a stretch the data say is a turn. Whatever its status,
  // so that the status rules never change a pose.
  const bool measured_from_prediction =
      std::string_view(c.hypothesis).rfind("prediction", 0) == 0 && out->verification.passed &&
      out->verification.depth_constrained_directions >= config_.unverified_motion_min_directions;
  v.motion.update(out->T_world_cam, verified || measured_from_prediction, s.timestamp);
  // A frame not verified renews the reference, so that the next frames are checked against what
  // is in view: a stale reference would leave every later frame unverifiable.
  if (!verified || c.best.overlapFraction() < config_.reference_min_overlap ||
      ++v.frames_since_reference >= config_.reference_max_frames) {
    renewReference(s, out->T_world_cam, T_method);
  }
}

void Odometry::applyLateStatusRules(const CheckedPose& c, const LateEvidence& late,
                                    PoseEstimate* out) {
  VerificationState& v = *verify_;
  // Each rule only demotes an OK frame, keeping the first reason that applied.
  const auto demoteWhen = [out](bool rule_applies, const char* reason) {
    if (out->state != TrackingState::kOk || !rule_applies) return;
    out->state = TrackingState::kDegraded;
    out->reason = reason;
  };
  // Last, so that it changes no pose: the pose stands as the best fit of both sensors, which
  // measured motions too far apart for it to be called right.
  const bool out_of_step = outOfStep(c.best, config_);
  demoteWhen(out_of_step,
             "depth and grey values disagree on the rotation (colour and depth out of step, "
             "motion blur?)");
  // Likewise: the last frame's own sensors did not agree on its pose, so the motion since it,
  // what a frame-to-frame error and a client's velocity read, carries that pose's error whatever
  // this frame's check says (docs/accuracy.md, "The real clip played backwards, and the frame
  // after one out of step").
  demoteWhen(
      v.previous_out_of_step,
      "the last frame's depth and grey values disagreed on the rotation: the motion since it "
      "is not verified");
  v.previous_out_of_step = out_of_step;
  // Likewise after a frame without depth: this pose is checked against the reference, but the
  // last answer was only predicted, and the motion since it corrects that prediction.
  demoteWhen(v.previous_without_depth,
             "the last frame had no depth (its pose was predicted): the motion since it is not "
             "measured");
  v.previous_without_depth = false;
  // Likewise: OK rested on a direction the check did not fix (confirmed by a small would-be step,
  // or the method's value), yet the grey values fit the pose moved a silent failure's distance
  // along it as well.
  demoteWhen(late.weak_direction_untold,
             "a direction the check did not fix: the grey values fit the pose moved along it "
             "(align_confirm_shift_m) as well");
  // Likewise: a direction only the grey values fixed, that they cannot tell from the pose moved
  // along it with the rest fitted again (stripes along themselves).
  demoteWhen(late.grey_fixed_untold,
             "a direction only the grey values fixed: they fit the pose moved along it "
             "(align_confirm_shift_m) as well");
  // Likewise: another start ended as good a fit further away than OK allows.
  demoteWhen(config_.ok_needs_hypotheses_to_agree && c.tie_beyond_ok_bounds,
             "two hypotheses fit alike yet ended further apart than OK allows: the data do not fix "
             "the pose that closely");
  // Likewise: the check's own spread, from the sensor noise alone, reaches beyond what OK promises.
  const double k = config_.verify_max_spread_sigmas;
  demoteWhen(k > 0 && (k * out->verification.sigma_rotation_deg * M_PI / 180 >
                           config_.prediction_trust_rad ||
                       k * out->verification.sigma_translation_m > config_.prediction_trust_m),
             "the pose's spread from the sensor noise is wider than OK allows");
  // Likewise: at the start no motion has been measured yet, so "near the prediction" is near
  // standing still, an assumption; a pose that rests on it along what depth leaves free is not
  // verified (a sequence that starts fast over one plane).
  const bool independent = c.origin.from_method || c.best.depth_constrained == 6;
  demoteWhen(
      !v.motion_measured && !independent && config_.start_requires_measured_motion,
      "the start: no motion measured yet, and depth leaves a direction to the assumption that "
      "the camera stands still");
  // Likewise last: back from LOST, the check's minimum was found from hypotheses the lost stretch
  // left far off, where a wrong minimum can fit both sensors; until the prediction has been right
  // again, only depth fixing every direction says the pose is right.
  if (v.recovering && v.prediction.reliable(config_)) v.recovering = false;
  demoteWhen(
      v.recovering && c.best.depth_constrained < config_.recovery_min_depth_directions,
      "recovering from LOST: depth leaves a direction free and the motion prediction has not "
      "been right again yet");
  if (out->state == TrackingState::kOk && independent) v.motion_measured = true;
}

}  // namespace nidevo
