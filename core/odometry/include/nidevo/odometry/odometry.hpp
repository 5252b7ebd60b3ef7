#pragma once
// The per-session NIDEVO odometry: frames in, T_world_cam out. The three stages (normal map,
// rotation, translation) are separately callable so that a caller can run them on different
// threads; stage 2 and stage 3 must each see the frames in order.
#include <Eigen/Geometry>
#include <cstdint>
#include <memory>
#include <vector>

#include "nidevo/odometry/camera.hpp"
#include "nidevo/odometry/depth_shift.hpp"
#include "nidevo/odometry/image.hpp"
#include "nidevo/odometry/kcc.hpp"
#include "nidevo/odometry/motion_model.hpp"
#include "nidevo/odometry/normal_map.hpp"
#include "nidevo/odometry/odometry_config.hpp"
#include "nidevo/odometry/ortho_projection.hpp"
#include "nidevo/odometry/plane_tracking.hpp"
#include "nidevo/odometry/plane_yaw.hpp"

namespace nidevo {

enum class TrackingState { kOk, kDegraded, kLost };
const char* toString(TrackingState s);

enum class RotationSource {
  kInitial,     // first frame (or first after a loss): identity or the last pose
  kPlanes,      // two or more non-parallel planes (the method)
  kOnePlane,    // one plane: prediction corrected so that the plane's normal agrees
  kPrediction,  // no plane: constant-rotation-rate prediction
};
const char* toString(RotationSource s);

struct StageTimes {
  double normals_s = 0;
  double rotation_s = 0;
  double translation_s = 0;  // includes the verification
};

// The check of the full pose against the reference frame (depth_alignment.hpp).
struct PoseVerification {
  const char* hypothesis = "";  // "method", "prediction" or "" (no check: first frame, no depth)
  double inlier_fraction = 0;
  double overlap_fraction = 0;
  double residual_rms_m = 0;
  double ncc = 0;
  int constrained_directions = 0;        // of 6; the others kept the hypothesis' value
  int depth_constrained_directions = 0;  // ... that depth alone fixed (the rest: grey values)
  int confirmed_directions = 0;   // too weak to update, yet left at the hypothesis by the data
  bool free_rotation = false;     // a direction left free is (mostly) a rotation
  bool free_translation = false;  // ... a translation
  bool passed = false;
  double grey_depth_gap_deg = 0;   // AlignmentResult::grey_depth_gap_rad, in degrees
  double grey_depth_gap_m = 0;     // AlignmentResult::grey_depth_gap_m
  double sigma_rotation_deg = 0;   // AlignmentResult::sigma_rotation_rad, in degrees
  double sigma_translation_m = 0;  // AlignmentResult::sigma_translation_m
  double normal_noise_deg = 0;     // root of AlignmentResult::normal_noise_var, in degrees
  Eigen::Matrix<double, 6, 1> depth_eigenvalues =
      Eigen::Matrix<double, 6, 1>::Zero();  // AlignmentResult::depth_eigenvalues
  Eigen::Matrix<double, 6, 1> eigenvalues =
      Eigen::Matrix<double, 6, 1>::Zero();  // AlignmentResult::eigenvalues
  // OK although a direction was left free: its value is the motion prediction's, which matched
  // the recent verified frames (OdometryConfig::prediction_trust_frames).
  bool predicted_directions = false;
};

struct PoseEstimate {
  uint64_t frame_index = 0;
  double timestamp = 0;
  Eigen::Isometry3d T_world_cam = Eigen::Isometry3d::Identity();
  TrackingState state = TrackingState::kOk;
  const char* reason = "";  // static text; empty when OK
  double psr = 0;
  int kcc_rival_peaks = 0;  // other KCC maxima nearly as high (KccMatch::rival_peaks)
  double kcc_ridge_u = 0;   // KccMatch::ridge_u and ridge_v
  double kcc_ridge_v = 0;
  int planes_used = 0;
  RotationSource rotation_source = RotationSource::kInitial;
  bool rotation_keyframe = false;
  bool translation_keyframe = false;
  int overlap_pixels = 0;
  double projection_resolution = 0;  // m/px of the translation keyframe
  PoseVerification verification;
  StageTimes times;
};

// What one frame carries from stage to stage. Reusable: buffers keep their capacity.
struct FrameState {
  uint64_t frame_index = 0;
  double timestamp = 0;
  bool depth_ok = false;
  NormalMap normals;
  // Projection cloud (camera frame), one plane per coordinate; z = 0 where depth is missing.
  std::vector<float> cloud_x, cloud_y, cloud_z;
  std::vector<float> map_intensity;  // [0, 1], one per normal-map pixel
  // [0, 1], one per projection point; empty when the projection's stride is the map's (the
  // projection reads map_intensity then).
  std::vector<float> intensity;
  // Stage 2 output.
  Eigen::Matrix3d R_world_cam = Eigen::Matrix3d::Identity();
  RotationSource rotation_source = RotationSource::kInitial;
  int planes_used = 0;
  int overlap_pixels = 0;
  bool rotation_keyframe = false;
  PlaneYaw plane_yaw;  // one plane: the turn about its normal from the grey values
  StageTimes times;
};

struct KccRidges;       // pose_check.hpp
struct StatusEvidence;  // pose_check.hpp

class Odometry {
 public:
  // Throws std::invalid_argument naming the bad field of the camera or the config.
  Odometry(const Camera& camera, const OdometryConfig& config);
  ~Odometry();

