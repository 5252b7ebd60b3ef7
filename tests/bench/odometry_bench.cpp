// Per-stage and whole-frame cost of the odometry on one thread (640x480, and the whole frame at
// 320x240 and 1280x720 too). Reports medians over repetitions; asserts nothing about time.
#include <benchmark/benchmark.h>

#include <chrono>

#include "nidevo/io/camera_io.hpp"
#include "nidevo/odometry/odometry.hpp"
#include "nidevo/sim/sequence.hpp"

namespace nidevo {
namespace {

// The low-texture, noisy office: `count` frames seen by `camera`.
std::vector<RgbdFrame> renderOffice(int count, const Camera& camera) {
  synth::SequenceConfig c;
  c.frames = count;
  c.texture = synth::TextureRichness::kLow;
  c.noise = synth::SensorNoise::kIclLike;
  c.camera = camera;
  const synth::SyntheticSequence seq(c);
  std::vector<RgbdFrame> out;
  for (int i = 0; i < seq.size(); ++i) out.push_back(seq.renderFrame(i));
  return out;
}

const Camera& camera() {
  static const Camera c = *cameraPreset("icl");
  return c;
}

// Frame k of going back and forth through `sequence`, so that the motion stays smooth for any
// iteration count.
const RgbdFrame& backAndForth(const std::vector<RgbdFrame>& sequence, size_t k) {
  const size_t n = sequence.size(), period = 2 * (n - 1), i = k % period;
  return sequence[i < n ? i : period - i];
}

// The office at 640x480, rendered once per process.
const RgbdFrame& frameAt(size_t k) {
  static const std::vector<RgbdFrame> office = renderOffice(40, camera());
  return backAndForth(office, k);
}

void BM_WholeFrame(benchmark::State& state) {
  Odometry odometry(camera(), OdometryConfig{});
  size_t k = 0;
  for (; k < 10; ++k) odometry.track(frameAt(k));
  for (auto _ : state) benchmark::DoNotOptimize(odometry.track(frameAt(k++)));
  state.SetItemsProcessed(int64_t(state.iterations()));
}
BENCHMARK(BM_WholeFrame)->Unit(benchmark::kMillisecond);

// The ICL camera scaled to width x height (the field of view kept across the width).
Camera cameraOfSize(int width, int height) {
  Camera c = camera();
  const double s = double(width) / c.width;
  c.fx *= s;
  c.fy *= s;
  c.cx = 0.5 * (width - 1);
  c.cy = 0.5 * (height - 1);
  c.width = width;
  c.height = height;
  return c;
}

// The same office at another input size: does the cost grow with the pixel count?
void BM_WholeFrameAtSize(benchmark::State& state) {
  const Camera sized_camera = cameraOfSize(int(state.range(0)), int(state.range(1)));
  const std::vector<RgbdFrame> sized = renderOffice(20, sized_camera);
  Odometry odometry(sized_camera, OdometryConfig{});
  size_t k = 0;
  for (; k < 10; ++k) odometry.track(backAndForth(sized, k));
  for (auto _ : state) benchmark::DoNotOptimize(odometry.track(backAndForth(sized, k++)));
  state.counters["pixels"] = double(state.range(0) * state.range(1));
}
BENCHMARK(BM_WholeFrameAtSize)
    ->Args({320, 240})
    ->Args({640, 480})
    ->Args({1280, 720})
    ->Unit(benchmark::kMillisecond);

// The stages are timed inside one tracking loop (each needs the previous ones' state), with
// manual timing of the stage under test.
template <int kStage>
void BM_Stage(benchmark::State& state) {
  Odometry odometry(camera(), OdometryConfig{});
  FrameState frame_state;
  size_t k = 0;
  auto step = [&](int timed) {
    frame_state.frame_index = k;
    const RgbdFrame& f = frameAt(k++);
    double seconds = 0;
    auto time = [&](int stage, auto&& fn) {
      const auto t0 = std::chrono::steady_clock::now();
      fn();
      if (stage == timed)
        seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
    };
    time(0, [&] { odometry.computeNormals(f, &frame_state); });
    time(1, [&] { odometry.estimateRotation(&frame_state); });
    time(2, [&] { benchmark::DoNotOptimize(odometry.estimateTranslation(&frame_state)); });
    return seconds;
  };
  for (int i = 0; i < 10; ++i) step(-1);
  for (auto _ : state) state.SetIterationTime(step(kStage));
}
BENCHMARK_TEMPLATE(BM_Stage, 0)
    ->Name("BM_Stage1_NormalMap")
    ->UseManualTime()
    ->Unit(benchmark::kMillisecond);
BENCHMARK_TEMPLATE(BM_Stage, 1)
    ->Name("BM_Stage2_Rotation")
    ->UseManualTime()
    ->Unit(benchmark::kMillisecond);
BENCHMARK_TEMPLATE(BM_Stage, 2)
    ->Name("BM_Stage3_Translation")
    ->UseManualTime()
    ->Unit(benchmark::kMillisecond);

void BM_KccMatch(benchmark::State& state) {
  const int w = int(state.range(0)), h = int(state.range(1));
  KernelCrossCorrelator kcc(w, h, 1, 0.2, 0.1, 2.0);
  std::vector<float> image(size_t(w) * size_t(h));
  for (size_t i = 0; i < image.size(); ++i) image[i] = float((i * 2654435761u) % 1000) / 1000.f;
  const float* channels[] = {image.data()};
  kcc.train(channels);
  for (auto _ : state) benchmark::DoNotOptimize(kcc.match(channels, true, 5));
}
BENCHMARK(BM_KccMatch)->Args({320, 240})->Args({480, 360})->Unit(benchmark::kMillisecond);

}  // namespace
}  // namespace nidevo

BENCHMARK_MAIN();
