#pragma once
#include <Eigen/Geometry>
#include <istream>
#include <string>
#include <vector>

namespace nidevo {

// One line of a TUM trajectory: T_world_cam at a timestamp. The quaternion is kept as read so
// that a read/write cycle reproduces the file exactly; use pose() for arithmetic.
struct StampedPose {
  double timestamp = 0.0;
  Eigen::Vector3d translation = Eigen::Vector3d::Zero();
  Eigen::Quaterniond rotation = Eigen::Quaterniond::Identity();

  Eigen::Isometry3d pose() const;
  static StampedPose fromPose(double timestamp, const Eigen::Isometry3d& pose);
};

using Trajectory = std::vector<StampedPose>;

// TUM format: "timestamp tx ty tz qx qy qz qw" per line, '#' comments. Throws std::runtime_error
// naming the file and line on malformed input.
Trajectory readTumTrajectory(const std::string& path);
// The same from a stream; `source` names it in errors.
Trajectory parseTumTrajectory(std::istream& in, const std::string& source);
void writeTumTrajectory(const std::string& path, const Trajectory& trajectory);
std::string formatTumLine(const StampedPose& pose);
// Parses one line; returns false for blank/comment lines, throws std::invalid_argument if
// malformed.
bool parseTumLine(const std::string& line, StampedPose* pose);

}  // namespace nidevo
