#pragma once
#include <Eigen/Core>
#include <string>
#include <vector>

namespace nidevo {

// Writes a PNG with two panels, top view (x-z) and side view (x-y), of the reference (grey) and
// the aligned estimate (blue), with a metre scale. Throws std::runtime_error on write failure.
void writeTrajectoryPlot(const std::string& path, const std::vector<Eigen::Vector3d>& reference,
                         const std::vector<Eigen::Vector3d>& estimate, const std::string& title);

}  // namespace nidevo
