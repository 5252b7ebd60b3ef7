#pragma once
// Every tunable of the odometry in one place, with the defaults of METHOD.md (the authors'),
// except where the ablation table of docs/accuracy.md measured a gain (marked "paper:" below).
#include <string>

#include "nidevo/odometry/depth_alignment.hpp"
#include "nidevo/odometry/depth_shift.hpp"
#include "nidevo/odometry/plane_tracking.hpp"
#include "nidevo/odometry/plane_yaw.hpp"

namespace nidevo {

enum class RotationMethod {
  kBestPair,    // paper Sec. 3.1: every pair of planes, scored on the remaining planes
  kClosedForm,  // weighted least squares over all planes (Kabsch/Horn via SVD)
};
RotationMethod parseRotationMethod(const std::string& name);  // best_pair, closed_form
const char* toString(RotationMethod m);

struct OdometryConfig {
  // Stage 1: normal map (paper Eq. 4).
  int normal_stride = 2;              // 2: normals at 320x240 from 640x480, as the authors
  int cell_size = 10;                 // box-filter side (paper Table 3)
  float depth_discontinuity = 0.05f;  // neighbour depth jump (relative) that breaks a normal
  float min_depth_m = 0.1f;
  float max_depth_m = 10.0f;

  // Stage 2: plane tracking and rotation (paper Alg. 1, Eqs. 5-8).
  int border_px = 10;        // in input pixels
  float overlap_dot = 0.9f;  // key/current normals of one pixel at least this aligned
  // Compare a pixel with the keyframe pixel the predicted rotation maps it to, and its normal
  // after that rotation (paper: the same pixel, unrotated).
  bool predicted_association = true;
  float crease_dot = 0.999f;         // 4-neighbour normals less aligned than this: a crease
  float mode_dot = 0.95f;            // a pixel joins a mode within this
  float min_plane_fraction = 0.05f;  // pixels of a mode, as a fraction of the normal map
  // Plane tracking reads every n-th normal-map pixel in u and v: a plane of min_plane_fraction
  // still has hundreds of pixels, and stage 2 costs 1/n^2 (the pose check reads the whole map).
  int plane_pixel_step = 2;
  float parallel_dot = 0.97f;  // two plane normals closer than this count as parallel
  int max_modes = 16;
  RotationMethod rotation_method = RotationMethod::kClosedForm;         // paper: kBestPair
  PlaneNormalEstimator plane_normal = PlaneNormalEstimator::kPlaneFit;  // paper: kMedian
  float plane_fit_cone_dot = 0.99f;          // fit: pixels within this of the mode's median normal
  float plane_max_residual = 0.01f;          // rad; closed_form drops planes that disagree more
  float plane_unchanged_tolerance = 0.002f;  // |n_key - n_cur| below this: the plane did not turn
  int rotation_keyframe_interval = 5;
  float rotation_keyframe_min_overlap = 0.065f;  // fraction; authors: 5000 px at 320x240
  float rotation_keyframe_max_angle = 0.15f;     // rad
  // One plane: the turn about its normal measured from the directions of the grey gradients on
  // the plane (plane_yaw.hpp) where they tell it, instead of left to the prediction. Off: it
  // mends fast one-plane turns on the suite but costs the real clip (docs/accuracy.md "The turn
  // about one plane's normal from the grey values").
  bool one_plane_image_yaw = false;
  int plane_yaw_bins = 120;                // over the full turn
  int plane_yaw_smooth_radius = 7;         // binomial smoothing of the grey values, map pixels
  float plane_yaw_min_gradient = 0.01f;    // grey step per map pixel (grey in [0, 1])
  float plane_yaw_max_footprint_m = 0.1f;  // a map pixel seeing more of the plane is left out
  int plane_yaw_min_pixels = 400;
  float plane_yaw_min_ncc = 0.6f;        // the two histograms' correlation at the turn
  float plane_yaw_max_turn_rad = 0.35f;  // searched either way
  // A measured turn smaller than this is taken for the measurement's noise: the prediction's
  // value stands (on smooth motion it is the more precise).
  float plane_yaw_min_turn_rad = 0.f;

