#include "nidevo/cli/odometry_flags.hpp"

#include <charconv>
#include <cstdlib>
#include <stdexcept>
#include <string>

#include "absl/flags/flag.h"
#include "nidevo/cli/cli.hpp"

namespace {
const nidevo::OdometryConfig kDefaults;

// A float default as the shortest decimal that reads back to the same float, so that --help
// shows 0.0003 rather than 0.00030000001424923539 (the double nearest the float).
double shortestDecimal(float value) {
  char text[32];
  const auto end = std::to_chars(text, text + sizeof text, value).ptr;
  return std::strtod(std::string(text, end).c_str(), nullptr);
}
}  // namespace

NIDEVO_FLAG_HEADING("Odometry (METHOD.md; defaults are OdometryConfig's)");
ABSL_FLAG(int, cell_size, kDefaults.cell_size, "Normal-map box filter side (paper Table 3)");
ABSL_FLAG(int, normal_stride, kDefaults.normal_stride,
          "Normal map at 1/stride of the input resolution (1 = full, 2 = half)");
ABSL_FLAG(std::string, rotation_method, nidevo::toString(kDefaults.rotation_method),
          "best_pair (paper) or closed_form (SVD over all planes)");
ABSL_FLAG(std::string, plane_normal, nidevo::toString(kDefaults.plane_normal),
          "Plane normal per frame: median (paper) or fit (least-squares plane through the points)");
ABSL_FLAG(double, min_plane_fraction, shortestDecimal(kDefaults.min_plane_fraction),
          "Smallest plane, as a fraction of the normal map's pixels");
ABSL_FLAG(int, plane_pixel_step, kDefaults.plane_pixel_step,
          "Plane tracking reads every n-th normal-map pixel in u and v (1: all, as the paper)");
ABSL_FLAG(int, projection_width, kDefaults.projection_width, "Orthographic projection width");
ABSL_FLAG(int, projection_height, kDefaults.projection_height, "Orthographic projection height");
ABSL_FLAG(int, projection_stride, kDefaults.projection_stride,
          "Project every n-th input pixel in u and v");
ABSL_FLAG(bool, fft_measure, kDefaults.fft_measure,
          "Time FFTW plans (FFTW_MEASURE): poses then differ in the last bits between runs");
ABSL_FLAG(bool, kcc_depth, kDefaults.kcc_use_depth, "Correlate depth as a second KCC channel");
ABSL_FLAG(double, kcc_label_sigma, shortestDecimal(kDefaults.kcc_label_sigma),
          "KCC label: 0 = delta (authors), else a Gaussian of this many pixels");
ABSL_FLAG(bool, flatten_outline, kDefaults.projection_flatten_outline,
          "Empty projection cells take the mean grey instead of 0.5 (authors), and contrast fades "
          "towards the image border");
ABSL_FLAG(double, border_fade, shortestDecimal(kDefaults.projection_border_fade),
          "Width of that fade as a fraction of the image width");
ABSL_FLAG(int, fill_gap, kDefaults.projection_fill_gap,
          "Fill projection holes of up to this many cells within one surface (0: off)");
ABSL_FLAG(bool, subpixel, kDefaults.subpixel_peak, "Sub-pixel refinement of the KCC peak");
ABSL_FLAG(int, rotation_keyframe_interval, kDefaults.rotation_keyframe_interval,
          "Renew the rotation keyframe at least every this many frames");
ABSL_FLAG(double, psr_bound, shortestDecimal(kDefaults.psr_bound),
          "Translation keyframe renewed at or below this PSR (paper: 50)");
ABSL_FLAG(bool, one_plane_image_yaw, kDefaults.one_plane_image_yaw,
          "With one plane, measure the turn about its normal from the grey gradients' directions "
          "on it (false: the prediction's)");
