#include "nidevo/odometry/rotation_solver.hpp"

#include <gtest/gtest.h>

#include <Eigen/Geometry>
#include <random>

namespace nidevo {
namespace {

using Eigen::Matrix3d;
using Eigen::Vector3d;

double angleBetween(const Matrix3d& a, const Matrix3d& b) {
  return Eigen::AngleAxisd(a.transpose() * b).angle();
}

TEST(RotationFromTwoPlanes, CaseOneIdentity) {
  TwoPlaneCase which;
  const Matrix3d R = rotationFromTwoPlanes(Vector3d::UnitX(), Vector3d::UnitX(), Vector3d::UnitY(),
                                           Vector3d::UnitY(), 1e-9, &which);
  EXPECT_EQ(which, TwoPlaneCase::kIdentity);
  EXPECT_LT(angleBetween(R, Matrix3d::Identity()), 1e-12);
}

TEST(RotationFromTwoPlanes, CaseTwoOneNormalIsTheAxis) {
  const Vector3d n1 = Vector3d(0.2, -1, 0.1).normalized(), n2 = Vector3d(1, 0.1, 0.3).normalized();
  const Matrix3d truth = Eigen::AngleAxisd(0.3, n1).toRotationMatrix();
  TwoPlaneCase which;
  const Matrix3d R = rotationFromTwoPlanes(truth * n1, n1, truth * n2, n2, 1e-9, &which);
  EXPECT_EQ(which, TwoPlaneCase::kOneUnchanged);
  EXPECT_LT(angleBetween(R, truth), 1e-6);
  // And with the unchanged pair second.
  const Matrix3d R2 = rotationFromTwoPlanes(truth * n2, n2, truth * n1, n1, 1e-9, &which);
  EXPECT_EQ(which, TwoPlaneCase::kOneUnchanged);
  EXPECT_LT(angleBetween(R2, truth), 1e-6);
}

TEST(RotationFromTwoPlanes, CaseThreeGeneral) {
  const Vector3d n1 = Vector3d(0, 0, -1), n2 = Vector3d(0, -1, 0);
  const Matrix3d truth = Eigen::AngleAxisd(0.2, Vector3d(1, 2, 3).normalized()).toRotationMatrix();
  TwoPlaneCase which;
  const Matrix3d R = rotationFromTwoPlanes(truth * n1, n1, truth * n2, n2, 1e-9, &which);
  EXPECT_EQ(which, TwoPlaneCase::kGeneral);
  EXPECT_LT(angleBetween(R, truth), 1e-6);
}

TEST(RotationFromTwoPlanes, AxisInTheSpanOfTheNormalsFallsBackToTheExactFit) {
  const Vector3d n1 = Vector3d::UnitX(), n2 = Vector3d::UnitY();
  const Matrix3d truth = Eigen::AngleAxisd(0.25, Vector3d(1, 1, 0).normalized()).toRotationMatrix();
  TwoPlaneCase which;
  const Matrix3d R = rotationFromTwoPlanes(truth * n1, n1, truth * n2, n2, 1e-9, &which);
  EXPECT_EQ(which, TwoPlaneCase::kDegenerateAxis);
  EXPECT_LT(angleBetween(R, truth), 1e-6);
}

TEST(RotationFromTwoPlanes, ExactForRandomRotationsUpTo30Degrees) {
  std::mt19937 rng(7);
  std::uniform_real_distribution<double> u(-1, 1), angle(0, 30 * M_PI / 180);
  for (int trial = 0; trial < 2000; ++trial) {
    const Matrix3d truth =
        Eigen::AngleAxisd(angle(rng), Vector3d(u(rng), u(rng), u(rng)).normalized())
            .toRotationMatrix();
    const Vector3d n1 = Vector3d(u(rng), u(rng), u(rng)).normalized();
    const Vector3d n2 = Vector3d(u(rng), u(rng), u(rng)).normalized();
    if (std::abs(n1.dot(n2)) > 0.9) continue;
    const Matrix3d R = rotationFromTwoPlanes(truth * n1, n1, truth * n2, n2);
    EXPECT_LT(angleBetween(R, truth), 1e-6) << "trial " << trial;
  }
}

class SolveRotation : public ::testing::TestWithParam<RotationMethod> {};

TEST_P(SolveRotation, ExactOnExactNormalsForRandomRotationsUpTo30Degrees) {
  std::mt19937 rng(42);
  std::uniform_real_distribution<double> u(-1, 1), angle(0, 30 * M_PI / 180);
  for (int trial = 0; trial < 300; ++trial) {
    const Matrix3d truth =
        Eigen::AngleAxisd(angle(rng), Vector3d(u(rng), u(rng), u(rng)).normalized())
            .toRotationMatrix();
    std::vector<PlanePair> planes;
    const int count = 2 + trial % 3;
    while (int(planes.size()) < count) {
      const Vector3d cur = Vector3d(u(rng), u(rng), u(rng)).normalized();
      bool parallel = false;
      for (const auto& p : planes)
        parallel = parallel || std::abs(p.cur.cast<double>().dot(cur)) > 0.8;
      if (parallel) continue;
      planes.push_back({(truth * cur).cast<float>(), cur.cast<float>(), 1000 + trial});
    }
    const auto solution = solveRotation(planes, GetParam(), 0.97, 0.0);
    ASSERT_TRUE(solution.has_value());
    // Exact up to the float storage of the plane normals (PlanePair holds floats).
    EXPECT_LT(angleBetween(solution->rotation, truth), 1e-4) << "trial " << trial;
  }
}

TEST_P(SolveRotation, NeedsTwoNonParallelPlanes) {
  const Eigen::Vector3f a(0, 0, -1), b = Eigen::Vector3f(0.01f, 0, -1).normalized();
  EXPECT_FALSE(solveRotation({}, GetParam(), 0.97, 0.0).has_value());
  EXPECT_FALSE(solveRotation({{a, a, 100}}, GetParam(), 0.97, 0.0).has_value());
  EXPECT_FALSE(solveRotation({{a, a, 100}, {b, b, 100}}, GetParam(), 0.97, 0.0).has_value());
}

INSTANTIATE_TEST_SUITE_P(Methods, SolveRotation,
                         ::testing::Values(RotationMethod::kBestPair, RotationMethod::kClosedForm));

TEST(AngleAboutAxis, MatchesRodrigues) {
  const Vector3d axis = Vector3d(1, -1, 2).normalized(), v = Vector3d(0.3, 0.9, -0.2).normalized();
  for (double a : {-2.5, -0.4, 0.0, 0.7, 3.0}) {
    const Vector3d rotated = Eigen::AngleAxisd(a, axis) * v;
    EXPECT_NEAR(angleAboutAxis(axis, rotated, v), a, 1e-9);
  }
}

}  // namespace
}  // namespace nidevo
