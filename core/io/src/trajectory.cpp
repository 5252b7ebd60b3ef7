#include "nidevo/io/trajectory.hpp"

#include <charconv>
#include <cmath>
#include <fstream>
#include <stdexcept>

#include "nidevo/io/text_parse.hpp"

namespace nidevo {

Eigen::Isometry3d StampedPose::pose() const {
  Eigen::Isometry3d T = Eigen::Isometry3d::Identity();
  T.linear() = rotation.normalized().toRotationMatrix();
  T.translation() = translation;
  return T;
}

StampedPose StampedPose::fromPose(double timestamp, const Eigen::Isometry3d& pose) {
  StampedPose p;
  p.timestamp = timestamp;
  p.translation = pose.translation();
  p.rotation = Eigen::Quaterniond(pose.rotation()).normalized();
  return p;
}

namespace {
void appendShortest(std::string* out, double v) {
  char buf[64];
  auto res = std::to_chars(buf, buf + sizeof(buf), v);
  out->append(buf, res.ptr);
}
}  // namespace

std::string formatTumLine(const StampedPose& p) {
  std::string line;
  const double values[] = {p.timestamp,    p.translation.x(), p.translation.y(), p.translation.z(),
                           p.rotation.x(), p.rotation.y(),    p.rotation.z(),    p.rotation.w()};
  for (size_t i = 0; i < 8; ++i) {
    if (i) line += ' ';
    appendShortest(&line, values[i]);
  }
  return line;
}

bool parseTumLine(const std::string& line, StampedPose* pose) {
  auto fields = splitFields(line);
  if (fields.empty()) return false;
  if (fields.size() != 8) {
    throw std::invalid_argument("expected 8 fields 'timestamp tx ty tz qx qy qz qw', got " +
                                std::to_string(fields.size()));
  }
  double v[8];
  for (size_t i = 0; i < 8; ++i) v[i] = parseDouble(fields[i]);
  Eigen::Quaterniond q(v[7], v[4], v[5], v[6]);
  const double n = q.norm();
  if (!(n > 0.9 && n < 1.1)) {
    throw std::invalid_argument("quaternion norm " + std::to_string(n) + " is not close to 1");
  }
  pose->timestamp = v[0];
  pose->translation = {v[1], v[2], v[3]};
  pose->rotation = q;
  return true;
}

Trajectory readTumTrajectory(const std::string& path) {
  std::ifstream in(path);
  if (!in) throw std::runtime_error(path + ": cannot open trajectory file");
  return parseTumTrajectory(in, path);
}

Trajectory parseTumTrajectory(std::istream& in, const std::string& path) {
  Trajectory traj;
  std::string line;
  int line_no = 0;
  while (std::getline(in, line)) {
    ++line_no;
    StampedPose p;
    try {
      if (!parseTumLine(line, &p)) continue;
    } catch (const std::invalid_argument& e) {
      throw std::runtime_error(path + ":" + std::to_string(line_no) + ": " + e.what());
    }
    traj.push_back(p);
  }
  return traj;
}

void writeTumTrajectory(const std::string& path, const Trajectory& trajectory) {
  std::ofstream out(path);
  if (!out) throw std::runtime_error(path + ": cannot write trajectory file");
  out << "# timestamp tx ty tz qx qy qz qw\n";
  for (const auto& p : trajectory) out << formatTumLine(p) << '\n';
  if (!out) throw std::runtime_error(path + ": write failed");
}

}  // namespace nidevo