ABSL_FLAG(double, plane_yaw_min_ncc, shortestDecimal(kDefaults.plane_yaw_min_ncc),
          "... accepted where the two frames' direction histograms correlate at least this well");
ABSL_FLAG(int, plane_yaw_smooth_radius, kDefaults.plane_yaw_smooth_radius,
          "... on grey values smoothed by a binomial of this radius (map pixels, 0..7)");
ABSL_FLAG(double, plane_yaw_max_footprint, shortestDecimal(kDefaults.plane_yaw_max_footprint_m),
          "... leaving out map pixels that see more of the plane than this (m)");
ABSL_FLAG(double, plane_yaw_min_turn_deg,
          shortestDecimal(float(kDefaults.plane_yaw_min_turn_rad * 180 / M_PI)),
          "... and taken only when it turns at least this far from the prediction (degrees)");
ABSL_FLAG(double, plane_yaw_max_turn_deg,
          shortestDecimal(float(kDefaults.plane_yaw_max_turn_rad * 180 / M_PI)),
          "... searched this far either way (degrees)");
ABSL_FLAG(bool, predicted_association, kDefaults.predicted_association,
          "Plane association through the predicted rotation (false: the same pixel, as the paper)");
ABSL_FLAG(double, kcc_prior_ratio, shortestDecimal(kDefaults.kcc_prior_ratio),
          "KCC maxima of at least this fraction of the highest compete; the one nearest the "
          "predicted shift wins (1: the highest only)");

ABSL_FLAG(bool, prediction_settles_ties, kDefaults.prediction_settles_ties,
          "A periodic pattern's tie settled by a motion prediction right on recent frames is OK");
ABSL_FLAG(bool, ok_needs_hypotheses_to_agree, kDefaults.ok_needs_hypotheses_to_agree,
          "A frame where another hypothesis fit alike yet ended further away than OK allows "
          "(--prediction_trust_*) is DEGRADED, its pose unchanged");
ABSL_FLAG(bool, start_requires_measured_motion, kDefaults.start_requires_measured_motion,
          "Until a frame measured the motion without the prediction, a pose resting on it is not "
          "OK");
ABSL_FLAG(bool, unseen_reference_needs_measured_rotation,
          kDefaults.unseen_reference_needs_measured_rotation,
          "With the reference out of view of every hypothesis, the method's pose is kept only if "
          "two planes measured its rotation or it agrees with the prediction (else the "
          "prediction's)");
ABSL_FLAG(bool, grey_fixed_needs_ncc, kDefaults.grey_fixed_needs_ncc,
          "A direction only the grey values fixed counts as fixed only when their NCC with the "
          "pose is at least --verify_min_ncc");
ABSL_FLAG(int, recovery_min_depth_directions, kDefaults.recovery_min_depth_directions,
          "After a LOST frame, until the prediction is right again, OK needs depth to fix this "
          "many of the 6 directions (0: never)");
ABSL_FLAG(int, kcc_ridge_cells, kDefaults.kcc_ridge_cells,
          "KCC ridge test: distance from the peak, in projection cells");
ABSL_FLAG(double, kcc_ridge_ratio, shortestDecimal(kDefaults.kcc_ridge_ratio),
          "A KCC response still at this fraction of its peak --kcc_ridge_cells away along an "
          "axis did not measure the translation along it (0: never)");

ABSL_FLAG(int, align_iterations, kDefaults.align_iterations,
          "Pose check: refinement steps on the constrained directions (0: the method's pose is "
          "only checked)");
ABSL_FLAG(double, align_converged, shortestDecimal(kDefaults.align_converged_m),
          "Pose check: a refinement step moving the surface less than this (m) ends it");
ABSL_FLAG(double, align_join, shortestDecimal(kDefaults.align_join_m),
          "Pose check: a fallback hypothesis whose refinement comes within this (m) of one that "
          "passed ends there with its result (0: each refined to its end)");
