#pragma once
// Flags shared by the nidevo-client subcommands: connection, encoding, overload policy.
#include <string>

#include "frame_encoder.hpp"
#include "odometry_client.hpp"

namespace nidevo::client {

ChannelOptions channelOptionsFromFlags();
FrameEncoding frameEncodingFromFlags();
std::string encodingName();
// Camera from the sequence; encodings, overload policy and queue capacity from the flags.
SessionOptions sessionOptionsFromFlags(const Camera& camera);

}  // namespace nidevo::client
