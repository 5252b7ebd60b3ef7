#include "nidevo/sim/sequence.hpp"

#include <algorithm>
#include <cmath>
#include <filesystem>
#include <fstream>
#include <limits>
#include <opencv2/core.hpp>
#include <opencv2/imgcodecs.hpp>
#include <opencv2/imgproc.hpp>
#include <random>
#include <stdexcept>

#include "nidevo/io/camera_io.hpp"

namespace nidevo::synth {

using Eigen::Vector3d;

SensorNoise parseSensorNoise(const std::string& name) {
  if (name == "none") return SensorNoise::kNone;
  if (name == "icl") return SensorNoise::kIclLike;
  if (name == "kinect") return SensorNoise::kStructuredLight;
  throw std::invalid_argument("unknown noise '" + name + "' (none, icl, kinect)");
}

const char* toString(SensorNoise n) {
  switch (n) {
    case SensorNoise::kNone:
      return "none";
    case SensorNoise::kIclLike:
      return "icl";
    case SensorNoise::kStructuredLight:
      return "kinect";
  }
  return "?";
}

double structuredLightDepth(double depth, double disparity_noise_px, const SequenceConfig& c) {
  if (!(depth > 0)) return 0;
  double disparity = c.disparity_focal_baseline / depth + disparity_noise_px;
  disparity = std::round(disparity / c.sl_disparity_step_px) * c.sl_disparity_step_px;
  return disparity > 0 ? c.disparity_focal_baseline / disparity : 0.0;
}

std::string SequenceConfig::validate() const {
  if (frames <= 0 || frames > 1000000) return "frames must be in 1..1000000";
  if (!(rate_hz > 0 && rate_hz <= 1000)) return "rate_hz must be in (0, 1000]";
  if (!(speed > 0 && speed <= 10)) return "speed must be in (0, 10] m/s";
  if (auto e = camera.validate(); !e.empty()) return "camera: " + e;
  if (!(exposure_jumps_per_s >= 0 && exposure_jumps_per_s <= 100))
    return "exposure_jumps_per_s must be in [0, 100]";
  if (!(exposure_jump_min >= 0 && exposure_jump_min <= exposure_jump_max && exposure_jump_max < 1))
    return "exposure jumps must satisfy 0 <= min <= max < 1";
  if (!(sl_disparity_step_px > 0)) return "sl_disparity_step_px must be positive";
  return {};
}

namespace {

Vector3d catmullRom(const Vector3d& p0, const Vector3d& p1, const Vector3d& p2, const Vector3d& p3,
                    double s) {
  const double s2 = s * s, s3 = s2 * s;
  return 0.5 * ((2 * p1) + (-p0 + p2) * s + (2 * p0 - 5 * p1 + 4 * p2 - p3) * s2 +
                (-p0 + 3 * p1 - 3 * p2 + p3) * s3);
}

// Handheld shake: a few incommensurate sinusoids per axis, phases from the seed.
struct Shake {
  double phase[6][3];
  explicit Shake(uint64_t seed) {
    std::mt19937_64 rng(seed);
    std::uniform_real_distribution<double> u(0, 2 * M_PI);
    for (auto& axis : phase)
      for (double& p : axis) p = u(rng);
  }
  double value(int axis, double t) const {
    static const double kFreq[3] = {0.37, 0.91, 1.73};
    static const double kAmp[3] = {1.0, 0.45, 0.2};
    double v = 0;
    for (int k = 0; k < 3; ++k) v += kAmp[k] * std::sin(2 * M_PI * kFreq[k] * t + phase[axis][k]);
    return v;
  }
};

// Intersection with the nearest rectangle along d (camera ray with d.z = 1 in camera frame, so t is
// the depth). Everything is expressed in the camera frame.
struct CamRect {
  Vector3d n, c, u, v;
  double hu, hv, num;
  int index;
  // Bounds of the rectangle's image on the z = 1 plane (when it is wholly in front): a ray
  // outside them cannot hit it, which spares the intersection for most rays in cluttered rooms.
  double x_min = -std::numeric_limits<double>::infinity(), x_max = -x_min;
  double y_min = x_min, y_max = x_max;
};

// Sets the image bounds; false when the rectangle lies wholly behind the depth limit of hits.
bool boundImage(CamRect* r) {
  double z_max = -std::numeric_limits<double>::infinity();
  double z_min = -z_max;
  Vector3d corners[4];
  int k = 0;
  for (double a : {-1.0, 1.0})
    for (double b : {-1.0, 1.0}) corners[k++] = r->c + a * r->hu * r->u + b * r->hv * r->v;
  for (const Vector3d& p : corners) z_min = std::min(z_min, p.z()), z_max = std::max(z_max, p.z());
  if (z_max <= 1e-3) return false;
  if (z_min <= 1e-3) return true;  // crosses the camera plane: no bounds
  r->x_min = r->y_min = std::numeric_limits<double>::infinity();
  r->x_max = r->y_max = -r->x_min;
  for (const Vector3d& p : corners) {
    r->x_min = std::min(r->x_min, p.x() / p.z()), r->x_max = std::max(r->x_max, p.x() / p.z());
    r->y_min = std::min(r->y_min, p.y() / p.z()), r->y_max = std::max(r->y_max, p.y() / p.z());
  }
  const double margin = 1e-9 * (1 + std::abs(r->x_max - r->x_min) + std::abs(r->y_max - r->y_min));
  r->x_min -= margin, r->x_max += margin, r->y_min -= margin, r->y_max += margin;
  return true;
}

std::vector<CamRect> rectsInCamera(const Scene& scene, const Eigen::Isometry3d& T_world_cam) {
  const Eigen::Isometry3d T_cam_world = T_world_cam.inverse();
  const Eigen::Matrix3d R = T_cam_world.linear();
  std::vector<CamRect> out;
  for (size_t i = 0; i < scene.rects.size(); ++i) {
    const Rect& r = scene.rects[i];
    CamRect c;
    c.n = R * r.normal;
    c.c = T_cam_world * r.center;
    c.u = R * r.axis_u;
    c.v = R * r.axis_v;
    c.hu = r.half_u;
    c.hv = r.half_v;
    c.num = c.n.dot(c.c);  // ray origin is the camera centre
    c.index = int(i);
    if (boundImage(&c)) out.push_back(c);
  }
  return out;
}

struct Hit {
  double depth = 0;  // 0 = no hit
  int rect = -1;
  double s = 0, t = 0;  // in-plane coordinates
  double incidence_cos = 1;
  Vector3d normal = Vector3d::Zero();  // of the rectangle hit, in the camera frame
};

Hit castRay(const std::vector<CamRect>& rects, double x, double y) {
  Hit best;
  double best_t = std::numeric_limits<double>::infinity();
  for (const CamRect& r : rects) {
    if (x < r.x_min || x > r.x_max || y < r.y_min || y > r.y_max) continue;
    const double denom = r.n.x() * x + r.n.y() * y + r.n.z();
    if (std::abs(denom) < 1e-12) continue;
    const double t = r.num / denom;
    if (t <= 1e-3 || t >= best_t) continue;
    const Vector3d p(t * x - r.c.x(), t * y - r.c.y(), t - r.c.z());
    const double s = p.dot(r.u), q = p.dot(r.v);
    if (std::abs(s) > r.hu || std::abs(q) > r.hv) continue;
    best_t = t;
    best.depth = t;
    best.rect = r.index;
    best.s = s;
    best.t = q;
    best.incidence_cos = std::abs(denom) / std::sqrt(x * x + y * y + 1);
    best.normal = r.n;
  }
  return best;
}

}  // namespace

SyntheticSequence::SyntheticSequence(const SequenceConfig& config)
    : config_(config), scene_(makeScene(config.scene)) {
  if (auto e = config_.validate(); !e.empty()) throw std::invalid_argument(e);
  const Camera& cam = config_.camera;
  if (!cam.distortion.none()) {
    pixel_rays_.resize(size_t(cam.width) * size_t(cam.height));
    for (int v = 0; v < cam.height; ++v)
      for (int u = 0; u < cam.width; ++u)
        pixel_rays_[size_t(v) * size_t(cam.width) + size_t(u)] = rayAt(u, v);
  }
  // Auto-exposure: the gain jumps at random frames and holds until the next jump.
  std::mt19937_64 exposure_rng(config_.seed * 7919ull + 99);
  std::uniform_real_distribution<double> unit(0, 1);
  double gain = 1;
  for (int i = 0; i < config_.frames; ++i) {
    if (config_.exposure_jumps_per_s > 0 &&
        unit(exposure_rng) < config_.exposure_jumps_per_s / config_.rate_hz) {
      const double size =
          config_.exposure_jump_min +
          (config_.exposure_jump_max - config_.exposure_jump_min) * unit(exposure_rng);
      gain = std::clamp(gain * (unit(exposure_rng) < 0.5 ? 1 - size : 1 + size), 0.5, 2.0);
    }
    exposure_gain_.push_back(gain);
  }
  double t = 0;
  const size_t n = scene_.path.size();
  for (size_t i = 0; i < n; ++i) {
    const double len = (scene_.path[(i + 1) % n].position - scene_.path[i].position).norm();
    // Turning the view also takes time, so short hops between far-apart look-at points are slowed.
    const double look = (scene_.path[(i + 1) % n].look_at - scene_.path[i].look_at).norm();
    const double duration = scene_.path[i].duration_s;
    t += duration > 0 ? duration : std::max(len, 0.25 * look) / config_.speed;
    segment_end_time_.push_back(t);
  }
}

Eigen::Isometry3d SyntheticSequence::poseAtTime(double time) const {
  const size_t n = scene_.path.size();
  const double loop = segment_end_time_.back();
  double tl = std::fmod(time, loop);
  size_t seg = 0;
  while (seg + 1 < n && tl > segment_end_time_[seg]) ++seg;
  const double start = seg == 0 ? 0.0 : segment_end_time_[seg - 1];
  const double s = (tl - start) / (segment_end_time_[seg] - start);
  auto wp = [&](long k) { return scene_.path[size_t((k % long(n) + long(n)) % long(n))]; };
  const long k = long(seg);
  Vector3d pos =
      catmullRom(wp(k - 1).position, wp(k).position, wp(k + 1).position, wp(k + 2).position, s);
  Vector3d look =
      catmullRom(wp(k - 1).look_at, wp(k).look_at, wp(k + 1).look_at, wp(k + 2).look_at, s);
  const Shake shake(config_.seed);
  pos += 0.02 * Vector3d(shake.value(0, time), shake.value(1, time), shake.value(2, time));
  look += 0.06 * Vector3d(shake.value(3, time), shake.value(4, time), 0.0);
  const double roll = 0.03 * shake.value(5, time);

  const Vector3d z = (look - pos).normalized();
  // With fy < 0 the camera's y axis points up the image, otherwise down.
  const Vector3d up = Vector3d::UnitY() * (config_.camera.fy < 0 ? 1.0 : -1.0);
  Vector3d x = up.cross(z).normalized();
  Vector3d y = z.cross(x);
  Eigen::Matrix3d R;
  R.col(0) = x;
  R.col(1) = y;
  R.col(2) = z;
  R = R * Eigen::AngleAxisd(roll, Vector3d::UnitZ()).toRotationMatrix();
  Eigen::Isometry3d T = Eigen::Isometry3d::Identity();
  T.linear() = R;
  T.translation() = pos;
  return T;
}

Eigen::Isometry3d SyntheticSequence::groundTruth(int i) const { return poseAtTime(timestamp(i)); }

Trajectory SyntheticSequence::groundTruthTrajectory() const {
  Trajectory traj;
  for (int i = 0; i < size(); ++i)
    traj.push_back(StampedPose::fromPose(timestamp(i), groundTruth(i)));
  return traj;
}

DepthImageF SyntheticSequence::renderDepth(const Eigen::Isometry3d& T_world_cam) const {
  const Camera& cam = config_.camera;
  const auto rects = rectsInCamera(scene_, T_world_cam);
  DepthImageF depth(cam.width, cam.height, 0.f);
  for (int v = 0; v < cam.height; ++v) {
    for (int u = 0; u < cam.width; ++u) {
      depth.at(u, v) = float(castRay(rects, (u - cam.cx) / cam.fx, (v - cam.cy) / cam.fy).depth);
    }
  }
  return depth;
}

double SyntheticSequence::depthAt(const Eigen::Isometry3d& T_world_cam, double u, double v) const {
  const Camera& cam = config_.camera;
  return castRay(rectsInCamera(scene_, T_world_cam), (u - cam.cx) / cam.fx, (v - cam.cy) / cam.fy)
      .depth;
}

double SyntheticSequence::distanceToScene(const Vector3d& p) const {
  double best = std::numeric_limits<double>::infinity();
  for (const Rect& r : scene_.rects) {
    const Vector3d d = p - r.center;
    const double s = std::clamp(d.dot(r.axis_u), -r.half_u, r.half_u);
    const double t = std::clamp(d.dot(r.axis_v), -r.half_v, r.half_v);
    best = std::min(best, (d - s * r.axis_u - t * r.axis_v).norm());
  }
  return best;
}

Eigen::Vector2d SyntheticSequence::rayAt(double u, double v) const {
  const Camera& cam = config_.camera;
  // Normalised coordinates of the (distorted) image; the ray is where the lens bent them from.
  const Eigen::Vector2d image((u - cam.cx) / cam.fx, (v - cam.cy) / cam.fy);
  return cam.distortion.none() ? image : cam.distortion.undistort(image);
}

double SyntheticSequence::exposureGain(uint64_t frame) const {
  return frame < exposure_gain_.size() ? exposure_gain_[frame] : 1.0;
}

RenderedFrame SyntheticSequence::render(int index) const {
  return renderAt(groundTruth(index), timestamp(index), uint64_t(index));
}

namespace {

// Kinect-like: lateral jitter of where the pattern is sampled, then disparity noise and
// quantisation, then dropouts (grazing angles, beyond the range; for the structured-light model
// also too close, dark surfaces and depth edges).
template <typename RayAt, typename CleanDepthAt>
double sensorDepth(const SequenceConfig& c, const RayAt& rayAt, const CleanDepthAt& clean_depth_at,
                   const std::vector<CamRect>& rects, const Hit& hit, double reflectance, int u,
                   int v, std::mt19937_64* rng, std::normal_distribution<double>* gauss) {
  const double ju = u + c.lateral_sigma_px * (*gauss)(*rng);
  const double jv = v + c.lateral_sigma_px * (*gauss)(*rng);
  const Eigen::Vector2d jittered_ray = rayAt(ju, jv);
  double depth = castRay(rects, jittered_ray.x(), jittered_ray.y()).depth;
  if (c.noise == SensorNoise::kIclLike) {
    if (depth > 0) {
      double disparity = c.disparity_focal_baseline / depth + c.disparity_sigma_px * (*gauss)(*rng);
      disparity = std::round(disparity / c.disparity_step_px) * c.disparity_step_px;
      depth = disparity > 0 ? c.disparity_focal_baseline / disparity : 0.0;
    }
    if (depth > c.max_range_m || hit.incidence_cos < c.min_incidence_cos) depth = 0;
    return depth;
  }
  depth = structuredLightDepth(depth, c.disparity_sigma_px * (*gauss)(*rng), c);
  if (depth < c.sl_min_range_m || depth > c.sl_max_range_m) return 0;
  if (hit.incidence_cos < c.sl_min_incidence_cos || reflectance < c.sl_dark_reflectance) return 0;
  // Holes along depth edges: the projector's pattern is occluded there.
  for (const auto& [du, dv] : {std::pair{1, 0}, {-1, 0}, {0, 1}, {0, -1}}) {
    const double neighbour = clean_depth_at(u + du, v + dv);
    if (!(neighbour > 0) || std::abs(neighbour - hit.depth) > c.sl_edge_jump * hit.depth) return 0;
  }
  return depth;
}

}  // namespace

RenderedFrame SyntheticSequence::renderAt(const Eigen::Isometry3d& T, double timestamp,
                                          uint64_t noise_index) const {
  const Camera& cam = config_.camera;
  const auto rects = rectsInCamera(scene_, T);
  const Vector3d light_cam = T.linear().transpose() * scene_.light_dir;
  const bool noisy = config_.noise != SensorNoise::kNone;
  const double gain = exposureGain(noise_index);
  std::mt19937_64 rng(config_.seed * 1000003ull + noise_index);
  std::normal_distribution<double> gauss(0.0, 1.0);
  const auto ray_at = [this](double u, double v) { return rayAt(u, v); };

  RenderedFrame out;
  out.timestamp = timestamp;
  out.rgb.assign(size_t(cam.width) * size_t(cam.height) * 3, 0);
  out.frame.timestamp = out.timestamp;
  out.frame.gray.resize(cam.width, cam.height);
  out.frame.depth.resize(cam.width, cam.height);

  // Every pixel's clean hit first: the structured-light model looks at the neighbours' depths.
  std::vector<Hit> hits(size_t(cam.width) * size_t(cam.height));
  for (int v = 0; v < cam.height; ++v) {
    for (int u = 0; u < cam.width; ++u) {
      const Eigen::Vector2d ray = pixel_rays_.empty()
                                      ? rayAt(u, v)
                                      : pixel_rays_[size_t(v) * size_t(cam.width) + size_t(u)];
      hits[size_t(v) * size_t(cam.width) + size_t(u)] = castRay(rects, ray.x(), ray.y());
    }
  }
  const auto clean_depth_at = [&](int u, int v) {
    if (u >= 0 && v >= 0 && u < cam.width && v < cam.height)
      return hits[size_t(v) * size_t(cam.width) + size_t(u)].depth;
    const Eigen::Vector2d ray = rayAt(u, v);
    return castRay(rects, ray.x(), ray.y()).depth;
  };

  for (int v = 0; v < cam.height; ++v) {
    for (int u = 0; u < cam.width; ++u) {
      const Hit& hit = hits[size_t(v) * size_t(cam.width) + size_t(u)];
      Vector3d rgb(0.05, 0.05, 0.05);
      if (hit.rect >= 0) {
        const Rect& r = scene_.rects[size_t(hit.rect)];
        const double shade = 0.35 + 0.65 * std::abs(hit.normal.dot(light_cam));
        const double tex =
            patternValue(r.pattern, config_.texture, r.texture_seed, r.period, hit.s, hit.t);
        rgb = r.tint * (r.albedo * shade * tex);
      }
      const double reflectance = rgb.mean();
      if (gain != 1.0) rgb *= gain;
      for (int c = 0; c < 3; ++c) {
        double value = 255.0 * rgb[c] + (noisy ? config_.rgb_sigma * gauss(rng) : 0.0);
        out.rgb[(size_t(v) * cam.width + u) * 3 + c] =
            uint8_t(std::lround(std::clamp(value, 0.0, 255.0)));
      }
      const uint8_t* px = &out.rgb[(size_t(v) * cam.width + u) * 3];
      out.frame.gray.at(u, v) = uint8_t(std::lround(0.299 * px[0] + 0.587 * px[1] + 0.114 * px[2]));
      out.frame.depth.at(u, v) =
          float(noisy && hit.depth > 0 ? sensorDepth(config_, ray_at, clean_depth_at, rects, hit,
                                                     reflectance, u, v, &rng, &gauss)
                                       : hit.depth);
    }
  }
  return out;
}

void SyntheticSequence::writeTumFolder(const std::string& folder) const {
  namespace fs = std::filesystem;
  const fs::path dir(folder);
  fs::create_directories(dir / "rgb");
  fs::create_directories(dir / "depth");
  std::ofstream rgb_list(dir / "rgb.txt"), depth_list(dir / "depth.txt"),
      assoc(dir / "associations.txt");
  if (!rgb_list || !depth_list || !assoc) throw std::runtime_error(folder + ": cannot write lists");
  rgb_list << "# colour images\n# timestamp filename\n";
  depth_list << "# depth images, 16-bit PNG, " << config_.camera.depth_scale
             << " per metre\n# timestamp filename\n";
  const Camera& cam = config_.camera;
  for (int i = 0; i < size(); ++i) {
    const RenderedFrame f = render(i);
    char name[32];
    std::snprintf(name, sizeof(name), "%06d.png", i);
    char ts[32];
    std::snprintf(ts, sizeof(ts), "%.6f", f.timestamp);
    cv::Mat rgb(cam.height, cam.width, CV_8UC3, const_cast<uint8_t*>(f.rgb.data()));
    cv::Mat bgr;
    cv::cvtColor(rgb, bgr, cv::COLOR_RGB2BGR);
    cv::Mat depth(cam.height, cam.width, CV_16UC1);
    for (int v = 0; v < cam.height; ++v) {
      for (int u = 0; u < cam.width; ++u) {
        const double raw = std::round(f.frame.depth.at(u, v) * cam.depth_scale);
        depth.at<uint16_t>(v, u) = uint16_t(std::clamp(raw, 0.0, 65535.0));
      }
    }
    const std::string rgb_path = (dir / "rgb" / name).string();
    const std::string depth_path = (dir / "depth" / name).string();
    if (!cv::imwrite(rgb_path, bgr)) throw std::runtime_error(rgb_path + ": write failed");
    if (!cv::imwrite(depth_path, depth)) throw std::runtime_error(depth_path + ": write failed");
    rgb_list << ts << " rgb/" << name << "\n";
    depth_list << ts << " depth/" << name << "\n";
    assoc << ts << " rgb/" << name << " " << ts << " depth/" << name << "\n";
  }
  writeTumTrajectory((dir / "groundtruth.txt").string(), groundTruthTrajectory());
  writeCameraFile((dir / "camera.txt").string(), cam);
}

}  // namespace nidevo::synth