  // Stage 3: orthographic projection, KCC, depth shift (paper Eqs. 3, 9-18).
  int projection_width = 320;
  int projection_height = 240;
  int projection_stride = 2;                // project every n-th input pixel in u and v
  float projection_inlier_fraction = 0.8f;  // mu: points inside the projection
  bool projection_flatten_outline = true;   // empty cells: mean grey instead of 0.5 (authors),
                                            // contrast faded towards the image border
  float projection_border_fade = 0.1f;      // width of that fade, as a fraction of the image width
  int projection_fill_gap = 2;              // fill holes of up to this many cells within a surface
  float kcc_sigma = 0.2f;
  float kcc_lambda = 0.1f;
  float kcc_label_sigma = 0.0f;   // 0: delta label (authors); else Gaussian label, pixels
  bool kcc_use_depth = false;     // correlate depth as a second channel
  float kcc_depth_weight = 0.5f;  // per metre of depth difference
  bool subpixel_peak = true;
  // FFTW_MEASURE planning: maybe a little faster, but the plan (and so the last bits of every
  // pose) can differ between processes. Off: the same frames give the same poses everywhere.
  bool fft_measure = false;
  int psr_exclusion = 5;  // side lobe excludes (2n+1)^2 around the peak
  // Translation keyframe renewed at or below; paper: 50 (docs/accuracy.md, "Other seeds").
  float psr_bound = 30.0f;
  float psr_min = 8.0f;  // below: the KCC match is not trusted
  // KCC maxima of at least this fraction of the highest compete; the one nearest the motion
  // model's predicted shift wins (a periodic texture's next period). 1: the highest only.
  float kcc_prior_ratio = 0.9f;
  // A KCC response still at kcc_ridge_ratio of its peak kcc_ridge_cells away along an axis of
  // the projection did not measure the translation along that axis: a direction the pose check
  // leaves free along it is then not the method's measurement (0: never). Off by default: at 0.6
  // it caught 1 of 4 silent failures on never-seen seeds and demoted 94 good frames
  // (docs/accuracy.md, "Never-seen seeds 40-59").
  int kcc_ridge_cells = 8;
  float kcc_ridge_ratio = 0.0f;
  float depth_gray_tolerance = 0.1f;  // Eq. 18 inlier test on intensity
  float depth_inlier_m = 0.1f;        // Eq. 18 inlier test on the depth difference
  int depth_iterations = 3;
  int depth_sample_step = 2;     // Eq. 18 over every n-th cell in u and v
  float depth_max_slope = 1.5f;  // Eq. 18 skips cells of steeper surfaces (0: off)

