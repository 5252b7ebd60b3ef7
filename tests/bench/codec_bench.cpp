// What each wire encoding costs at 640x480: the client's encoding and the server's decoding
// into the odometry's grey + metric depth, and the bytes on the wire. Asserts nothing.
#include <benchmark/benchmark.h>

#include "frame_decoder.hpp"
#include "frame_encoder.hpp"
#include "nidevo/io/camera_io.hpp"
#include "nidevo/sim/sequence.hpp"

namespace nidevo {
namespace {

const char* const kEncodings[] = {"raw", "raw-f32", "png", "jpeg"};

const RgbdFrame& frame() {
  static const RgbdFrame f = [] {
    synth::SequenceConfig c;
    c.frames = 1;
    c.noise = synth::SensorNoise::kIclLike;
    return synth::SyntheticSequence(c).renderFrame(0);
  }();
  return f;
}

v1::SessionConfig sessionFor(const client::FrameEncoding& e) {
  const Camera cam = *cameraPreset("icl");
  v1::SessionConfig c;
  c.mutable_camera()->set_fx(cam.fx);
  c.mutable_camera()->set_fy(cam.fy);
  c.mutable_camera()->set_cx(cam.cx);
  c.mutable_camera()->set_cy(cam.cy);
  c.mutable_camera()->set_width(uint32_t(cam.width));
  c.mutable_camera()->set_height(uint32_t(cam.height));
  c.set_color_encoding(e.color);
  c.set_depth_encoding(e.depth);
  c.set_depth_scale(cam.depth_scale);
  return c;
}

void BM_Encode(benchmark::State& state) {
  const auto encoding = client::parseFrameEncoding(kEncodings[state.range(0)]);
  v1::Frame wire;
  for (auto _ : state) {
    client::encodeFrame(frame(), 5000, encoding, &wire);
    benchmark::DoNotOptimize(wire);
  }
  state.SetLabel(kEncodings[state.range(0)]);
  state.counters["wire_kB"] = double(wire.ByteSizeLong()) / 1000.0;
}

void BM_Decode(benchmark::State& state) {
  const auto encoding = client::parseFrameEncoding(kEncodings[state.range(0)]);
  v1::Frame wire;
  client::encodeFrame(frame(), 5000, encoding, &wire);
  server::FrameDecoder decoder(sessionFor(encoding));
  RgbdFrame out;
  for (auto _ : state) {
    const std::string error = decoder.decode(wire, &out);
    if (!error.empty()) state.SkipWithError(error.c_str());
    benchmark::DoNotOptimize(out);
  }
  state.SetLabel(kEncodings[state.range(0)]);
  state.counters["wire_kB"] = double(wire.ByteSizeLong()) / 1000.0;
}

BENCHMARK(BM_Encode)->DenseRange(0, 3)->Unit(benchmark::kMillisecond);
BENCHMARK(BM_Decode)->DenseRange(0, 3)->Unit(benchmark::kMillisecond);

}  // namespace
}  // namespace nidevo

BENCHMARK_MAIN();
