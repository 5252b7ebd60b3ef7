#pragma once
// Shared by the integration tests: rendered sequences, offline reference poses, streaming.
#include <optional>
#include <string>
#include <vector>

#include "frame_encoder.hpp"
#include "nidevo/odometry/odometry.hpp"
#include "nidevo/sim/sequence.hpp"
#include "odometry_client.hpp"

namespace nidevo::test {

struct TestSequence {
  Camera camera;
  std::vector<RgbdFrame> frames;
  Trajectory ground_truth;
};

// The office scene at 320x240 (ICL intrinsics halved): quick to render, enough to track.
TestSequence renderOffice(int frames, uint64_t seed, const std::string& texture = "rich");
// What the offline pipeline (same default config) gives for these frames.
std::vector<PoseEstimate> offlinePoses(const TestSequence& sequence);

client::SessionOptions sessionFor(const Camera& camera, const client::FrameEncoding& encoding);

struct StreamResult {
  std::vector<v1::TrackResponse> responses;
  grpc::Status status;
};
// Streams every frame (sequence numbers 0..n-1) in one session and collects the answers.
StreamResult streamSequence(client::Client& client, const TestSequence& sequence,
                            const client::FrameEncoding& encoding,
                            const std::optional<Eigen::Isometry3d>& initial_pose = std::nullopt);

}  // namespace nidevo::test
