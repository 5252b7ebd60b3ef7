#pragma once
// Offline runners: all stages on one thread, or the paper's three-thread pipeline (normal map,
// rotation, translation each on its own thread, frames in order).
#include <functional>
#include <vector>

#include "nidevo/odometry/odometry.hpp"

namespace nidevo {

using FrameSource = std::function<const RgbdFrame&(size_t index)>;

std::vector<PoseEstimate> runSequential(Odometry& odometry, size_t frames,
                                        const FrameSource& source);
std::vector<PoseEstimate> runPipelined(Odometry& odometry, size_t frames,
                                       const FrameSource& source);

}  // namespace nidevo