  const Camera& camera() const { return camera_; }
  const OdometryConfig& config() const { return config_; }

  // Stage 1: thread-safe for distinct states. Throws std::invalid_argument if the frame does
  // not match the camera's size.
  void computeNormals(const RgbdFrame& frame, FrameState* state) const;
  // Stage 2: rotation against the rotation keyframe.
  void estimateRotation(FrameState* state);
  // Stage 3: translation against the translation keyframe; the frame's final pose.
  PoseEstimate estimateTranslation(FrameState* state);

  // All three stages on the calling thread.
  PoseEstimate track(const RgbdFrame& frame);

 private:
  struct RotationState;
  struct TranslationState;
  struct VerificationState;
  void matchRotationKeyframe(const Eigen::Matrix3d& R_pred, FrameState* state);
  void makeRotationKeyframe(const FrameState& state);
  void measureTurnAboutPlane(const PlanePair& plane, FrameState* state, Eigen::Matrix3d* R_key_cur);
  void makeTranslationKeyframe(const FrameState& state, const Eigen::Isometry3d& T_world_cam);
  // Returns why the translation was predicted instead, or nullptr; sets *T_world_cam.
  const char* matchTranslationKeyframe(const FrameState& state, const Eigen::Isometry3d& T_pred,
                                       Eigen::Isometry3d* T_world_cam, PoseEstimate* out,
                                       KccRidges* ridges);
  // Why the method's own estimate is weak (a stage fell back to the prediction), or nullptr.
  const char* methodProblem(const FrameState& state, const char* translation_problem) const;
  // Checks (and refines) the method's pose against the reference frame, tries the prediction
  // when it fails, and decides the state; sets out->T_world_cam.
  void verifyPose(const FrameState& state, const Eigen::Isometry3d& T_method,
                  const char* method_problem, bool translation_measured, const KccRidges& ridges,
                  PoseEstimate* out);
  // verifyPose's steps (pose_verification.cpp).
  struct CheckedPose;
  void reportLostWithoutDepth(const FrameState& state, const Eigen::Isometry3d& T_method,
                              const char* method_problem, PoseEstimate* out);
  // Aligns the method's pose, then if needed the prediction and the last pose, then if none
  // passed the prediction coarse to fine, and chooses.
  CheckedPose checkHypotheses(const FrameState& state, const Eigen::Isometry3d& T_method,
                              const char* method_problem, bool translation_measured);
  // Betters a pose not called OK along what it leaves free; its status stays.
  void refineUnverified(const CheckedPose& checked, PoseEstimate* out);
  // The prediction's record, the motion model and the reference, from the frame's outcome.
  void updateMotion(const FrameState& state, const CheckedPose& checked,
                    const Eigen::Isometry3d& T_method, const PoseEstimate* out);
  // Whether the status was OK only thanks to a weak direction's value (confirmed, or the
  // method's) that the grey values cannot tell from the pose moved along it
  // (DepthAligner::untoldWeakDirections).
  bool weakDirectionUntold(const CheckedPose& checked, const StatusEvidence& evidence);
  // Whether the status was OK only thanks to a direction that the grey values alone fix and
  // cannot tell (DepthAligner::greyFixedDirectionUntold).
  bool greyFixedUntold(const CheckedPose& checked, const StatusEvidence& evidence);
  // What the status rules applied after the motion model took the pose (so that they move no
  // pose) need beyond the check itself.
  struct LateEvidence {
    bool weak_direction_untold = false;
    bool grey_fixed_untold = false;
  };
  void applyLateStatusRules(const CheckedPose& checked, const LateEvidence& late,
                            PoseEstimate* out);
  void renewReference(const FrameState& state, const Eigen::Isometry3d& T_out,
                      const Eigen::Isometry3d& T_method);
  CloudView projectionCloud(const FrameState& state) const;
  // The same strides sample the same grey values: the map's serve the projection too (0.3 MB
  // less per frame in flight at VGA).
  bool projectionReadsMapIntensity() const {
    return config_.projection_stride == config_.normal_stride;
  }
  void projectForCorrelation(const CloudView& cloud, const Eigen::Matrix3f& R,
                             OrthoImage* image) const;
  const float* depthChannel(const OrthoImage& image, float mean_depth,
                            std::vector<float>* channel) const;

  Camera camera_;
  OdometryConfig config_;
  std::unique_ptr<RotationState> rot_;
  std::unique_ptr<TranslationState> trans_;
  std::unique_ptr<VerificationState> verify_;
  std::vector<float> point_weight_;   // per projection point, fades contrast at the border
  std::vector<float> ray_x_, ray_y_;  // projection cloud: per-pixel undistorted rays
  std::unique_ptr<const PixelRays> normal_rays_;  // the normal map's
  FrameState own_state_;
  uint64_t next_index_ = 0;
};

}  // namespace nidevo
