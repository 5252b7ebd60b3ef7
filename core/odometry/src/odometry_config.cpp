#include "nidevo/odometry/odometry_config.hpp"

#include <algorithm>
#include <cmath>
#include <stdexcept>

namespace nidevo {

RotationMethod parseRotationMethod(const std::string& name) {
  if (name == "best_pair") return RotationMethod::kBestPair;
  if (name == "closed_form") return RotationMethod::kClosedForm;
  throw std::invalid_argument("unknown rotation method '" + name + "' (best_pair, closed_form)");
}

const char* toString(RotationMethod m) {
  return m == RotationMethod::kBestPair ? "best_pair" : "closed_form";
}

std::string OdometryConfig::validate() const {
  auto in = [](double v, double lo, double hi) { return std::isfinite(v) && v >= lo && v <= hi; };
  if (normal_stride < 1 || normal_stride > 4) return "normal_stride must be in 1..4";
  if (cell_size < 1 || cell_size > 64) return "cell_size must be in 1..64";
  if (!in(depth_discontinuity, 1e-4, 1)) return "depth_discontinuity must be in [1e-4, 1]";
  if (!in(min_depth_m, 0, 100) || !in(max_depth_m, 0, 1000) || min_depth_m >= max_depth_m)
    return "min_depth_m must be below max_depth_m";
  if (border_px < 0 || border_px > 200) return "border_px must be in 0..200";
  if (!in(overlap_dot, 0, 1)) return "overlap_dot must be in [0, 1]";
  if (!in(crease_dot, 0, 1)) return "crease_dot must be in [0, 1]";
  if (!in(mode_dot, 0, 1)) return "mode_dot must be in [0, 1]";
  if (!in(min_plane_fraction, 1e-4, 1)) return "min_plane_fraction must be in [1e-4, 1]";
  if (plane_pixel_step < 1 || plane_pixel_step > 8) return "plane_pixel_step must be in 1..8";
  if (!in(parallel_dot, 0, 1)) return "parallel_dot must be in [0, 1]";
  if (!in(plane_unchanged_tolerance, 0, 0.5))
    return "plane_unchanged_tolerance must be in [0, 0.5]";
  if (!in(plane_fit_cone_dot, 0, 1)) return "plane_fit_cone_dot must be in [0, 1]";
  if (!in(plane_max_residual, 1e-5, 1)) return "plane_max_residual must be in [1e-5, 1]";
  if (max_modes < 2 || max_modes > 64) return "max_modes must be in 2..64";
  if (plane_yaw_bins < 16 || plane_yaw_bins > 1440) return "plane_yaw_bins must be in 16..1440";
  if (plane_yaw_smooth_radius < 0 || plane_yaw_smooth_radius > 7)
    return "plane_yaw_smooth_radius must be in 0..7";
  if (!(plane_yaw_min_gradient >= 0)) return "plane_yaw_min_gradient must be at least 0";
  if (!(plane_yaw_max_footprint_m > 0)) return "plane_yaw_max_footprint_m must be positive";
  if (plane_yaw_min_pixels < 1) return "plane_yaw_min_pixels must be at least 1";
  if (!in(plane_yaw_min_ncc, -1, 1)) return "plane_yaw_min_ncc must be in [-1, 1]";
  if (!in(plane_yaw_max_turn_rad, 0, 1.5)) return "plane_yaw_max_turn_rad must be in [0, 1.5]";
  if (!in(plane_yaw_min_turn_rad, 0, plane_yaw_max_turn_rad))
    return "plane_yaw_min_turn_rad must be in [0, plane_yaw_max_turn_rad]";
  if (rotation_keyframe_interval < 1) return "rotation_keyframe_interval must be at least 1";
  if (!in(rotation_keyframe_min_overlap, 0, 1))
    return "rotation_keyframe_min_overlap must be in [0, 1]";
  if (!in(rotation_keyframe_max_angle, 0, 1.5))
    return "rotation_keyframe_max_angle must be in [0, 1.5]";
  if (projection_width < 16 || projection_width > 4096 || projection_width % 2)
    return "projection_width must be even and in 16..4096";
  if (projection_height < 16 || projection_height > 4096 || projection_height % 2)
    return "projection_height must be even and in 16..4096";
  if (projection_stride < 1 || projection_stride > 8) return "projection_stride must be in 1..8";
  if (!in(projection_inlier_fraction, 0.05, 1))
    return "projection_inlier_fraction must be in [0.05, 1]";
  if (projection_fill_gap < 0 || projection_fill_gap > 16)
    return "projection_fill_gap must be in 0..16";
  if (!in(projection_border_fade, 0, 0.5)) return "projection_border_fade must be in [0, 0.5]";
  if (!in(kcc_sigma, 1e-3, 100)) return "kcc_sigma must be in [1e-3, 100]";
  if (!in(kcc_lambda, 1e-6, 1e3)) return "kcc_lambda must be in [1e-6, 1e3]";
  if (!in(kcc_label_sigma, 0, 50)) return "kcc_label_sigma must be in [0, 50]";
  if (!in(kcc_depth_weight, 0, 100)) return "kcc_depth_weight must be in [0, 100]";
  if (psr_exclusion < 0 || 2 * psr_exclusion + 1 >= projection_width / 2 ||
      2 * psr_exclusion + 1 >= projection_height / 2)
    return "psr_exclusion must be non-negative and small against the projection";
  if (!in(psr_bound, 0, 1e6)) return "psr_bound must be non-negative";
  if (!in(psr_min, 0, 1e6) || psr_min > psr_bound) return "psr_min must be in [0, psr_bound]";
  if (!(kcc_prior_ratio > 0 && kcc_prior_ratio <= 1)) return "kcc_prior_ratio must be in (0, 1]";
  if (kcc_ridge_cells < 1 || kcc_ridge_cells > 64) return "kcc_ridge_cells must be in [1, 64]";
  if (!in(kcc_ridge_ratio, 0, 1)) return "kcc_ridge_ratio must be in [0, 1]";
  if (!in(depth_gray_tolerance, 0, 1)) return "depth_gray_tolerance must be in [0, 1]";
  if (!in(depth_inlier_m, 1e-4, 10)) return "depth_inlier_m must be in [1e-4, 10]";
  if (!in(depth_max_slope, 0, 100)) return "depth_max_slope must be in [0, 100]";
  if (depth_sample_step < 1 || depth_sample_step > 8) return "depth_sample_step must be in 1..8";
  if (depth_iterations < 1 || depth_iterations > 20) return "depth_iterations must be in 1..20";
  if (verify_sample_step < 1 || verify_sample_step > 32)
    return "verify_sample_step must be in 1..32";
  if (align_iterations < 0 || align_iterations > 50) return "align_iterations must be in 0..50";
  if (!in(align_converged_m, 0, 0.01)) return "align_converged_m must be in [0, 0.01]";
  if (!in(align_join_m, 0, 0.01)) return "align_join_m must be in [0, 0.01]";
  if (!in(align_max_distance_m, 1e-4, 10)) return "align_max_distance_m must be in [1e-4, 10]";
  if (!in(align_inlier_m, 1e-5, 10)) return "align_inlier_m must be in [1e-5, 10]";
  if (!in(align_inlier_per_m, 0, 1)) return "align_inlier_per_m must be in [0, 1]";
  if (!in(align_normal_dot, -1, 1)) return "align_normal_dot must be in [-1, 1]";
  if (!in(align_min_eigenvalue, 0, 100)) return "align_min_eigenvalue must be in [0, 100]";
  if (!in(align_step_eigenvalue, 0, 100)) return "align_step_eigenvalue must be in [0, 100]";
  if (!in(align_step_inlier_slack, 0, 0.5)) return "align_step_inlier_slack must be in [0, 0.5]";
  if (!in(align_photometric_weight, 0, 10)) return "align_photometric_weight must be in [0, 10]";
  if (!in(align_confirm_eigenvalue, 0, 100)) return "align_confirm_eigenvalue must be in [0, 100]";
  if (!in(align_confirm_step_m, 0, 1)) return "align_confirm_step_m must be in [0, 1]";
  if (!in(align_confirm_shift_m, 0, 1)) return "align_confirm_shift_m must be in [0, 1]";
  if (!in(verify_max_spread_sigmas, 0, 1000))
    return "verify_max_spread_sigmas must be in [0, 1000]";
  if (align_polish_iterations < 0 || align_polish_iterations > 50)
    return "align_polish_iterations must be in 0..50";
  if (align_coarse_levels < 0 || align_coarse_levels > 3)
    return "align_coarse_levels must be in 0..3";
  if (!in(align_coarse_gate_growth, 1, 4)) return "align_coarse_gate_growth must be in [1, 4]";
  if (!in(verify_min_inliers, 0, 1)) return "verify_min_inliers must be in [0, 1]";
  if (!in(verify_min_overlap, 0, 1)) return "verify_min_overlap must be in [0, 1]";
  if (!in(verify_max_rms_m, 0, 10)) return "verify_max_rms_m must be in [0, 10]";
  if (!in(verify_min_ncc, -1, 1)) return "verify_min_ncc must be in [-1, 1]";
  if (!in(verify_texture_std, 0, 1)) return "verify_texture_std must be in [0, 1]";
  if (!in(verify_max_grey_depth_gap_rad, 0, 3.2))
    return "verify_max_grey_depth_gap_rad must be in [0, 3.2]";
  if (!in(prior_translation_m, 1e-4, 10)) return "prior_translation_m must be in [1e-4, 10]";
  if (!in(prior_rotation_rad, 1e-4, 3.2)) return "prior_rotation_rad must be in [1e-4, 3.2]";
  if (!in(hypothesis_tie, 0, 1)) return "hypothesis_tie must be in [0, 1]";
  if (!in(reference_min_overlap, 0, 1)) return "reference_min_overlap must be in [0, 1]";
  if (reference_max_frames < 1) return "reference_max_frames must be at least 1";
  if (prediction_trust_frames < 0 || prediction_trust_frames > 16)
    return "prediction_trust_frames must be in 0..16";
  if (prediction_trust_gap < 1) return "prediction_trust_gap must be at least 1";
  if (!in(prediction_trust_rad, 0, 3.2)) return "prediction_trust_rad must be in [0, 3.2]";
  if (!in(prediction_trust_m, 0, 10)) return "prediction_trust_m must be in [0, 10]";
  if (unverified_motion_min_directions < 1 || unverified_motion_min_directions > 7)
    return "unverified_motion_min_directions must be in 1..7";
  if (!in(min_valid_depth_fraction, 0, 1)) return "min_valid_depth_fraction must be in [0, 1]";
  if (max_degraded_frames < 1) return "max_degraded_frames must be at least 1";
  if (recovery_min_depth_directions < 0 || recovery_min_depth_directions > 6)
    return "recovery_min_depth_directions must be in 0..6";
  return {};
}

PlaneTrackingParams planeTrackingParams(const OdometryConfig& c, int normal_map_pixels) {
  PlaneTrackingParams p;
  p.border = c.border_px / c.normal_stride;
  p.overlap_dot = c.overlap_dot;
  p.mode_dot = c.mode_dot;
  p.pixel_step = c.plane_pixel_step;
  // Counted over the pixels read, one in pixel_step^2.
  p.min_plane_pixels = std::max(
      1, int(c.min_plane_fraction * float(normal_map_pixels) / float(p.pixel_step * p.pixel_step)));
  p.max_modes = c.max_modes;
  p.estimator = c.plane_normal;
  p.fit_cone_dot = c.plane_fit_cone_dot;
  return p;
}

PlaneYawParams planeYawParams(const OdometryConfig& c) {
  PlaneYawParams p;
  p.bins = c.plane_yaw_bins;
  p.pixel_step = c.plane_pixel_step;
  p.smooth_radius = c.plane_yaw_smooth_radius;
  p.min_gradient = c.plane_yaw_min_gradient;
  p.max_footprint_m = c.plane_yaw_max_footprint_m;
  p.min_pixels = c.plane_yaw_min_pixels;
  p.min_ncc = c.plane_yaw_min_ncc;
  p.max_turn_rad = c.plane_yaw_max_turn_rad;
  return p;
}

AlignmentParams alignmentParams(const OdometryConfig& c) {
  AlignmentParams p;
  p.iterations = c.align_iterations;
  p.converged_m = c.align_converged_m;
  p.join_m = c.align_join_m;
  p.max_distance_m = c.align_max_distance_m;
  p.inlier_m = c.align_inlier_m;
  p.inlier_per_m = c.align_inlier_per_m;
  p.normal_dot = c.align_normal_dot;
  p.coarse_gate_growth = c.align_coarse_gate_growth;
  p.min_eigenvalue = c.align_min_eigenvalue;
  p.step_eigenvalue = c.align_step_eigenvalue;
  p.step_inlier_slack = c.align_step_inlier_slack;
  p.photometric_weight = c.align_photometric_weight;
  p.confirm_eigenvalue = c.align_confirm_eigenvalue;
  p.confirm_step_m = c.align_confirm_step_m;
  p.confirm_shift_m = c.align_confirm_shift_m;
  p.polish_iterations = std::min(c.align_polish_iterations, c.align_iterations);
  p.grey_depth_gap_rad = c.verify_max_grey_depth_gap_rad;
  return p;
}

DepthShiftParams depthShiftParams(const OdometryConfig& c) {
  DepthShiftParams p;
  p.gray_tolerance = c.depth_gray_tolerance;
  p.inlier_m = c.depth_inlier_m;
  p.iterations = c.depth_iterations;
  p.sample_step = c.depth_sample_step;
  p.max_slope = c.depth_max_slope;
  p.resolution = 0;
  return p;
}

}  // namespace nidevo
