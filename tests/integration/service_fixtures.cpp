#include "service_fixtures.hpp"

#include "nidevo/io/camera_io.hpp"
#include "nidevo/odometry/pipeline.hpp"

namespace nidevo::test {

TestSequence renderOffice(int frames, uint64_t seed, const std::string& texture) {
  synth::SequenceConfig config;
  config.scene = "office";
  config.texture = synth::parseTextureRichness(texture);
  config.frames = frames;
  config.seed = seed;
  config.camera = cameraPreset("icl")->subsampled(2);
  synth::SyntheticSequence sequence(config);
  TestSequence out;
  out.camera = config.camera;
  for (int i = 0; i < frames; ++i) out.frames.push_back(sequence.renderFrame(i));
  out.ground_truth = sequence.groundTruthTrajectory();
  return out;
}

std::vector<PoseEstimate> offlinePoses(const TestSequence& sequence) {
  Odometry odometry(sequence.camera, OdometryConfig{});
  return runSequential(odometry, sequence.frames.size(),
                       [&](size_t i) -> const RgbdFrame& { return sequence.frames[i]; });
}

client::SessionOptions sessionFor(const Camera& camera, const client::FrameEncoding& encoding) {
  client::SessionOptions options;
  options.camera = camera;
  options.color_encoding = encoding.color;
  options.depth_encoding = encoding.depth;
  options.client_name = "integration-test";
  return options;
}

StreamResult streamSequence(client::Client& client, const TestSequence& sequence,
                            const client::FrameEncoding& encoding,
                            const std::optional<Eigen::Isometry3d>& initial_pose) {
  StreamResult result;
  client::SessionOptions options = sessionFor(sequence.camera, encoding);
  options.initial_pose = initial_pose;
  auto session =
      client.open(options, [&](const v1::TrackResponse& r) { result.responses.push_back(r); });
  v1::Frame frame;
  for (size_t i = 0; i < sequence.frames.size(); ++i) {
    client::encodeFrame(sequence.frames[i], sequence.camera.depth_scale, encoding, &frame);
    frame.set_sequence(i);
    if (!session->send(frame)) break;
  }
  result.status = session->finish();
  return result;
}

}  // namespace nidevo::test
