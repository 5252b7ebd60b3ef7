#include "nidevo/odometry/depth_alignment.hpp"

#include <Eigen/Eigenvalues>
#include <algorithm>
#include <cmath>
#include <limits>

#include "lens_projection.hpp"

namespace nidevo {

using Eigen::Isometry3d;
using Eigen::Matrix3d;
using Eigen::Vector3d;
using Eigen::Vector3f;

void SurfaceSample::clear() {
  point.clear();
  normal.clear();
  intensity.clear();
}

void sampleSurface(const NormalMap& map, const std::vector<float>& intensity, int step,
                   SurfaceSample* out) {
  out->clear();
  for (int v = step / 2; v < map.height; v += step) {
    for (int u = step / 2; u < map.width; u += step) {
      const size_t i = size_t(v) * size_t(map.width) + size_t(u);
      if (!map.smooth[i]) continue;
      out->point.push_back(map.points[i]);
      out->normal.push_back(map.normal[i]);
      out->intensity.push_back(intensity[i]);
    }
  }
}

void buildAlignmentTarget(const NormalMap& map, const std::vector<float>& intensity,
                          AlignmentTarget* out) {
  const int W = map.width, H = map.height;
  const size_t n = size_t(W) * size_t(H);
  out->width = W;
  out->height = H;
  out->plane.resize(n);
  const float nan = std::numeric_limits<float>::quiet_NaN();
  static_assert(sizeof(Eigen::Vector3f) == 3 * sizeof(float) &&
                sizeof(Eigen::Vector4f) == 4 * sizeof(float));
  const float* normal = reinterpret_cast<const float*>(map.normal.data());
  const float* point = reinterpret_cast<const float*>(map.points.data());
  float* plane = reinterpret_cast<float*>(out->plane.data());
  // On the floats themselves, without a branch per pixel: Eigen's temporaries and the choice kept
  // the compiler from vectorising. n . q in Eigen's order, x + (y + z), for the same bits.
  for (size_t j = 0; j < n; ++j) {
    const float* nj = normal + 3 * j;
    const float* qj = point + 3 * j;
    const bool valid = map.valid[j] != 0;
    plane[4 * j + 0] = valid ? nj[0] : nan;
    plane[4 * j + 1] = valid ? nj[1] : nan;
    plane[4 * j + 2] = valid ? nj[2] : nan;
    plane[4 * j + 3] = valid ? nj[0] * qj[0] + (nj[1] * qj[1] + nj[2] * qj[2]) : nan;
  }
  out->grey.assign(intensity.begin(), intensity.end());
}

namespace {

bool hasSurface(const Eigen::Vector4f& plane) { return !std::isnan(plane.w()); }

// Left-multiplied increment: rotation vector omega, translation v.
Isometry3d increment(const Eigen::Matrix<double, 6, 1>& xi) {
  Isometry3d T = Isometry3d::Identity();
  const Vector3d omega = xi.head<3>();
  const double angle = omega.norm();
  if (angle > 0) T.linear() = Eigen::AngleAxisd(angle, omega / angle).toRotationMatrix();
  T.translation() = xi.tail<3>();
  return T;
}

// Bilinear grey value at (u, v) and its gradient with respect to the camera-frame point p
// (the image gradient by central differences, interpolated, times the pinhole projection's
// Jacobian; the lens distortion's own derivative is left out: it is near 1 where texture
// matters).
bool greyAndGradient(const AlignmentTarget& cur, const Pinhole& cam, const Vector3f& p, float u,
                     float v, float* grey, Vector3f* gradient) {
  if (!(u >= 1.f && v >= 1.f)) return false;
  const int u0 = int(u), v0 = int(v);  // truncation is rounding down for u, v >= 1
  if (u0 + 2 >= cur.width || v0 + 2 >= cur.height) return false;
  const float a = u - float(u0), b = v - float(v0);
  const size_t W = size_t(cur.width);
  const float* c = &cur.grey[size_t(v0) * W + size_t(u0)];
  auto bilinear = [&](const float* q) {
    return (1 - b) * ((1 - a) * q[0] + a * q[1]) + b * ((1 - a) * q[W] + a * q[W + 1]);
  };
  *grey = bilinear(c);
  const float gu = 0.5f * (bilinear(c + 1) - bilinear(c - 1)) * cam.fx;
  const float gv = 0.5f * (bilinear(c + W) - bilinear(c - W)) * cam.fy;
  const float iz = 1.f / p.z();
  *gradient = Vector3f(gu * iz, gv * iz, -(gu * p.x() + gv * p.y()) * iz * iz);
  return true;
}

// Of the sample's points, at least 0.1 m: rotation columns are divided by it, so that rotation
// and translation directions have comparable eigenvalues.
double meanDepth(const SurfaceSample& ref) {
  double sum = 0;
  for (const auto& p : ref.point) sum += p.z();
  return ref.size() ? std::max(0.1, sum / double(ref.size())) : 1.0;
}

// Huber weight of residual r at scale k, so that outliers pull little.
double huberWeight(double r, double k) { return std::abs(r) <= k ? 1.0 : k / std::abs(r); }

}  // namespace

void DepthAligner::WeightedRows::add(const Vector3f& p, const Vector3f& d, float r, float w,
                                     float inverse_depth_scale) {
  if ((count_ + 1) * kWidth > data_.size()) data_.resize((count_ + 1) * kWidth * 2);
  const float s = std::sqrt(w);
  const Vector3f turn = p.cross(d) * (s * inverse_depth_scale);
  float* row = &data_[count_ * kWidth];
  row[0] = turn.x(), row[1] = turn.y(), row[2] = turn.z();
  row[3] = s * d.x(), row[4] = s * d.y(), row[5] = s * d.z();
  row[6] = s * r, row[7] = 0.f;
  ++count_;
}

void DepthAligner::WeightedRows::sum(NormalEquations* out) const {
  const Eigen::Map<const Eigen::Matrix<float, Eigen::Dynamic, kWidth, Eigen::RowMajor>> A(
      data_.data(), Eigen::Index(count_), Eigen::Index(kWidth));
  Eigen::Matrix<float, kWidth, kWidth> M;
  M.noalias() = A.transpose() * A;
  out->H = M.topLeftCorner<6, 6>().cast<double>();
  out->b = M.block<6, 1>(0, 6).cast<double>();
  out->rr = double(M(6, 6));
}

void DepthAligner::reserve(size_t points) {
  depth_rows_.reserve(points);
  grey_rows_.reserve(points);
  warped_.reserve(points);
  pixel_.reserve(points);
}

void DepthAligner::warp(const SurfaceSample& ref, const AlignmentTarget& cur, const Camera& camera,
                        const Eigen::Matrix3f& R, const Vector3f& t) {
  const Pinhole cam(camera);
  const size_t n = ref.size();
  warped_.resize(n);
  pixel_.resize(n);
  // Four points at a time: the lens polynomial is a chain of dependent operations that one
  // point at a time leaves the CPU waiting on.
  using Array4f = Eigen::Array4f;
  size_t i = 0;
  for (; i + 4 <= n; i += 4) {
    Array4f X, Y, Z;
    for (int k = 0; k < 4; ++k) {
      const Vector3f& q = ref.point[i + size_t(k)];
      X[k] = q.x(), Y[k] = q.y(), Z[k] = q.z();
    }
    const Warped<Array4f> w = warpPoint(R, t, X, Y, Z, cam);
    for (int k = 0; k < 4; ++k) {
      warped_[i + size_t(k)] = {Vector3f(w.x[k], w.y[k], w.z[k]), w.u[k], w.v[k]};
      pixel_[i + size_t(k)] = nearestPixel(w.z[k], w.u[k], w.v[k], cur.width, cur.height);
    }
  }
  for (; i < n; ++i) {
    const Vector3f& q = ref.point[i];
    const Warped<float> w = warpPoint(R, t, q.x(), q.y(), q.z(), cam);
    warped_[i] = {Vector3f(w.x, w.y, w.z), w.u, w.v};
    pixel_[i] = nearestPixel(w.z, w.u, w.v, cur.width, cur.height);
  }
}

void DepthAligner::evaluate(const SurfaceSample& ref, const AlignmentTarget& cur,
                            const Camera& map_camera, const Isometry3d& T_cur_ref,
                            const AlignmentParams& prm, double depth_scale, Rows rows,
                            AlignmentResult* res) {
  const bool build_system = rows != Rows::kNone;
  const bool depth_system = rows == Rows::kDepth || rows == Rows::kDepthAndGrey;
  const bool photometric = rows == Rows::kDepthAndGrey || rows == Rows::kGrey;
  // Floats per point: metres to 1e-7 relative, far below depth noise; the 6x6 systems are
  // solved in double.
  const Eigen::Matrix3f R = T_cur_ref.linear().cast<float>();
  warp(ref, cur, map_camera, R, T_cur_ref.translation().cast<float>());
  const Pinhole cam(map_camera);
  if (build_system) {
    depth_rows_.clear();
    grey_rows_.clear();
  }
  const float inverse_depth_scale = float(1.0 / depth_scale);
  int associated = 0, inliers = 0;
  double sq = 0, sa = 0, sb = 0, saa = 0, sbb = 0, sab = 0, normal_sq = 0;
  const float gate = prm.max_distance_m;
  // The target's pixels are scattered over more than a core's L2 cache, and a point's row of
  // the normal equations is too long for the CPU to run far enough ahead to start the next
  // points' loads itself.
  constexpr size_t kPrefetchAhead = 8;
  const size_t n = ref.size();
  for (size_t i = 0; i < n; ++i) {
    if (i + kPrefetchAhead < n && pixel_[i + kPrefetchAhead] >= 0) {
      const size_t ahead = size_t(pixel_[i + kPrefetchAhead]);
      __builtin_prefetch(&cur.plane[ahead]);
      if (photometric) __builtin_prefetch(&cur.grey[ahead]);
    }
    if (pixel_[i] < 0) continue;
    const size_t j = size_t(pixel_[i]);
    const Eigen::Vector4f& plane = cur.plane[j];
    if (!hasSurface(plane)) continue;
    ++associated;
    const Vector3f& p = warped_[i].point;
    const Vector3f n_cur = plane.head<3>();
    const float r = plane.w() - n_cur.dot(p);
    const float normal_dot = n_cur.dot(R * ref.normal[i]);
    if (std::abs(r) > gate || normal_dot < prm.normal_dot) continue;
    if (std::abs(r) <= prm.inlier_m + prm.inlier_per_m * p.z()) {
      ++inliers;
      sq += double(r) * r;
      normal_sq += 2.0 - 2.0 * double(normal_dot);  // |n_cur - n_ref|^2 of unit normals
      const double a = ref.intensity[i], b = cur.grey[j];
      sa += a, sb += b, saa += a * a, sbb += b * b, sab += a * b;
    }
    if (!build_system) continue;
    if (depth_system)
      depth_rows_.add(p, n_cur, r, float(huberWeight(r, prm.inlier_m)),
                      inverse_depth_scale);  // scale: the inlier threshold
    if (photometric) {
      Vector3f g;
      float grey;
      if (greyAndGradient(cur, cam, p, warped_[i].u, warped_[i].v, &grey, &g)) {
        const float lambda = prm.photometric_weight;
        const float rg = float(gain_ * ref.intensity[i] + bias_) - grey;
        grey_rows_.add(p, lambda * g, lambda * rg, float(huberWeight(rg, prm.photometric_huber)),
                       inverse_depth_scale);
      }
    }
  }
  if (build_system) {
    if (depth_system) depth_rows_.sum(&depth_);
    if (photometric) {
      grey_rows_.sum(&grey_);
      grey_pose_ = T_cur_ref;
    }
  }
  res->sampled = int(ref.size());
  res->associated = associated;
  res->inliers = inliers;
  res->rms_m = inliers ? std::sqrt(sq / inliers) : 0.0;
  res->normal_noise_var = inliers ? normal_sq / (4.0 * inliers) : 0.0;
  res->ncc = 0;
  res->ref_intensity_std = 0;
  if (inliers > 1) {
    const double N = inliers;
    const double cov = sab - sa * sb / N, va = saa - sa * sa / N, vb = sbb - sb * sb / N;
    if (va > 1e-12 && vb > 1e-12) res->ncc = cov / std::sqrt(va * vb);
    res->ref_intensity_std = std::sqrt(std::max(0.0, va / N));
    // Exposure: the current grey values as gain * reference + bias, for the next pass.
    if (va > 1e-9) {
      gain_ = std::clamp(cov / va, 0.5, 2.0);
      bias_ = (sb - gain_ * sa) / N;
    }
  }
}

namespace {

using Matrix6d = Eigen::Matrix<double, 6, 6>;
using Vector6d = Eigen::Matrix<double, 6, 1>;
using Eigen6 = Eigen::SelfAdjointEigenSolver<Matrix6d>;

// The Gauss-Newton step of one kind of residual alone, along the directions it fixes.
Vector6d stepAlone(const Eigen6& eig, const Vector6d& b, double min_eigenvalue) {
  Vector6d xi = Vector6d::Zero();
  for (int k = 0; k < 6; ++k) {
    const double lambda = eig.eigenvalues()(k);
    if (lambda >= min_eigenvalue)
      xi += (eig.eigenvectors().col(k).dot(b) / lambda) * eig.eigenvectors().col(k);
  }
  return xi;
}

}  // namespace

void halveAlignmentTarget(const AlignmentTarget& fine, AlignmentTarget* out) {
  const int W = fine.width / 2, H = fine.height / 2;
  out->width = W;
  out->height = H;
  out->plane.resize(size_t(W) * size_t(H));
  out->grey.resize(size_t(W) * size_t(H));
  const int fw = fine.width, fh = fine.height;
  auto fineAt = [&](int u, int v) { return size_t(v) * size_t(fw) + size_t(u); };
  for (int v = 0; v < H; ++v) {
    for (int u = 0; u < W; ++u) {
      const size_t c = size_t(v) * size_t(W) + size_t(u);
      const size_t f = fineAt(2 * u, 2 * v);
      const size_t block[4] = {f, f + 1, f + size_t(fw), f + size_t(fw) + 1};
      out->plane[c] = fine.plane[f];
      for (const size_t b : block) {
        if (!std::isnan(fine.plane[b].w())) {
          out->plane[c] = fine.plane[b];
          break;
        }
      }
      float sum = 0.f;
      for (int dv = -1; dv <= 1; ++dv) {
        const int fv = std::clamp(2 * v + dv, 0, fh - 1);
        for (int du = -1; du <= 1; ++du) {
          const int fu = std::clamp(2 * u + du, 0, fw - 1);
          sum += float((2 - std::abs(du)) * (2 - std::abs(dv))) * fine.grey[fineAt(fu, fv)];
        }
      }
      out->grey[c] = sum / 16.f;
    }
  }
}

void AlignmentPyramid::reserve(int levels, const Camera& fine_camera) {
  level.resize(size_t(levels));
  camera.clear();
  for (int k = 0; k < levels; ++k) {
    camera.push_back(fine_camera.subsampled(2 << k));
    const size_t n = size_t(fine_camera.width >> (k + 1)) * size_t(fine_camera.height >> (k + 1));
    level[size_t(k)].plane.reserve(n);
    level[size_t(k)].grey.reserve(n);
  }
}

void AlignmentPyramid::build(const AlignmentTarget& fine) {
  for (size_t k = 0; k < level.size(); ++k)
    halveAlignmentTarget(k ? level[k - 1] : fine, &level[k]);
}

bool DepthAligner::reachedEarlier(const Isometry3d& T_cur_ref, double depth_scale, double join_m) {
  for (int k = 0; k < join_count_; ++k) {
    const Isometry3d apart = T_cur_ref * join_[k]->T_ref_cur;
    if (apart.translation().norm() < join_m &&
        Eigen::AngleAxisd(apart.linear()).angle() * depth_scale < join_m) {
      joined_ = k;
      return true;
    }
  }
  return false;
}

void DepthAligner::gaussNewton(const SurfaceSample& ref, const AlignmentTarget& cur,
                               const Camera& map_camera, const AlignmentParams& prm,
                               double depth_scale, bool photometric, int iterations,
                               Isometry3d* T_cur_ref_io, Eigen::Matrix<double, 6, 1>* weak_moved,
                               AlignmentResult* result,
                               const Eigen::Matrix<double, 6, 1>* held_axis) {
  Isometry3d& T_cur_ref = *T_cur_ref_io;
  AlignmentResult& res = *result;
  for (int it = 0; it < iterations; ++it) {
    evaluate(ref, cur, map_camera, T_cur_ref, prm, depth_scale,
             photometric ? Rows::kDepthAndGrey : Rows::kDepth, &res);
    // Too few points for six unknowns, or a step no small-motion linearisation can take: the
    // hypothesis is left as it is (and judged as it is).
    const int system_points = int(depth_rows_.size());
    if (system_points < std::max(12, int(ref.size() / 20))) return;
    const Eigen::Matrix<double, 6, 6> H_depth = depth_.H / system_points;
    Eigen::Matrix<double, 6, 6> H = H_depth;
    Eigen::Matrix<double, 6, 1> b = depth_.b / system_points;
    if (photometric) {
      H += grey_.H / system_points;
      b += grey_.b / system_points;
    }
    // A stiffness far over any eigenvalue of the normalised system: no step along the axis.
    if (held_axis) H += 1e4 * (*held_axis) * held_axis->transpose();
    Eigen::SelfAdjointEigenSolver<Eigen::Matrix<double, 6, 6>> eig(H);
    Eigen::Matrix<double, 6, 1> xi = Eigen::Matrix<double, 6, 1>::Zero();
    res.constrained = 0;
    res.confirmed = 0;
    res.weak_count = 0;
    res.free_rotation = res.free_translation = false;
    for (int k = 0; k < 6; ++k) {
      const double lambda = eig.eigenvalues()(k);
      if (lambda < prm.min_eigenvalue) {
        const auto vk = eig.eigenvectors().col(k);
        double moved = vk.dot(b) / lambda;  // would-be step from here
        if (weak_moved && lambda >= prm.step_eigenvalue) {
          // Stepped along: what counts is how far the steps took the hypothesis.
          xi += moved * vk;
          *weak_moved += moved * vk;
          moved = vk.dot(*weak_moved);
        }
        const bool confirmed = prm.confirm_eigenvalue > 0 && lambda >= prm.confirm_eigenvalue &&
                               std::abs(moved) <= prm.confirm_step_m;
        res.confirmed += confirmed;
        res.weak_confirmed[res.weak_count] = confirmed;
        res.weak_axes.col(res.weak_count++) = vk;
        const bool rotational = vk.head<3>().squaredNorm() > 0.5;
        (rotational ? res.free_rotation : res.free_translation) = true;
        continue;
      }
      ++res.constrained;
      const auto vk = eig.eigenvectors().col(k);
      xi += (vk.dot(b) / lambda) * vk;
    }
    {
      // sigma^2 H^-1 over the fixed directions, H the sums of the rows (not per point).
      const double rows = double(system_points + (photometric ? grey_rows_.size() : 0));
      const double rr = depth_.rr + (photometric ? grey_.rr : 0.0);
      const double s2 = rows > 6 ? rr / (rows - 6) : 0.0;
      Eigen::Matrix<double, 6, 6> cov = Eigen::Matrix<double, 6, 6>::Zero();
      for (int k = 0; k < 6; ++k) {
        const double lambda = eig.eigenvalues()(k);
        if (lambda < prm.min_eigenvalue) continue;
        const auto vk = eig.eigenvectors().col(k);
        cov += (s2 / (lambda * system_points)) * vk * vk.transpose();
      }
      res.sigma_rotation_rad = std::sqrt(cov.topLeftCorner<3, 3>().trace()) / depth_scale;
      res.sigma_translation_m = std::sqrt(cov.bottomRightCorner<3, 3>().trace());
    }
    res.eigenvalues = eig.eigenvalues();
    // What depth alone fixes at this pose, whatever the grey values add.
    res.depth_eigenvalues =
        photometric ? Eigen6(H_depth, Eigen::EigenvaluesOnly).eigenvalues() : eig.eigenvalues();
    res.depth_constrained =
        int((res.depth_eigenvalues.array() >= double(prm.min_eigenvalue)).count());
    // Here the rotation part is still in metres at the mean depth.
    const bool converged =
        xi.head<3>().norm() < prm.converged_m && xi.tail<3>().norm() < prm.converged_m;
    xi.head<3>() /= depth_scale;
    if (!xi.allFinite() || xi.head<3>().norm() > 0.3 || xi.tail<3>().norm() > 0.3) return;
    T_cur_ref = increment(xi) * T_cur_ref;
    ++res.steps;
    T_cur_ref.linear() = Eigen::Quaterniond(T_cur_ref.linear()).normalized().toRotationMatrix();
    if (converged) return;
    if (join_count_ > 0 && reachedEarlier(T_cur_ref, depth_scale, prm.join_m)) return;
  }
}

// Grey values alone, from the pose both sensors gave, to where they fit best: their rotation
// against depth's own optimum. Steps along the directions grey values fix (their rows carry
// photometric_weight, squared in the normal equations), stopping at a step below 0.01 deg and
// 0.5 mm, at one over about 6 deg or 0.1 m (out of the linearisation's reach), after
// kGreyDepthGapSteps, or after the first where the gap is under a quarter of the bound.
void DepthAligner::measureGreyDepthGap(const SurfaceSample& ref, const AlignmentTarget& cur,
                                       const Camera& map_camera, const AlignmentParams& prm,
                                       double depth_scale, const Isometry3d& T_depth,
                                       const Isometry3d& T_both, AlignmentResult* res) {
  constexpr int kGreyDepthGapSteps = 6;
  Isometry3d T_grey = T_both;
  auto gap_rad = [&] { return Eigen::AngleAxisd((T_grey * T_depth.inverse()).linear()).angle(); };
  AlignmentResult scratch;
  const double grey_min = prm.min_eigenvalue * prm.photometric_weight * prm.photometric_weight;
  for (int it = 0; it < kGreyDepthGapSteps; ++it) {
    // The polish's last pass left grey rows built a step before T_both: the first step starts
    // there instead of from a pass of its own (the same optimum, one pass fewer on most frames).
    if (it == 0 && grey_pose_)
      T_grey = *grey_pose_;
    else
      evaluate(ref, cur, map_camera, T_grey, prm, depth_scale, Rows::kGrey, &scratch);
    const double n = double(std::max<size_t>(12, grey_rows_.size()));
    Vector6d xi = stepAlone(Eigen6(grey_.H / n), grey_.b / n, grey_min);
    xi.head<3>() /= depth_scale;
    if (!xi.allFinite() || xi.head<3>().norm() > 0.1 || xi.tail<3>().norm() > 0.1) break;
    T_grey = increment(xi) * T_grey;
    if (it == 0 && gap_rad() < 0.25 * prm.grey_depth_gap_rad) break;
    if (xi.head<3>().norm() < 1.7e-4 && xi.tail<3>().norm() < 5e-4) break;
  }
  res->grey_depth_gap_rad = gap_rad();
  res->grey_depth_gap_m = (T_grey.inverse().translation() - T_depth.inverse().translation()).norm();
}

AlignmentResult DepthAligner::align(const SurfaceSample& ref, const NormalMap& cur,
                                    const std::vector<float>& cur_intensity,
                                    const Camera& map_camera, const Isometry3d& T_ref_cur,
                                    const AlignmentParams& prm) {
  buildAlignmentTarget(cur, cur_intensity, &own_target_);
  return align(ref, own_target_, map_camera, T_ref_cur, prm);
}

AlignmentResult DepthAligner::align(const SurfaceSample& ref, const AlignmentTarget& cur,
                                    const Camera& map_camera, const Isometry3d& T_ref_cur,
                                    const AlignmentParams& prm,
                                    const AlignmentResult* const* earlier, int earlier_count) {
  join_ = earlier;
  join_count_ = prm.join_m > 0 ? earlier_count : 0;
  joined_ = -1;
  AlignmentResult res = align(ref, cur, map_camera, T_ref_cur, prm);
  if (joined_ >= 0) {
    res = *earlier[joined_];
    res.joined = joined_;
  }
  // Nothing to join outside this call: a later plain align must run to its own end.
  join_count_ = 0;
  joined_ = -1;
  return res;
}

AlignmentResult DepthAligner::align(const SurfaceSample& ref, const AlignmentTarget& cur,
                                    const Camera& map_camera, const Isometry3d& T_ref_cur,
                                    const AlignmentParams& prm) {
  AlignmentResult res;
  Isometry3d T_cur_ref = T_ref_cur.inverse();
  gain_ = 1.0;
  bias_ = 0.0;
  grey_pose_.reset();
  const double depth_scale = meanDepth(ref);
  // Depth alone first (its basin is wider than the grey values'); then depth and grey values
  // together: they fix what geometry leaves free, and where depth fixed everything they still
  // polish the pose in a few steps (a real sensor's depth is biased and noisy).
  gaussNewton(ref, cur, map_camera, prm, depth_scale, false, prm.iterations, &T_cur_ref, nullptr,
              &res);
  if (joined_ >= 0) return res;
  if (prm.photometric_weight > 0) {
    const int steps =
        res.constrained < 6 ? prm.iterations : std::min(prm.polish_iterations, prm.iterations);
    const Isometry3d T_depth = T_cur_ref;
    const bool depth_fixed_all = res.constrained == 6;
    if (steps > 0)
      gaussNewton(ref, cur, map_camera, prm, depth_scale, true, steps, &T_cur_ref, nullptr, &res);
    if (joined_ >= 0) return res;
    if (depth_fixed_all && prm.grey_depth_gap_rad > 0)
      measureGreyDepthGap(ref, cur, map_camera, prm, depth_scale, T_depth, T_cur_ref, &res);
  }
  evaluate(ref, cur, map_camera, T_cur_ref, prm, depth_scale, Rows::kNone, &res);
  res.T_ref_cur = T_cur_ref.inverse();
  return res;
}

AlignmentResult DepthAligner::alignCoarseToFine(
    const SurfaceSample& ref, const AlignmentTarget& cur, const Camera& map_camera,
    const AlignmentPyramid& pyramid, const Isometry3d& T_ref_cur, const AlignmentParams& prm) {
  Isometry3d T = T_ref_cur;
  for (size_t k = pyramid.level.size(); k-- > 0;) {
    AlignmentParams level_prm = prm;
    level_prm.max_distance_m = prm.max_distance_m * std::pow(prm.coarse_gate_growth, float(k + 1));
    T = align(ref, pyramid.level[k], pyramid.camera[k], T, level_prm).T_ref_cur;
  }
  return align(ref, cur, map_camera, T, prm);
}

DepthAligner::Untold DepthAligner::untoldWeakDirections(const SurfaceSample& ref,
                                                        const AlignmentTarget& cur,
                                                        const Camera& map_camera,
                                                        const AlignmentResult& result,
                                                        const AlignmentParams& prm) {
  const Isometry3d T_cur_ref = result.T_ref_cur.inverse();
  const double depth_scale = meanDepth(ref);
  Untold untold;
  for (int k = 0; k < result.weak_count; ++k) {
    bool worse_both_ways = true;
    for (const double sign : {-1.0, 1.0}) {
      Vector6d xi = sign * prm.confirm_shift_m * result.weak_axes.col(k);
      xi.head<3>() /= depth_scale;
      AlignmentResult moved;
      evaluate(ref, cur, map_camera, increment(xi) * T_cur_ref, prm, depth_scale, Rows::kNone,
               &moved);
      worse_both_ways = worse_both_ways && moved.ncc < result.ncc;
    }
    if (worse_both_ways) continue;
    ++untold.directions;
    untold.confirmed += result.weak_confirmed[k];
  }
  return untold;
}

bool DepthAligner::greyFixedDirectionUntold(const SurfaceSample& ref, const AlignmentTarget& cur,
                                            const Camera& map_camera, const AlignmentResult& result,
                                            const AlignmentParams& prm, Vector6d* axis) {
  if (prm.photometric_weight <= 0 || result.constrained <= result.depth_constrained) return false;
  const Isometry3d T_cur_ref = result.T_ref_cur.inverse();
  const double depth_scale = meanDepth(ref);
  AlignmentResult at;
  evaluate(ref, cur, map_camera, T_cur_ref, prm, depth_scale, Rows::kNone, &at);
  evaluate(ref, cur, map_camera, T_cur_ref, prm, depth_scale, Rows::kDepthAndGrey, &at);
  const double n = double(depth_rows_.size());
  if (n < 12) return false;
  const Eigen6 depth(depth_.H / n);
  // Depth's weak directions are the first columns (eigenvalues ascend). Both systems seen in
  // depth's eigenvectors, every direction beyond the weak ones held out by a stiffness over any
  // eigenvalue of the weak block (at most its trace): fixed sizes, so no allocation.
  int weak = 0;
  while (weak < 6 && depth.eigenvalues()(weak) < prm.min_eigenvalue) ++weak;
  if (weak == 0) return false;
  Matrix6d in_weak =
      depth.eigenvectors().transpose() * ((depth_.H + grey_.H) / n) * depth.eigenvectors();
  const double stiffness = 2.0 * in_weak.topLeftCorner(weak, weak).trace() + 1.0;
  for (int k = weak; k < 6; ++k) {
    in_weak.row(k).setZero();
    in_weak.col(k).setZero();
    in_weak(k, k) = stiffness;
  }
  // Of depth's weak directions, the one both together fix least, yet fix (the weaker ones are
  // left free anyway: untoldWeakDirections is their check).
  const Eigen6 both(in_weak);
  int least = 0;
  while (least < weak && both.eigenvalues()(least) < prm.min_eigenvalue) ++least;
  if (least == weak) return false;
  *axis = (depth.eigenvectors() * both.eigenvectors().col(least)).normalized();
  const double gain = gain_, bias = bias_;
  bool worse_both_ways = true;
  for (const double sign : {-1.0, 1.0}) {
    Vector6d xi = sign * prm.confirm_shift_m * *axis;
    xi.head<3>() /= depth_scale;
    Isometry3d T = increment(xi) * T_cur_ref;
    gain_ = gain, bias_ = bias;
    AlignmentResult moved;
    gaussNewton(ref, cur, map_camera, prm, depth_scale, true, prm.polish_iterations, &T, nullptr,
                &moved, axis);
    evaluate(ref, cur, map_camera, T, prm, depth_scale, Rows::kNone, &moved);
    worse_both_ways = worse_both_ways && moved.ncc < result.ncc;
  }
  return !worse_both_ways;
}

AlignmentResult DepthAligner::refineAlongWeakDirections(const SurfaceSample& ref,
                                                        const AlignmentTarget& cur,
                                                        const Camera& map_camera,
                                                        const AlignmentResult& from,
                                                        const AlignmentParams& prm) {
  if (prm.step_eigenvalue <= 0 || prm.photometric_weight <= 0 || from.constrained >= 6) return from;
  Isometry3d T_cur_ref = from.T_ref_cur.inverse();
  gain_ = 1.0;
  bias_ = 0.0;
  const double depth_scale = meanDepth(ref);
  AlignmentResult weak = from;
  Eigen::Matrix<double, 6, 1> weak_moved = Eigen::Matrix<double, 6, 1>::Zero();
  gaussNewton(ref, cur, map_camera, prm, depth_scale, true, prm.iterations, &T_cur_ref, &weak_moved,
              &weak);
  evaluate(ref, cur, map_camera, T_cur_ref, prm, depth_scale, Rows::kNone, &weak);
  if (!(weak.ncc > from.ncc && weak.inliers >= (1.0 - prm.step_inlier_slack) * from.inliers &&
        weak.rms_m <= from.rms_m))
    return from;
  weak.T_ref_cur = T_cur_ref.inverse();
  return weak;
}

}  // namespace nidevo