ABSL_FLAG(double, align_min_eigenvalue, shortestDecimal(kDefaults.align_min_eigenvalue),
          "Directions the geometry constrains less than this keep the hypothesis' value");
ABSL_FLAG(double, align_photometric_weight, shortestDecimal(kDefaults.align_photometric_weight),
          "Grey-value residuals in the refinement, metres per grey unit (0: depth only)");
ABSL_FLAG(double, align_step_eigenvalue, shortestDecimal(kDefaults.align_step_eigenvalue),
          "A DEGRADED or LOST pose is refined once more along weaker directions of at least "
          "this eigenvalue; the status stays (0: never)");
ABSL_FLAG(double, align_step_inlier_slack, shortestDecimal(kDefaults.align_step_inlier_slack),
          "That refinement is kept only if it loses at most this fraction of the inliers");
ABSL_FLAG(double, align_confirm_eigenvalue, shortestDecimal(kDefaults.align_confirm_eigenvalue),
          "A weaker direction of at least this eigenvalue confirms the hypothesis when its step "
          "stays within --align_confirm_step (0: never)");
ABSL_FLAG(double, align_confirm_shift, shortestDecimal(kDefaults.align_confirm_shift_m),
          "An OK frame resting on a weak direction's value (confirmed, or the method's) along "
          "which the grey values agree no worse with the pose moved this far either way is "
          "DEGRADED (m; 0: never)");
ABSL_FLAG(bool, verify_grey_fixed_told, kDefaults.verify_grey_fixed_told,
          "An OK frame where grey values fixed what depth left weak is DEGRADED when they fit the "
          "pose moved --align_confirm_shift along the direction they fix least as well (off by "
          "default: docs/accuracy.md)");
ABSL_FLAG(double, verify_max_spread_sigmas, shortestDecimal(kDefaults.verify_max_spread_sigmas),
          "An OK frame whose spread times this exceeds the accuracy asked of OK frames "
          "(--prediction_trust_*) is DEGRADED (0: never)");
ABSL_FLAG(double, align_confirm_step, shortestDecimal(kDefaults.align_confirm_step_m),
          "Largest would-be step along a weak direction that confirms the hypothesis (m)");
ABSL_FLAG(int, align_polish_iterations, kDefaults.align_polish_iterations,
          "Grey-value refinement steps after depth alone fixed all six directions (0: none)");
ABSL_FLAG(int, align_coarse_levels, kDefaults.align_coarse_levels,
          "When no hypothesis passes the pose check, the prediction aligned coarse to fine from "
          "the frame halved this many times (0: never)");
ABSL_FLAG(double, align_coarse_gate_growth, shortestDecimal(kDefaults.align_coarse_gate_growth),
          "Coarse to fine: the association gate on a level halved k times is "
          "--align_max_distance times this to the power k (1: the same on every level)");
ABSL_FLAG(int, verify_sample_step, kDefaults.verify_sample_step,
          "Check every n-th smooth normal-map pixel of the reference");
ABSL_FLAG(double, verify_min_inliers, shortestDecimal(kDefaults.verify_min_inliers),
          "Fraction of the checked points that must agree for OK");
ABSL_FLAG(double, verify_max_rms, shortestDecimal(kDefaults.verify_max_rms_m),
          "Largest point-to-plane RMS (m) for OK");
ABSL_FLAG(double, verify_min_ncc, shortestDecimal(kDefaults.verify_min_ncc),
          "Smallest grey-value correlation for OK, where the reference has texture");
ABSL_FLAG(double, verify_max_grey_depth_gap_deg,
          shortestDecimal(float(kDefaults.verify_max_grey_depth_gap_rad * 180 / M_PI)),
          "DEGRADED (pose unchanged) when the poses depth alone and grey values alone fit best "
          "are this far apart in rotation (deg; 0: never)");
ABSL_FLAG(double, reference_min_overlap, shortestDecimal(kDefaults.reference_min_overlap),
          "Renew the reference frame when less of it is in view");
