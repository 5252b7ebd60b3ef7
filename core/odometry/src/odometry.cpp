#include "nidevo/odometry/odometry.hpp"

#include <algorithm>
#include <chrono>
#include <cmath>
#include <stdexcept>

#include "constant_stride.hpp"
#include "nidevo/odometry/motion_model.hpp"
#include "nidevo/odometry/rotation_solver.hpp"
#include "vector_clones.hpp"
#include "verification_state.hpp"

namespace nidevo {

using Eigen::Isometry3d;
using Eigen::Matrix3d;

const char* toString(TrackingState s) {
  switch (s) {
    case TrackingState::kOk:
      return "OK";
    case TrackingState::kDegraded:
      return "DEGRADED";
    case TrackingState::kLost:
      return "LOST";
  }
  return "?";
}

const char* toString(RotationSource s) {
  switch (s) {
    case RotationSource::kInitial:
      return "initial";
    case RotationSource::kPlanes:
      return "planes";
    case RotationSource::kOnePlane:
      return "one_plane";
    case RotationSource::kPrediction:
      return "prediction";
  }
  return "?";
}

namespace {

double secondsSince(std::chrono::steady_clock::time_point t0) {
  return std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
}

Isometry3d rotationOnly(const Matrix3d& R) {
  Isometry3d T = Isometry3d::Identity();
  T.linear() = R;
  return T;
}

}  // namespace

struct Odometry::RotationState {
  RotationState(const OdometryConfig& c, const Camera& camera, int map_pixels)
      : tracking(planeTrackingParams(c, map_pixels)),
        yaw_params(planeYawParams(c)),
        normal_map_pixels(map_pixels),
        map_camera(camera.subsampled(c.normal_stride)) {}
  const PlaneTrackingParams tracking;
  const PlaneYawParams yaw_params;
  const int normal_map_pixels;
  const Camera map_camera;
  bool has_keyframe = false;
  NormalMap key_normals;
  std::vector<float> key_intensity;  // the keyframe's map_intensity, for the one-plane turn
  Matrix3d R_world_key = Matrix3d::Identity();
  int frames_since_key = 0;
  MotionModel motion;
  PlaneTracker tracker;
  PlaneTrackingResult tracked;
  PlaneYawEstimator plane_yaw;
};

struct Odometry::TranslationState {
  explicit TranslationState(const OdometryConfig& c)
      : kcc(c.projection_width, c.projection_height, c.kcc_use_depth ? 2 : 1, c.kcc_sigma,
            c.kcc_lambda, c.kcc_label_sigma, c.fft_measure),
        depth_params(depthShiftParams(c)) {}
  bool has_keyframe = false;
  OrthoImage key, cur;
  std::vector<float> key_depth_channel, cur_depth_channel;
  float key_mean_depth = 0;
  double resolution = 0;
  Isometry3d T_world_key = Isometry3d::Identity();
  MotionModel motion;
  KernelCrossCorrelator kcc;
  OrthoProjector projector;
  DepthShiftEstimator depth_shift;
  DepthShiftParams depth_params;  // its resolution follows the keyframe's
};

Odometry::Odometry(const Camera& camera, const OdometryConfig& config)
    : camera_(camera), config_(config) {
  if (auto e = camera.validate(); !e.empty()) throw std::invalid_argument("camera: " + e);
  if (auto e = config.validate(); !e.empty()) throw std::invalid_argument("config: " + e);
  if (camera.width / config.normal_stride < 2 * config.cell_size + 8 ||
      camera.height / config.normal_stride < 2 * config.cell_size + 8) {
    throw std::invalid_argument("camera: image too small for normal_stride and cell_size");
  }
  // Contrast fades out towards the image border (raised cosine over the outer margin).
  const int stride = config_.projection_stride;
  const int W = camera_.width / stride, H = camera_.height / stride;
  const float margin = config_.projection_border_fade * float(W);
  point_weight_.assign(size_t(W) * size_t(H), 1.f);
  if (margin > 0) {
    for (int v = 0; v < H; ++v) {
      for (int u = 0; u < W; ++u) {
        const float d = float(std::min({u, v, W - 1 - u, H - 1 - v}));
        if (d < margin)
          point_weight_[size_t(v) * size_t(W) + size_t(u)] =
              0.5f - 0.5f * std::cos(float(M_PI) * d / margin);
      }
    }
  }
  // Camera::backproject's per-pixel divisions (and undistortion), done once.
  std::vector<float> column_ray(static_cast<size_t>(W)), row_ray(static_cast<size_t>(H));
  for (int u = 0; u < W; ++u)
    column_ray[size_t(u)] = float((float(u * stride) - camera_.cx) / camera_.fx);
  for (int v = 0; v < H; ++v)
    row_ray[size_t(v)] = float((float(v * stride) - camera_.cy) / camera_.fy);
  expandRays(camera_.distortion, column_ray, row_ray, &ray_x_, &ray_y_);
  normal_rays_ = std::make_unique<const PixelRays>(camera_, config_.normal_stride);
  rot_ = std::make_unique<RotationState>(
      config_, camera_,
      (camera_.width / config_.normal_stride) * (camera_.height / config_.normal_stride));
  trans_ = std::make_unique<TranslationState>(config_);
  verify_ = std::make_unique<VerificationState>(config_, camera_);
}

Odometry::~Odometry() = default;

namespace {

// One row of the projection cloud from every step-th input pixel: the depth within
// [min_depth, max_depth] (else 0, NaN too) along the pixel's ray. Returns the valid count.
template <class Step>
[[gnu::always_inline]] inline int cloudRowWithStep(const float* __restrict depth_row, Step step,
                                                   const float* __restrict ray_x,
                                                   const float* __restrict ray_y, int width,
                                                   float min_depth, float max_depth,
                                                   float* __restrict x, float* __restrict y,
                                                   float* __restrict z) {
  int valid = 0;
  for (int u = 0; u < width; ++u) {
    const float d = depth_row[u * step];
    const bool in_range = (d >= min_depth) & (d <= max_depth);  // false for NaN
    const float depth = in_range ? d : 0.f;
    valid += in_range & (d > 0.f);  // depth > 0, in a form the vectoriser takes
    x[u] = ray_x[u] * depth;
    y[u] = ray_y[u] * depth;
    z[u] = depth;
  }
  return valid;
}

NIDEVO_VECTOR_CLONES int cloudRow(const float* depth_row, int step, const float* ray_x,
                                  const float* ray_y, int width, float min_depth, float max_depth,
                                  float* x, float* y, float* z) {
  // A constant stride of 2 (the default) vectorises; a stride known at run time only does not.
  // Not withConstantStride: its lambda would count into a captured reference, which keeps the
  // loop scalar.
  if (step == 2) {
    return cloudRowWithStep(depth_row, std::integral_constant<int, 2>{}, ray_x, ray_y, width,
                            min_depth, max_depth, x, y, z);
  }
  return cloudRowWithStep(depth_row, step, ray_x, ray_y, width, min_depth, max_depth, x, y, z);
}

// Every step-th grey value of a row, in [0, 1]. Apart from cloudRow: bytes and floats in one
// loop do not vectorise.
NIDEVO_VECTOR_CLONES void greyRow(const uint8_t* __restrict gray_row, int step, int width,
                                  float* __restrict out) {
  withConstantStride(step, [&](auto s) {
    for (int u = 0; u < width; ++u) out[u] = float(gray_row[u * s]) * (1.f / 255.f);
  });
}

}  // namespace

void Odometry::computeNormals(const RgbdFrame& frame, FrameState* s) const {
  const auto t0 = std::chrono::steady_clock::now();
  if (std::string e = camera_.checkImageSize(frame.depth.width, frame.depth.height); !e.empty())
    throw std::invalid_argument("depth " + e);
  if (std::string e = camera_.checkImageSize(frame.gray.width, frame.gray.height); !e.empty())
    throw std::invalid_argument("grey " + e);
  // Image's fields are public: a caller may have changed the size without the pixels.
  const size_t pixels = size_t(camera_.width) * size_t(camera_.height);
  if (frame.depth.size() != pixels || frame.gray.size() != pixels)
    throw std::invalid_argument("image holds a pixel count other than width x height");
  s->timestamp = frame.timestamp;
  // The builder's scratch (about 2 MB at VGA) serves every session the thread runs rather than
  // every frame in flight: only the map it fills is the frame's.
  thread_local NormalMapBuilder normal_builder;
  normal_builder.compute(frame.depth, *normal_rays_, config_.cell_size, config_.depth_discontinuity,
                         config_.min_depth_m, config_.max_depth_m, config_.crease_dot, &s->normals);
  const int map_width = s->normals.width;
  s->map_intensity.resize(size_t(map_width) * size_t(s->normals.height));
  for (int v = 0; v < s->normals.height; ++v) {
    greyRow(&frame.gray.data[size_t(v * config_.normal_stride) * size_t(camera_.width)],
            config_.normal_stride, map_width, &s->map_intensity[size_t(v) * size_t(map_width)]);
  }
  const int stride = config_.projection_stride;
  const int W = camera_.width / stride, H = camera_.height / stride;
  for (auto* plane : {&s->cloud_x, &s->cloud_y, &s->cloud_z}) plane->resize(size_t(W) * size_t(H));
  const bool own_intensity = !projectionReadsMapIntensity();
  s->intensity.resize(own_intensity ? size_t(W) * size_t(H) : 0);
  int valid = 0;
  for (int v = 0; v < H; ++v) {
    const size_t row = size_t(v) * size_t(W),
                 input_row = size_t(v * stride) * size_t(camera_.width);
    valid += cloudRow(&frame.depth.data[input_row], stride, &ray_x_[row], &ray_y_[row], W,
                      config_.min_depth_m, config_.max_depth_m, &s->cloud_x[row], &s->cloud_y[row],
                      &s->cloud_z[row]);
    if (own_intensity) greyRow(&frame.gray.data[input_row], stride, W, &s->intensity[row]);
  }
  s->depth_ok = float(valid) >= config_.min_valid_depth_fraction * float(W * H) &&
                s->normals.validCount() > 0;
  s->times = StageTimes{};
  s->times.normals_s = secondsSince(t0);
}

void Odometry::estimateRotation(FrameState* s) {
  const auto t0 = std::chrono::steady_clock::now();
  RotationState& r = *rot_;
  const Matrix3d R_pred = r.motion.predict(s->timestamp).linear();
  s->planes_used = 0;
  s->overlap_pixels = 0;
  s->rotation_keyframe = false;
  s->plane_yaw = PlaneYaw{};

  if (!s->depth_ok) {
    s->R_world_cam = R_pred;
    s->rotation_source = RotationSource::kPrediction;
  } else if (!r.has_keyframe) {
    s->R_world_cam = R_pred;
    s->rotation_source = RotationSource::kInitial;
    s->rotation_keyframe = true;
  } else {
    matchRotationKeyframe(R_pred, s);
  }
  // Re-orthonormalise so that rounding never accumulates into a non-rotation.
  s->R_world_cam = Eigen::Quaterniond(s->R_world_cam).normalized().toRotationMatrix();
  if (s->rotation_keyframe) makeRotationKeyframe(*s);
  r.motion.update(rotationOnly(s->R_world_cam),
                  s->rotation_source == RotationSource::kPlanes ||
                      s->rotation_source == RotationSource::kInitial,
                  s->timestamp);
  s->times.rotation_s = secondsSince(t0);
}

// Paper Alg. 1 and Eqs. 5-8: planes seen in both the keyframe and this frame give the rotation;
// with one plane the prediction is corrected to agree with it, with none it stands. Decides
// whether this frame becomes the next rotation keyframe.
void Odometry::matchRotationKeyframe(const Matrix3d& R_pred, FrameState* s) {
  RotationState& r = *rot_;
  const int px = r.normal_map_pixels;
  const Matrix3d R_key_pred = r.R_world_key.transpose() * R_pred;
  // A predicted turn of under a map pixel warps nothing: the same pixels are compared.
  const bool warp = config_.predicted_association &&
                    Eigen::AngleAxisd(R_key_pred).angle() * r.map_camera.fx >= 1.0;
  const PlaneWarp plane_warp{R_key_pred.cast<float>(), r.map_camera};
  r.tracker.track(r.key_normals, s->normals, r.tracking, &r.tracked, warp ? &plane_warp : nullptr);
  s->overlap_pixels = r.tracked.overlap_pixels;

  Matrix3d R_key_cur;
  const auto solution =
      solveRotation(r.tracked.planes, config_.rotation_method, config_.parallel_dot,
                    config_.plane_unchanged_tolerance, config_.plane_max_residual);
  if (solution) {
    R_key_cur = solution->rotation;
    s->planes_used = solution->planes_used;
    s->rotation_source = RotationSource::kPlanes;
  } else if (!r.tracked.planes.empty()) {
    const PlanePair& p = r.tracked.planes.front();
    R_key_cur =
        minimalRotation(R_key_pred * p.cur.cast<double>(), p.key.cast<double>()) * R_key_pred;
    s->planes_used = 1;
    s->rotation_source = RotationSource::kOnePlane;
    if (config_.one_plane_image_yaw) measureTurnAboutPlane(p, s, &R_key_cur);
  } else {
    R_key_cur = R_key_pred;
    s->rotation_source = RotationSource::kPrediction;
  }
  s->R_world_cam = r.R_world_key * R_key_cur;
  const double angle = Eigen::AngleAxisd(R_key_cur).angle();
  s->rotation_keyframe =
      ++r.frames_since_key >= config_.rotation_keyframe_interval ||
      float(s->overlap_pixels) < config_.rotation_keyframe_min_overlap * float(px) ||
      angle >= config_.rotation_keyframe_max_angle;
}

// The turn about the one plane's normal that the prediction left, from the grey values' gradient
// directions on the plane (plane_yaw.hpp); R_key_cur keeps the plane's normal where it was.
void Odometry::measureTurnAboutPlane(const PlanePair& plane, FrameState* s, Matrix3d* R_key_cur) {
  RotationState& r = *rot_;
  const PlaneView key{&r.key_normals, r.key_intensity.data(), plane.key,
                      Eigen::Matrix3f::Identity()};
  const PlaneView cur{&s->normals, s->map_intensity.data(), plane.cur, R_key_cur->cast<float>()};
  s->plane_yaw = r.plane_yaw.estimate(key, cur, r.map_camera, r.yaw_params);
  if (!s->plane_yaw.measured || std::abs(s->plane_yaw.turn_rad) < config_.plane_yaw_min_turn_rad)
    return;
  *R_key_cur =
      Eigen::AngleAxisd(s->plane_yaw.turn_rad, plane.key.cast<double>().normalized()) * *R_key_cur;
}

void Odometry::makeRotationKeyframe(const FrameState& s) {
  RotationState& r = *rot_;
  r.has_keyframe = true;
  r.key_normals.width = s.normals.width;
  r.key_normals.height = s.normals.height;
  r.key_normals.normal.assign(s.normals.normal.begin(), s.normals.normal.end());
  r.key_normals.valid.assign(s.normals.valid.begin(), s.normals.valid.end());
  r.key_normals.points.assign(s.normals.points.begin(), s.normals.points.end());
  r.key_normals.smooth.assign(s.normals.smooth.begin(), s.normals.smooth.end());
  r.key_intensity.assign(s.map_intensity.begin(), s.map_intensity.end());
  r.R_world_key = s.R_world_cam;
  r.frames_since_key = 0;
}

CloudView Odometry::projectionCloud(const FrameState& s) const {
  const float* intensity =
      projectionReadsMapIntensity() ? s.map_intensity.data() : s.intensity.data();
  return {s.cloud_x.data(), s.cloud_y.data(), s.cloud_z.data(),
          intensity,        s.cloud_z.size(), point_weight_.data()};
}

// Both the keyframe and the current frame go through the same projection, so that their images
// differ only by the motion.
void Odometry::projectForCorrelation(const CloudView& cloud, const Eigen::Matrix3f& R,
                                     OrthoImage* image) const {
  trans_->projector.project(cloud, R, trans_->resolution, config_.projection_width,
                            config_.projection_height, image);
  trans_->projector.fillGaps(image, config_.projection_fill_gap, config_.depth_discontinuity);
  if (config_.projection_flatten_outline) OrthoProjector::flattenOutline(image);
}

const float* Odometry::depthChannel(const OrthoImage& image, float mean_depth,
                                    std::vector<float>* channel) const {
  channel->resize(image.depth.size());
  for (size_t i = 0; i < image.depth.size(); ++i) {
    const float d = image.depth[i];
    (*channel)[i] = d > 0.f ? config_.kcc_depth_weight * (d - mean_depth) : 0.f;
  }
  return channel->data();
}

void Odometry::makeTranslationKeyframe(const FrameState& s, const Isometry3d& T_world_cam) {
  TranslationState& t = *trans_;
  const CloudView cloud = projectionCloud(s);
  const double r =
      t.projector.resolutionFor(cloud, Eigen::Matrix3f::Identity(), config_.projection_width,
                                config_.projection_height, config_.projection_inlier_fraction);
  if (r <= 0) return;
  t.resolution = r;
  t.depth_params.resolution = r;
  projectForCorrelation(cloud, Eigen::Matrix3f::Identity(), &t.key);
  const float* channels[2] = {t.key.gray.data(), nullptr};
  if (config_.kcc_use_depth) {
    double sum = 0;
    int n = 0;
    for (float d : t.key.depth)
      if (d > 0.f) sum += d, ++n;
    t.key_mean_depth = n ? float(sum / n) : 0.f;
    channels[1] = depthChannel(t.key, t.key_mean_depth, &t.key_depth_channel);
  }
  t.kcc.train(channels);
  t.T_world_key = T_world_cam;
  t.has_keyframe = true;
}

PoseEstimate Odometry::estimateTranslation(FrameState* s) {
  const auto t0 = std::chrono::steady_clock::now();
  TranslationState& t = *trans_;
  PoseEstimate out;
  out.frame_index = s->frame_index;
  out.timestamp = s->timestamp;
  out.planes_used = s->planes_used;
  out.rotation_source = s->rotation_source;
  out.rotation_keyframe = s->rotation_keyframe;
  out.overlap_pixels = s->overlap_pixels;

  const Isometry3d T_pred = t.motion.predict(s->timestamp);
  Isometry3d T = Isometry3d::Identity();
  T.linear() = s->R_world_cam;
  const char* translation_problem = nullptr;
  KccRidges ridges;
  if (!s->depth_ok) {
    T.translation() = T_pred.translation();
    translation_problem = "too little valid depth; pose predicted";
  } else if (!t.has_keyframe) {
    T.translation() = T_pred.translation();
    makeTranslationKeyframe(*s, T);
    out.translation_keyframe = t.has_keyframe;
  } else {
    translation_problem = matchTranslationKeyframe(*s, T_pred, &T, &out, &ridges);
  }
  out.projection_resolution = t.resolution;
  const char* method_problem = methodProblem(*s, translation_problem);
  t.motion.update(T, method_problem == nullptr, s->timestamp);
  // A KCC match with rivals nearly as high chose its peak by the prediction: not a measurement.
  const bool translation_measured =
      s->depth_ok && translation_problem == nullptr && out.kcc_rival_peaks == 0;
  verifyPose(*s, T, method_problem, translation_measured, ridges, &out);
  s->times.translation_s = secondsSince(t0);
  out.times = s->times;
  return out;
}

// Paper Eqs. 9-18: the current cloud, rotated into the keyframe's orientation, projected and
// correlated with the keyframe (KCC shift in the image plane), then the depth shift along the
// axis. Renews the keyframe when the match is weak (PSR at or below psr_bound).
const char* Odometry::matchTranslationKeyframe(const FrameState& s, const Isometry3d& T_pred,
                                               Isometry3d* T, PoseEstimate* out,
                                               KccRidges* ridges) {
  TranslationState& t = *trans_;
  const Matrix3d R_key_cur = t.T_world_key.linear().transpose() * s.R_world_cam;
  projectForCorrelation(projectionCloud(s), R_key_cur.cast<float>(), &t.cur);
  const float* channels[2] = {t.cur.gray.data(), nullptr};
  if (config_.kcc_use_depth) {
    channels[1] = depthChannel(t.cur, t.key_mean_depth, &t.cur_depth_channel);
  }
  // The shift the motion model expects, in the keyframe's projection (see T_key_cur below).
  const Eigen::Vector3d t_key_pred = (t.T_world_key.inverse() * T_pred).translation();
  const KccShiftPrior prior{-t_key_pred.x() / t.resolution, -t_key_pred.y() / t.resolution,
                            config_.kcc_prior_ratio};
  const KccMatch m =
      t.kcc.match(channels, config_.subpixel_peak, config_.psr_exclusion,
                  config_.kcc_prior_ratio < 1.f ? &prior : nullptr, config_.kcc_ridge_cells);
  out->psr = m.psr;
  out->kcc_rival_peaks = m.rival_peaks;
  out->kcc_ridge_u = m.ridge_u;
  out->kcc_ridge_v = m.ridge_v;
  // The projection's u and v are the keyframe camera's x and y.
  if (config_.kcc_ridge_ratio > 0) {
    if (m.ridge_u >= config_.kcc_ridge_ratio)
      ridges->axis[ridges->count++] = R_key_cur.transpose() * Eigen::Vector3d::UnitX();
    if (m.ridge_v >= config_.kcc_ridge_ratio)
      ridges->axis[ridges->count++] = R_key_cur.transpose() * Eigen::Vector3d::UnitY();
  }
  DepthShift dz;
  if (m.psr >= config_.psr_min)
    dz = t.depth_shift.estimate(t.key, t.cur, m.du, m.dv, t.depth_params);
  const char* problem = nullptr;
  if (m.psr < config_.psr_min) {
    problem = "low PSR; translation predicted";
  } else if (dz.inliers == 0) {
    problem = "no depth match; translation predicted";
  }
  if (problem) {
    T->translation() = T_pred.translation();
  } else {
    Isometry3d T_key_cur = Isometry3d::Identity();
    T_key_cur.linear() = R_key_cur;
    T_key_cur.translation() = Eigen::Vector3d(-m.du * t.resolution, -m.dv * t.resolution, dz.dz);
    *T = t.T_world_key * T_key_cur;
    T->linear() = s.R_world_cam;  // keep stage 2's rotation exactly
  }
  if (m.psr <= config_.psr_bound) {
    makeTranslationKeyframe(s, *T);
    out->translation_keyframe = true;
  }
  return problem;
}

const char* Odometry::methodProblem(const FrameState& s, const char* translation_problem) const {
  if (!s.depth_ok) return translation_problem;
  if (s.rotation_source == RotationSource::kOnePlane)
    return s.plane_yaw.measured ? "one plane; the turn about its normal from the grey values on it"
                                : "one plane; rotation partly predicted";
  if (s.rotation_source == RotationSource::kPrediction)
    return "fewer than two non-parallel planes; rotation predicted";
  return translation_problem;
}

PoseEstimate Odometry::track(const RgbdFrame& frame) {
  own_state_.frame_index = next_index_++;
  computeNormals(frame, &own_state_);
  estimateRotation(&own_state_);
  return estimateTranslation(&own_state_);
}

}  // namespace nidevo
