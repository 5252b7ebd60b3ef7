#pragma once
// The odometry's PoseEstimate as the API's TrackResponse.
#include "nidevo/odometry/odometry.hpp"
#include "nidevo/v1/odometry.pb.h"

namespace nidevo::server {

// Sets everything but the queue/decode/total timings, which only the session knows.
void fillPoseResponse(const v1::Frame& frame, const PoseEstimate& pose, v1::TrackResponse* out);

}  // namespace nidevo::server