  // Verification (depth_alignment.hpp): the full pose, checked against a reference frame (the
  // last frame that renewed it) and refined along the directions the geometry fixes.
  int verify_sample_step = 4;  // every n-th smooth normal-map pixel of the reference
  int align_iterations = 10;   // 0: the method's pose is checked, never changed
  // A step under this (rotation as metres at the mean depth, and translation) ends the
  // refinement: far under a depth sensor's noise (docs/performance.md measures it).
  float align_converged_m = 1e-4f;
  // A fallback hypothesis whose refinement comes within this of one that passed ends there with
  // its result (one basin): fewer passes, but the kept pose is no longer the best-scoring of
  // several converged ones. Off: at 1 mm the poses moved more than a nudge of the defaults does
  // (docs/performance.md, "A fallback that reaches a passed hypothesis"). 0: each refined to
  // its end.
  float align_join_m = 0.0f;
  float align_max_distance_m = 0.08f;  // association gate
  float align_inlier_m = 0.02f;  // inlier residual, plus align_inlier_per_m per metre of depth
  float align_inlier_per_m = 0.01f;
  float align_normal_dot = 0.8f;
  float align_min_eigenvalue = 0.004f;  // weaker directions keep the hypothesis' value
  // A frame reported DEGRADED or LOST is refined once more along the weak directions of at
  // least this eigenvalue (grey values too weak to verify them may still point the right way);
  // the status stays. 0: never. docs/accuracy.md "The pose check" measures it.
  float align_step_eigenvalue = 0.001f;
  float align_step_inlier_slack = 0.01f;  // that pass may lose this fraction of the inliers
  // A weaker direction, of at least this eigenvalue, whose would-be step stays within
  // align_confirm_step_m (metres at the mean depth) confirms the hypothesis' value there, and
  // counts as fixed for OK (0: never; docs/accuracy.md measures the pair).
  float align_confirm_eigenvalue = 3e-4f;
  float align_confirm_step_m = 0.005f;
  // An OK frame whose status rests on a weak direction's value (confirmed, or the method's own)
  // along which the grey values agree no worse with the pose moved this far either way (metres
  // at the mean depth; the 5 cm of a silent failure) is DEGRADED, its pose unchanged: a
  // linearised step cannot see a pose beyond the grey values' reach. 0: never (docs/accuracy.md
  // "Weak directions the grey values cannot tell apart").
  float align_confirm_shift_m = 0.05f;
  float align_photometric_weight = 0.1f;  // grey residuals in the refinement (0: depth only)
  // Grey-value steps after depth alone fixed all six directions (paper: none; 0: none).
  int align_polish_iterations = 3;
  // When no hypothesis passes the check, one more: the prediction aligned on the current frame
  // halved this many times first, then on each finer level (a wider reach than one level's, for
  // a motion that left every hypothesis outside the data's basin). 0: none.
  int align_coarse_levels = 2;
  // The association gate (align_max_distance_m) on a level halved k times, times this to the
  // power k: it grows with the level's pixel (1: the fine gate everywhere).
  float align_coarse_gate_growth = 2.0f;
  float verify_min_inliers = 0.7f;  // of the associated points
  float verify_min_overlap = 0.3f;  // of the sample landing on the current surface
  float verify_max_rms_m = 0.03f;
  float verify_min_ncc = 0.3f;       // grey-value agreement, where the reference has texture
  float verify_texture_std = 0.03f;  // reference grey std below which the NCC is not asked
  // A pose whose depth alone and grey values alone fit best this far apart in rotation
  // (AlignmentResult::grey_depth_gap_rad) is DEGRADED, its pose unchanged: the sensors measured
  // different motions (a real camera's colour and depth taken apart in time, motion blur). Above
  // every verified frame of the stress suite (max 0.83 deg), half the 2 deg of a silent failure;
  // 0: never (docs/accuracy.md).
  float verify_max_grey_depth_gap_rad = 0.017453292f;  // 1 deg
  // An OK frame whose spread (AlignmentResult::sigma_*) times this reaches beyond the accuracy
  // asked of OK frames (prediction_trust_rad, prediction_trust_m) is DEGRADED, its pose
  // unchanged: the sensor noise alone leaves it less sure than OK says. 2: about 95 % of a
  // Gaussian spread; 0: never (docs/accuracy.md "The pose's spread").
  float verify_max_spread_sigmas = 2.0f;
  // On: an OK frame where grey values fixed what depth left weak is decided again with the
  // direction they fix least left free when, with the pose moved align_confirm_shift_m either
  // way along it and the other directions fitted again, they agree no worse (NCC); not OK then:
  // DEGRADED, its pose unchanged. Off by default: on never-seen seeds 140-159 it caught none of
  // 8 silent failures and took 2 points off the OK share (docs/accuracy.md "Directions only the
  // grey values fix, and the normals' noise").
  bool verify_grey_fixed_told = false;
  // On: a direction the grey values fixed where depth could not counts as fixed only when the
  // grey values agree with the pose (NCC at least verify_min_ncc; on a texture too weak for the
  // NCC to be asked they may fix it by noise). Off by default: it caught 1 silent failure on
  // five sets and took 0.8-5.2 points off their OK share (docs/accuracy.md "Grey values that
  // fix a direction on a weak texture").
  bool grey_fixed_needs_ncc = false;
  // Motion prior: a verified pose this far (together) from the prediction has the prediction
  // tried too; fits within hypothesis_tie (relative) are a tie, won by the pose nearer it.
  float prior_translation_m = 0.05f;
  float prior_rotation_rad = 0.05f;
  float hypothesis_tie = 0.02f;
  float reference_min_overlap = 0.8f;  // renew the reference when less of it is seen
  int reference_max_frames = 15;
  // A direction the data leave free takes the hypothesis' value; when that is within
  // prediction_trust_rad and _m of the motion prediction, and the prediction's RMS error over
  // the last prediction_trust_frames verified frames, the latest at most prediction_trust_gap
  // frames back, was within them too, the frame is OK (0 frames: never). The bounds are the
  // accuracy asked of OK frames (docs/accuracy.md), not fitted.
  int prediction_trust_frames = 5;
  int prediction_trust_gap = 3;
  float prediction_trust_rad = 0.0052359878f;  // 0.3 deg
  float prediction_trust_m = 0.015f;
  // The same trusted prediction also settles a periodic pattern's tie (two poses fit alike, or a
  // better fit far away rests on grey values alone) when the pose kept lies within its bounds.
  bool prediction_settles_ties = true;
  // On: an OK frame where another hypothesis passed with a fit within hypothesis_tie of the
  // kept one's, yet ended further from it than OK promises (prediction_trust_rad and _m), is
  // DEGRADED, its pose unchanged: from different starts the data scored both alike, so they did
  // not fix the pose that closely (a plane without texture leaves each start where it was).
  // docs/accuracy.md "Hypotheses that stay apart".
  bool ok_needs_hypotheses_to_agree = true;
  // A pose not verified still measures the motion along what depth fixed: when it passed the
  // check from the prediction's hypothesis with at least this many of its 6 directions fixed by
  // depth, it updates the motion model's velocity. Along the rest it holds the prediction's own
  // value or the grey values', so the prediction confirms little it did not already say (the
  // method's value there, an unverified KCC peak, would; so may grey values alone, a texture
  // period away: docs/accuracy.md "The pose check"). 7: only verified poses do, and the velocity
  // decays over a stretch of unverified frames.
  int unverified_motion_min_directions = 5;

