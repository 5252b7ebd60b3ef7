#include <gtest/gtest.h>

#include <filesystem>
#include <fstream>
#include <random>
#include <sstream>

#include "nidevo/io/trajectory.hpp"

namespace nidevo {
namespace {

std::string readAll(const std::string& path) {
  std::ifstream in(path);
  std::stringstream ss;
  ss << in.rdbuf();
  return ss.str();
}

TEST(TrajectoryIo, RoundTripsExactly) {
  std::mt19937_64 rng(7);
  std::uniform_real_distribution<double> u(-5, 5);
  Trajectory traj;
  for (int i = 0; i < 200; ++i) {
    StampedPose p;
    p.timestamp = 1305031102.175304 + i * 0.0333333333333;
    p.translation = {u(rng), u(rng), u(rng)};
    p.rotation = Eigen::Quaterniond(
        Eigen::AngleAxisd(u(rng), Eigen::Vector3d(u(rng), u(rng), u(rng)).normalized()));
    traj.push_back(p);
  }
  const auto dir = std::filesystem::temp_directory_path();
  const std::string a = (dir / "nidevo_traj_a.txt").string(),
                    b = (dir / "nidevo_traj_b.txt").string();
  writeTumTrajectory(a, traj);
  const Trajectory read = readTumTrajectory(a);
  ASSERT_EQ(read.size(), traj.size());
  for (size_t i = 0; i < traj.size(); ++i) {
    EXPECT_EQ(read[i].timestamp, traj[i].timestamp);
    EXPECT_EQ(read[i].translation, traj[i].translation);
    EXPECT_EQ(read[i].rotation.coeffs(), traj[i].rotation.coeffs());
  }
  writeTumTrajectory(b, read);
  EXPECT_EQ(readAll(a), readAll(b));
}

TEST(TrajectoryIo, MalformedLinesNameFileAndLine) {
  const auto path = (std::filesystem::temp_directory_path() / "nidevo_traj_bad.txt").string();
  auto expect_error = [&](const std::string& content, const std::string& needle) {
    std::ofstream(path) << content;
    try {
      readTumTrajectory(path);
      FAIL() << "no error for: " << content;
    } catch (const std::runtime_error& e) {
      EXPECT_NE(std::string(e.what()).find(needle), std::string::npos) << e.what();
    }
  };
  expect_error("# header\n1 0 0 0 0 0 0 1\n2 0 0 0 0 0 1\n",
               "nidevo_traj_bad.txt:3: expected 8 fields");
  expect_error("1 0 0 x 0 0 0 1\n", ":1: 'x' is not a finite number");
  expect_error("1 0 0 0 0 0 0 5\n", "quaternion norm");
  expect_error("1 0 0 nan 0 0 0 1\n", "not a finite number");
  EXPECT_THROW(readTumTrajectory("/nonexistent/traj.txt"), std::runtime_error);
}

TEST(TrajectoryIo, PoseConversionIsConsistent) {
  Eigen::Isometry3d T = Eigen::Isometry3d::Identity();
  T.linear() = Eigen::AngleAxisd(0.3, Eigen::Vector3d(1, 2, 3).normalized()).toRotationMatrix();
  T.translation() = Eigen::Vector3d(1, -2, 3);
  const StampedPose p = StampedPose::fromPose(4.5, T);
  EXPECT_TRUE(p.pose().isApprox(T, 1e-12));
}

}  // namespace
}  // namespace nidevo
