// The TUM trajectory (ground truth) parser on arbitrary text: poses with finite values and a
// unit-ish quaternion, which format and parse back to the same numbers; or a
// std::runtime_error naming file and line.
#include <cmath>
#include <cstddef>
#include <cstdint>
#include <sstream>
#include <stdexcept>
#include <string>

#include "fuzz_check.hpp"
#include "nidevo/io/trajectory.hpp"

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
  std::istringstream in(std::string(reinterpret_cast<const char*>(data), size));
  nidevo::Trajectory trajectory;
  try {
    trajectory = nidevo::parseTumTrajectory(in, "fuzz");
  } catch (const std::runtime_error&) {
    return 0;
  }
  for (const auto& pose : trajectory) {
    NIDEVO_FUZZ_CHECK(std::isfinite(pose.timestamp) && pose.translation.allFinite());
    NIDEVO_FUZZ_CHECK(pose.pose().matrix().allFinite());
    nidevo::StampedPose again;
    NIDEVO_FUZZ_CHECK(nidevo::parseTumLine(nidevo::formatTumLine(pose), &again));
    NIDEVO_FUZZ_CHECK(again.timestamp == pose.timestamp);
    NIDEVO_FUZZ_CHECK(again.translation == pose.translation);
    NIDEVO_FUZZ_CHECK(again.rotation.coeffs() == pose.rotation.coeffs());
  }
  return 0;
}