ABSL_FLAG(int, reference_max_frames, kDefaults.reference_max_frames,
          "Renew the reference frame at least every this many frames");
ABSL_FLAG(
    int, prediction_trust_frames, kDefaults.prediction_trust_frames,
    "A direction the data leave free may take the motion prediction's value, and the frame "
    "be OK, when the prediction's RMS error over this many recent verified frames is within "
    "--prediction_trust_deg and --prediction_trust_m, and the pose as close to it (0: never)");
ABSL_FLAG(int, unverified_motion_min_directions, kDefaults.unverified_motion_min_directions,
          "A pose not verified that passed the check from the prediction with at least this many "
          "of 6 directions fixed by depth updates the motion model's velocity (7: never)");
ABSL_FLAG(int, prediction_trust_gap, kDefaults.prediction_trust_gap,
          "... the latest of those frames at most this many frames back");
ABSL_FLAG(double, prediction_trust_deg,
          shortestDecimal(float(kDefaults.prediction_trust_rad * 180 / M_PI)),
          "... rotation bound (deg)");
ABSL_FLAG(double, prediction_trust_m, shortestDecimal(kDefaults.prediction_trust_m),
          "... translation bound (m)");

namespace nidevo::cli {

OdometryConfig odometryConfigFromFlags() {
  OdometryConfig c;
  c.cell_size = absl::GetFlag(FLAGS_cell_size);
  c.normal_stride = absl::GetFlag(FLAGS_normal_stride);
  c.rotation_method = parseRotationMethod(absl::GetFlag(FLAGS_rotation_method));
  c.plane_normal = nidevo::parsePlaneNormalEstimator(absl::GetFlag(FLAGS_plane_normal));
  c.min_plane_fraction = float(absl::GetFlag(FLAGS_min_plane_fraction));
  c.plane_pixel_step = absl::GetFlag(FLAGS_plane_pixel_step);
  c.projection_width = absl::GetFlag(FLAGS_projection_width);
  c.projection_height = absl::GetFlag(FLAGS_projection_height);
  c.projection_stride = absl::GetFlag(FLAGS_projection_stride);
  c.kcc_use_depth = absl::GetFlag(FLAGS_kcc_depth);
  c.fft_measure = absl::GetFlag(FLAGS_fft_measure);
  c.kcc_label_sigma = float(absl::GetFlag(FLAGS_kcc_label_sigma));
  c.projection_flatten_outline = absl::GetFlag(FLAGS_flatten_outline);
  c.projection_border_fade = float(absl::GetFlag(FLAGS_border_fade));
  c.projection_fill_gap = absl::GetFlag(FLAGS_fill_gap);
  c.subpixel_peak = absl::GetFlag(FLAGS_subpixel);
  c.rotation_keyframe_interval = absl::GetFlag(FLAGS_rotation_keyframe_interval);
  c.psr_bound = float(absl::GetFlag(FLAGS_psr_bound));
  c.kcc_prior_ratio = float(absl::GetFlag(FLAGS_kcc_prior_ratio));
  c.prediction_settles_ties = absl::GetFlag(FLAGS_prediction_settles_ties);
  c.ok_needs_hypotheses_to_agree = absl::GetFlag(FLAGS_ok_needs_hypotheses_to_agree);
  c.start_requires_measured_motion = absl::GetFlag(FLAGS_start_requires_measured_motion);
  c.grey_fixed_needs_ncc = absl::GetFlag(FLAGS_grey_fixed_needs_ncc);
  c.unseen_reference_needs_measured_rotation =
      absl::GetFlag(FLAGS_unseen_reference_needs_measured_rotation);
  c.recovery_min_depth_directions = absl::GetFlag(FLAGS_recovery_min_depth_directions);
  c.kcc_ridge_cells = absl::GetFlag(FLAGS_kcc_ridge_cells);
  c.kcc_ridge_ratio = float(absl::GetFlag(FLAGS_kcc_ridge_ratio));
  c.predicted_association = absl::GetFlag(FLAGS_predicted_association);
  c.one_plane_image_yaw = absl::GetFlag(FLAGS_one_plane_image_yaw);
  c.plane_yaw_min_ncc = float(absl::GetFlag(FLAGS_plane_yaw_min_ncc));
  c.plane_yaw_smooth_radius = absl::GetFlag(FLAGS_plane_yaw_smooth_radius);
  c.plane_yaw_max_footprint_m = float(absl::GetFlag(FLAGS_plane_yaw_max_footprint));
  c.plane_yaw_max_turn_rad = float(absl::GetFlag(FLAGS_plane_yaw_max_turn_deg) * M_PI / 180);
  c.plane_yaw_min_turn_rad = float(absl::GetFlag(FLAGS_plane_yaw_min_turn_deg) * M_PI / 180);
  c.align_iterations = absl::GetFlag(FLAGS_align_iterations);
  c.align_converged_m = float(absl::GetFlag(FLAGS_align_converged));
  c.align_join_m = float(absl::GetFlag(FLAGS_align_join));
  c.align_min_eigenvalue = float(absl::GetFlag(FLAGS_align_min_eigenvalue));
  c.align_step_eigenvalue = float(absl::GetFlag(FLAGS_align_step_eigenvalue));
  c.align_step_inlier_slack = float(absl::GetFlag(FLAGS_align_step_inlier_slack));
  c.align_photometric_weight = float(absl::GetFlag(FLAGS_align_photometric_weight));
  c.align_polish_iterations = absl::GetFlag(FLAGS_align_polish_iterations);
  c.align_coarse_levels = absl::GetFlag(FLAGS_align_coarse_levels);
  c.align_coarse_gate_growth = float(absl::GetFlag(FLAGS_align_coarse_gate_growth));
  c.align_confirm_eigenvalue = float(absl::GetFlag(FLAGS_align_confirm_eigenvalue));
  c.align_confirm_step_m = float(absl::GetFlag(FLAGS_align_confirm_step));
  c.align_confirm_shift_m = float(absl::GetFlag(FLAGS_align_confirm_shift));
  c.verify_max_spread_sigmas = float(absl::GetFlag(FLAGS_verify_max_spread_sigmas));
  c.verify_grey_fixed_told = absl::GetFlag(FLAGS_verify_grey_fixed_told);
  c.verify_sample_step = absl::GetFlag(FLAGS_verify_sample_step);
  c.verify_min_inliers = float(absl::GetFlag(FLAGS_verify_min_inliers));
  c.verify_max_rms_m = float(absl::GetFlag(FLAGS_verify_max_rms));
  c.verify_min_ncc = float(absl::GetFlag(FLAGS_verify_min_ncc));
  c.verify_max_grey_depth_gap_rad =
      float(absl::GetFlag(FLAGS_verify_max_grey_depth_gap_deg) * M_PI / 180);
  c.reference_min_overlap = float(absl::GetFlag(FLAGS_reference_min_overlap));
  c.reference_max_frames = absl::GetFlag(FLAGS_reference_max_frames);
  c.prediction_trust_frames = absl::GetFlag(FLAGS_prediction_trust_frames);
  c.prediction_trust_gap = absl::GetFlag(FLAGS_prediction_trust_gap);
  c.prediction_trust_rad = float(absl::GetFlag(FLAGS_prediction_trust_deg) * M_PI / 180);
  c.prediction_trust_m = float(absl::GetFlag(FLAGS_prediction_trust_m));
  c.unverified_motion_min_directions = absl::GetFlag(FLAGS_unverified_motion_min_directions);
  if (auto e = c.validate(); !e.empty()) throw std::invalid_argument(e);
  return c;
}

}  // namespace nidevo::cli
