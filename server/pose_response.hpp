#pragma once
// The odometry's PoseEstimate as the API's TrackResponse.
#include <Eigen/Geometry>
#include <string>

#include "nidevo/odometry/odometry.hpp"
#include "nidevo/v1/odometry.pb.h"

namespace nidevo::server {

// Sets everything but the queue/decode/total timings, which only the session knows. The pose is
// reported as world_from_first * pose.T_world_cam (the session's initial pose, identity if none).
// `out` may hold an earlier answer: every field is overwritten (its buffers are reused).
void fillPoseResponse(const v1::Frame& frame, const PoseEstimate& pose,
                      const Eigen::Isometry3d& world_from_first, v1::TrackResponse* out);

// Empty when the config's initial pose is absent or usable, else what is wrong with it.
std::string validateInitialPose(const v1::SessionConfig& config);
// The config's initial pose (validated), identity when it has none.
Eigen::Isometry3d initialPoseOf(const v1::SessionConfig& config);

// The answer to a frame that was not processed (DROPPED or ERROR): no pose, the reason why.
v1::TrackResponse rejectionResponse(const v1::Frame& frame, v1::FrameStatus status,
                                    const std::string& reason);

}  // namespace nidevo::server
