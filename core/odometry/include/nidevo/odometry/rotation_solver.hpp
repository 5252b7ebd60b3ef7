#pragma once
// Stage 2b: rotation from tracked plane normals, R with n_key = R * n_cur (paper Eqs. 5-8).
#include <Eigen/Core>
#include <optional>
#include <vector>

#include "nidevo/odometry/odometry_config.hpp"
#include "nidevo/odometry/plane_tracking.hpp"

namespace nidevo {

enum class TwoPlaneCase { kIdentity, kOneUnchanged, kGeneral, kDegenerateAxis };

// Two non-parallel plane pairs: the three cases of the paper. `unchanged_tolerance` is the
// |n_key - n_cur| below which a pair counts as unchanged. When the differences are parallel
// (the rotation axis lies in the span of the two normals), Eq. 8 is undefined and the exact
// two-vector fit is used instead (reported as kDegenerateAxis).
Eigen::Matrix3d rotationFromTwoPlanes(const Eigen::Vector3d& key1, const Eigen::Vector3d& cur1,
                                      const Eigen::Vector3d& key2, const Eigen::Vector3d& cur2,
                                      double unchanged_tolerance = 1e-9,
                                      TwoPlaneCase* which = nullptr);

// Angle about a known unit axis that turns cur into key (Eqs. 6-7 as atan2).
double angleAboutAxis(const Eigen::Vector3d& axis, const Eigen::Vector3d& key,
                      const Eigen::Vector3d& cur);

struct RotationSolution {
  Eigen::Matrix3d rotation = Eigen::Matrix3d::Identity();
  int planes_used = 0;  // planes that defined or scored the rotation
};

// nullopt when fewer than two mutually non-parallel planes exist. kClosedForm drops planes whose
// angular residual exceeds max_residual (radians) while two non-parallel planes remain.
std::optional<RotationSolution> solveRotation(const std::vector<PlanePair>& planes,
                                              RotationMethod method, double parallel_dot,
                                              double unchanged_tolerance,
                                              double max_residual = 0.01);

// The smallest rotation that turns `from` into `to` (both unit).
Eigen::Matrix3d minimalRotation(const Eigen::Vector3d& from, const Eigen::Vector3d& to);

}  // namespace nidevo
