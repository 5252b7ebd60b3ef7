#pragma once
// The odometry's PoseEstimate as the API's TrackResponse.
#include <string>

#include "nidevo/odometry/odometry.hpp"
#include "nidevo/v1/odometry.pb.h"

namespace nidevo::server {

// Sets everything but the queue/decode/total timings, which only the session knows.
void fillPoseResponse(const v1::Frame& frame, const PoseEstimate& pose, v1::TrackResponse* out);

// The answer to a frame that was not processed (DROPPED or ERROR): no pose, the reason why.
v1::TrackResponse rejectionResponse(const v1::Frame& frame, v1::FrameStatus status,
                                    const std::string& reason);

}  // namespace nidevo::server
