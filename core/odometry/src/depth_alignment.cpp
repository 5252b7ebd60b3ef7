#include "nidevo/odometry/depth_alignment.hpp"

#include <Eigen/Eigenvalues>
#include <algorithm>
#include <cmath>

namespace nidevo {

using Eigen::Isometry3d;
using Eigen::Matrix3d;
using Eigen::Vector3d;

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

namespace {

// Pixel of a camera-frame point in the (distorted) image; false behind the camera.
bool projectToPixel(const Camera& cam, const Vector3d& p, double* u, double* v) {
  if (p.z() <= 1e-6) return false;
  Eigen::Vector2d xy(p.x() / p.z(), p.y() / p.z());
  if (!cam.distortion.none()) xy = cam.distortion.distort(xy);
  *u = cam.fx * xy.x() + cam.cx;
  *v = cam.fy * xy.y() + cam.cy;
  return true;
}

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
// (image gradient by central differences, times the pinhole projection's Jacobian; the lens
// distortion's own derivative is left out: it is near 1 where texture matters).
bool greyAndGradient(const std::vector<float>& image, int width, int height, const Camera& cam,
                     const Vector3d& p, double u, double v, double* grey, Vector3d* gradient) {
  const int u0 = int(std::floor(u)), v0 = int(std::floor(v));
  if (u0 < 1 || v0 < 1 || u0 + 2 >= width || v0 + 2 >= height) return false;
  const double a = u - u0, b = v - v0;
  auto at = [&](int x, int y) { return double(image[size_t(y) * size_t(width) + size_t(x)]); };
  auto bilinear = [&](int x, int y) {
    return (1 - a) * (1 - b) * at(x, y) + a * (1 - b) * at(x + 1, y) + (1 - a) * b * at(x, y + 1) +
           a * b * at(x + 1, y + 1);
  };
  *grey = bilinear(u0, v0);
  const double gu = 0.5 * (bilinear(u0 + 1, v0) - bilinear(u0 - 1, v0));
  const double gv = 0.5 * (bilinear(u0, v0 + 1) - bilinear(u0, v0 - 1));
  const double iz = 1.0 / p.z();
  *gradient = Vector3d(gu * cam.fx * iz, gv * cam.fy * iz,
                       -(gu * cam.fx * p.x() + gv * cam.fy * p.y()) * iz * iz);
  return true;
}

// Huber weight of residual r at scale k, so that outliers pull little.
double huberWeight(double r, double k) { return std::abs(r) <= k ? 1.0 : k / std::abs(r); }

}  // namespace

// One residual r with the model's derivative direction d (a normal, or a grey gradient): the
// Jacobian row is [p x d / depth_scale, d].
inline void DepthAligner::addRow(const Vector3d& p, const Vector3d& d, double r, double w,
                                 double depth_scale, NormalEquations* system) {
  Eigen::Matrix<double, 6, 1> J;
  J.head<3>() = p.cross(d) / depth_scale;
  J.tail<3>() = d;
  // The whole fixed-size outer product: Eigen unrolls and vectorises it, where a
  // selfadjointView rankUpdate goes through a generic product kernel per row.
  system->H.noalias() += (w * J) * J.transpose();
  system->b += w * r * J;
}

void DepthAligner::evaluate(const SurfaceSample& ref, const NormalMap& cur,
                            const std::vector<float>& cur_intensity, const Camera& cam,
                            const Isometry3d& T_cur_ref, const AlignmentParams& prm,
                            double depth_scale, bool build_system, bool photometric,
                            AlignmentResult* res) {
  const Matrix3d R = T_cur_ref.linear();
  const Vector3d t = T_cur_ref.translation();
  if (build_system) {
    depth_.setZero();
    grey_.setZero();
    system_points_ = 0;
  }
  int associated = 0, inliers = 0;
  double sq = 0, sa = 0, sb = 0, saa = 0, sbb = 0, sab = 0;
  const double gate = prm.max_distance_m;
  for (size_t i = 0; i < ref.size(); ++i) {
    const Vector3d p = R * ref.point[i].cast<double>() + t;
    double uf, vf;
    if (!projectToPixel(cam, p, &uf, &vf)) continue;
    const int u = int(std::lround(uf)), v = int(std::lround(vf));
    if (u < 0 || v < 0 || u >= cur.width || v >= cur.height) continue;
    const size_t j = size_t(v) * size_t(cur.width) + size_t(u);
    if (!cur.valid[j]) continue;
    ++associated;
    const Vector3d n = cur.normal[j].cast<double>();
    const Vector3d q = cur.points[j].cast<double>();
    const double r = n.dot(q - p);
    if (std::abs(r) > gate || n.dot(R * ref.normal[i].cast<double>()) < prm.normal_dot) continue;
    if (std::abs(r) <= prm.inlier_m + prm.inlier_per_m * p.z()) {
      ++inliers;
      sq += r * r;
      const double a = ref.intensity[i], b = cur_intensity[j];
      sa += a, sb += b, saa += a * a, sbb += b * b, sab += a * b;
    }
    if (!build_system) continue;
    addRow(p, n, r, huberWeight(r, prm.inlier_m), depth_scale,
           &depth_);  // scale: the inlier threshold
    ++system_points_;
    if (photometric) {
      Eigen::Vector3d g;
      double grey;
      if (greyAndGradient(cur_intensity, cur.width, cur.height, cam, p, uf, vf, &grey, &g)) {
        const double lambda = prm.photometric_weight;
        const double rg = gain_ * ref.intensity[i] + bias_ - grey;
        addRow(p, lambda * g, lambda * rg, huberWeight(rg, prm.photometric_huber), depth_scale,
               &grey_);
      }
    }
  }
  res->sampled = int(ref.size());
  res->associated = associated;
  res->inliers = inliers;
  res->rms_m = inliers ? std::sqrt(sq / inliers) : 0.0;
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

// Directions (of 6) whose normalised eigenvalue reaches min_eigenvalue.
int constrainedDirections(const Eigen::Matrix<double, 6, 6>& H, double min_eigenvalue) {
  Eigen::SelfAdjointEigenSolver<Eigen::Matrix<double, 6, 6>> eig(H, Eigen::EigenvaluesOnly);
  return int((eig.eigenvalues().array() >= min_eigenvalue).count());
}

}  // namespace

void DepthAligner::gaussNewton(const SurfaceSample& ref, const NormalMap& cur,
                               const std::vector<float>& cur_intensity, const Camera& map_camera,
                               const AlignmentParams& prm, double depth_scale, bool photometric,
                               int iterations, Isometry3d* T_cur_ref_io, AlignmentResult* result) {
  Isometry3d& T_cur_ref = *T_cur_ref_io;
  AlignmentResult& res = *result;
  for (int it = 0; it < iterations; ++it) {
    evaluate(ref, cur, cur_intensity, map_camera, T_cur_ref, prm, depth_scale, true, photometric,
             &res);
    // Too few points for six unknowns, or a step no small-motion linearisation can take: the
    // hypothesis is left as it is (and judged as it is).
    if (system_points_ < std::max(12, int(ref.size() / 20))) return;
    const Eigen::Matrix<double, 6, 6> H_depth =
        Eigen::Matrix<double, 6, 6>(depth_.H.selfadjointView<Eigen::Lower>()) / system_points_;
    Eigen::Matrix<double, 6, 6> H = H_depth;
    Eigen::Matrix<double, 6, 1> b = depth_.b / system_points_;
    if (photometric) {
      H += Eigen::Matrix<double, 6, 6>(grey_.H.selfadjointView<Eigen::Lower>()) / system_points_;
      b += grey_.b / system_points_;
    }
    Eigen::SelfAdjointEigenSolver<Eigen::Matrix<double, 6, 6>> eig(H);
    Eigen::Matrix<double, 6, 1> xi = Eigen::Matrix<double, 6, 1>::Zero();
    res.constrained = 0;
    res.confirmed = 0;
    res.free_rotation = res.free_translation = false;
    for (int k = 0; k < 6; ++k) {
      const double lambda = eig.eigenvalues()(k);
      if (lambda < prm.min_eigenvalue) {
        if (prm.confirm_eigenvalue > 0 && lambda >= prm.confirm_eigenvalue &&
            std::abs(eig.eigenvectors().col(k).dot(b) / lambda) <= prm.confirm_step_m)
          ++res.confirmed;
        const bool rotational = eig.eigenvectors().col(k).head<3>().squaredNorm() > 0.5;
        (rotational ? res.free_rotation : res.free_translation) = true;
        continue;
      }
      ++res.constrained;
      const auto vk = eig.eigenvectors().col(k);
      xi += (vk.dot(b) / lambda) * vk;
    }
    // What depth alone fixes at this pose, whatever the grey values add.
    res.depth_constrained =
        photometric ? constrainedDirections(H_depth, prm.min_eigenvalue) : res.constrained;
    // Here the rotation part is still in metres at the mean depth.
    const bool converged =
        xi.head<3>().norm() < prm.converged_m && xi.tail<3>().norm() < prm.converged_m;
    xi.head<3>() /= depth_scale;
    if (!xi.allFinite() || xi.head<3>().norm() > 0.3 || xi.tail<3>().norm() > 0.3) return;
    T_cur_ref = increment(xi) * T_cur_ref;
    ++res.steps;
    T_cur_ref.linear() = Eigen::Quaterniond(T_cur_ref.linear()).normalized().toRotationMatrix();
    if (converged) return;
  }
}

AlignmentResult DepthAligner::align(const SurfaceSample& ref, const NormalMap& cur,
                                    const std::vector<float>& cur_intensity,
                                    const Camera& map_camera, const Isometry3d& T_ref_cur,
                                    const AlignmentParams& prm) {
  AlignmentResult res;
  Isometry3d T_cur_ref = T_ref_cur.inverse();
  gain_ = 1.0;
  bias_ = 0.0;
  // Rotation columns divided by the mean depth, so that rotation and translation directions
  // have comparable eigenvalues.
  double depth_scale = 0;
  for (const auto& p : ref.point) depth_scale += p.z();
  depth_scale = ref.size() ? std::max(0.1, depth_scale / double(ref.size())) : 1.0;
  // Depth alone first (its basin is wider than the grey values'); then depth and grey values
  // together: they fix what geometry leaves free, and where depth fixed everything they still
  // polish the pose in a few steps (a real sensor's depth is biased and noisy).
  gaussNewton(ref, cur, cur_intensity, map_camera, prm, depth_scale, false, prm.iterations,
              &T_cur_ref, &res);
  if (prm.photometric_weight > 0) {
    const int steps =
        res.constrained < 6 ? prm.iterations : std::min(prm.polish_iterations, prm.iterations);
    if (steps > 0)
      gaussNewton(ref, cur, cur_intensity, map_camera, prm, depth_scale, true, steps, &T_cur_ref,
                  &res);
  }
  evaluate(ref, cur, cur_intensity, map_camera, T_cur_ref, prm, depth_scale, false, false, &res);
  res.T_ref_cur = T_cur_ref.inverse();
  return res;
}

}  // namespace nidevo
