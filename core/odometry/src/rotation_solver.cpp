#include "nidevo/odometry/rotation_solver.hpp"

#include <Eigen/Geometry>
#include <Eigen/SVD>
#include <algorithm>
#include <cmath>
#include <cstdint>
#include <limits>

namespace nidevo {

using Eigen::Matrix3d;
using Eigen::Vector3d;

double angleAboutAxis(const Vector3d& axis, const Vector3d& key, const Vector3d& cur) {
  // Eq. 6 numerator (cos) and Eq. 7 numerator (sin) share the denominator |axis x cur|^2.
  const double s = key.dot(axis.cross(cur));
  const double c = key.dot(cur) - axis.dot(cur) * axis.dot(key);
  return std::atan2(s, c);
}

namespace {

Matrix3d kabsch(const Matrix3d& cross_covariance) {  // sum w * key * cur^T
  Eigen::JacobiSVD<Matrix3d> svd(cross_covariance, Eigen::ComputeFullU | Eigen::ComputeFullV);
  Matrix3d D = Matrix3d::Identity();
  D(2, 2) = (svd.matrixU() * svd.matrixV().transpose()).determinant() < 0 ? -1.0 : 1.0;
  return svd.matrixU() * D * svd.matrixV().transpose();
}

}  // namespace

Matrix3d rotationFromTwoPlanes(const Vector3d& key1, const Vector3d& cur1, const Vector3d& key2,
                               const Vector3d& cur2, double tol, TwoPlaneCase* which) {
  const Vector3d d1 = key1 - cur1, d2 = key2 - cur2;
  const bool same1 = d1.norm() <= tol, same2 = d2.norm() <= tol;
  auto report = [&](TwoPlaneCase c) {
    if (which) *which = c;
  };
  if (same1 && same2) {  // case 1
    report(TwoPlaneCase::kIdentity);
    return Matrix3d::Identity();
  }
  if (same1 || same2) {  // case 2: the unchanged normal is the axis
    const Vector3d axis = (same1 ? key1 : key2).normalized();
    const double angle =
        same1 ? angleAboutAxis(axis, key2, cur2) : angleAboutAxis(axis, key1, cur1);
    report(TwoPlaneCase::kOneUnchanged);
    return Eigen::AngleAxisd(angle, axis).toRotationMatrix();
  }
  const Vector3d c = d1.cross(d2);  // case 3, Eq. 8
  if (c.norm() <= 1e-6 * d1.norm() * d2.norm()) {
    report(TwoPlaneCase::kDegenerateAxis);
    return kabsch(key1 * cur1.transpose() + key2 * cur2.transpose());
  }
  const Vector3d axis = c.normalized();
  // Both pairs vote on the angle, each weighted by how far its normal is from the axis.
  const double s = key1.dot(axis.cross(cur1)) + key2.dot(axis.cross(cur2));
  const double co = key1.dot(cur1) - axis.dot(cur1) * axis.dot(key1) + key2.dot(cur2) -
                    axis.dot(cur2) * axis.dot(key2);
  report(TwoPlaneCase::kGeneral);
  return Eigen::AngleAxisd(std::atan2(s, co), axis).toRotationMatrix();
}

Matrix3d minimalRotation(const Vector3d& from, const Vector3d& to) {
  return Eigen::Quaterniond::FromTwoVectors(from, to).toRotationMatrix();
}

namespace {

bool nonParallel(const PlanePair& a, const PlanePair& b, double parallel_dot) {
  return std::abs(a.key.dot(b.key)) < parallel_dot && std::abs(a.cur.dot(b.cur)) < parallel_dot;
}

// Whether the planes whose bits are set in `used` hold a pair of non-parallel planes.
bool hasNonParallelPair(const std::vector<PlanePair>& planes, uint64_t used, double parallel_dot) {
  const size_t n = std::min<size_t>(planes.size(), 64);
  for (size_t i = 0; i < n; ++i)
    for (size_t j = i + 1; j < n; ++j)
      if (((used >> i) & 1) && ((used >> j) & 1) && nonParallel(planes[i], planes[j], parallel_dot))
        return true;
  return false;
}

double residualAngle(const Matrix3d& R, const PlanePair& p) {
  const double c = (R * p.cur.cast<double>()).dot(p.key.cast<double>());
  return std::acos(std::clamp(c, -1.0, 1.0));
}

// Weighted fit over all planes; a plane that disagrees (a mis-fitted or mis-associated one) is
// dropped and the fit repeated, while two non-parallel planes remain.
RotationSolution closedFormDroppingOutliers(const std::vector<PlanePair>& planes,
                                            double parallel_dot, double max_residual) {
  const size_t n = planes.size();
  uint64_t used = n >= 64 ? ~uint64_t(0) : (uint64_t(1) << n) - 1;
  auto is_used = [&](size_t i) { return i < 64 && (used >> i) & 1; };
  RotationSolution best;
  for (;;) {
    Matrix3d H = Matrix3d::Zero();
    int count = 0;
    for (size_t i = 0; i < n; ++i) {
      if (!is_used(i)) continue;
      H += double(planes[i].pixels) * planes[i].key.cast<double>() *
           planes[i].cur.cast<double>().transpose();
      ++count;
    }
    best.rotation = kabsch(H);
    best.planes_used = count;
    size_t worst = n;
    double worst_residual = max_residual;
    for (size_t i = 0; i < n; ++i) {
      if (!is_used(i)) continue;
      const double residual = residualAngle(best.rotation, planes[i]);
      if (residual > worst_residual) worst_residual = residual, worst = i;
    }
    if (worst == n || count <= 2) break;
    const uint64_t without = used & ~(uint64_t(1) << worst);
    if (!hasNonParallelPair(planes, without, parallel_dot)) break;
    used = without;
  }
  return best;
}

// Paper Sec. 3.1: the rotation of every non-parallel pair, scored by the angular residual of
// the other planes weighted by their size; the best scoring one.
RotationSolution bestPair(const std::vector<PlanePair>& planes, double parallel_dot,
                          double unchanged_tolerance) {
  const size_t n = planes.size();
  RotationSolution best;
  best.planes_used = int(n);
  double best_score = std::numeric_limits<double>::infinity();
  for (size_t i = 0; i < n; ++i) {
    for (size_t j = i + 1; j < n; ++j) {
      if (!nonParallel(planes[i], planes[j], parallel_dot)) continue;
      const Matrix3d R = rotationFromTwoPlanes(
          planes[i].key.cast<double>(), planes[i].cur.cast<double>(), planes[j].key.cast<double>(),
          planes[j].cur.cast<double>(), unchanged_tolerance);
      double score = 0;
      for (size_t k = 0; k < n; ++k)
        if (k != i && k != j) score += planes[k].pixels * residualAngle(R, planes[k]);
      if (score < best_score) {
        best_score = score;
        best.rotation = R;
      }
    }
  }
  return best;
}

}  // namespace

std::optional<RotationSolution> solveRotation(const std::vector<PlanePair>& planes,
                                              RotationMethod method, double parallel_dot,
                                              double unchanged_tolerance, double max_residual) {
  // All planes (max_modes is at most 64, so every one has a bit).
  if (!hasNonParallelPair(planes, ~uint64_t(0), parallel_dot)) return std::nullopt;
  if (method == RotationMethod::kClosedForm)
    return closedFormDroppingOutliers(planes, parallel_dot, max_residual);
  return bestPair(planes, parallel_dot, unchanged_tolerance);
}

}  // namespace nidevo