  // Tracking state.
  float min_valid_depth_fraction = 0.05f;
  int max_degraded_frames = 30;  // consecutive DEGRADED frames before LOST
  // After a LOST frame, until the motion prediction has been right again on recent verified
  // frames (prediction_trust_*), a frame is OK only where depth fixed at least this many of its
  // 6 directions: the pose check's minimum, found from a hypothesis the lost stretch left far off,
  // may be a wrong one that depth and grey values agree on. The pose is unchanged (0: never;
  // docs/accuracy.md "Accuracy").
  int recovery_min_depth_directions = 6;
  // Until an OK frame has measured the motion without the prediction (depth fixed all six
  // directions, or the method's own pose was kept), a frame whose kept pose is the prediction's
  // or the last pose's along a direction depth leaves free is DEGRADED, its pose unchanged: at
  // the start the prediction is only "standing still" (docs/accuracy.md "The start: no motion
  // measured yet").
  bool start_requires_measured_motion = true;
  // When no hypothesis keeps the reference in view, the method's unverified pose is kept only
  // where its rotation was measured (two planes) or agrees with the prediction; else the
  // prediction's (one plane's correction can pair two different planes; docs/accuracy.md "One
  // plane whose fitted normals disagree").
  bool unseen_reference_needs_measured_rotation = true;

  // Empty when valid, else a message naming the bad field.
  [[nodiscard]] std::string validate() const;
};

// The stage modules' parameters, derived from the one config; Odometry builds them once.
// Plane tracking works on the normal map, of `normal_map_pixels` pixels.
PlaneTrackingParams planeTrackingParams(const OdometryConfig& config, int normal_map_pixels);
PlaneYawParams planeYawParams(const OdometryConfig& config);
// The resolution is the translation keyframe's, set with each new keyframe (0 until then).
DepthShiftParams depthShiftParams(const OdometryConfig& config);
AlignmentParams alignmentParams(const OdometryConfig& config);

}  // namespace nidevo
