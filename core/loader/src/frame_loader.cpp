#include "nidevo/loader/frame_loader.hpp"

#include <algorithm>
#include <atomic>
#include <exception>
#include <filesystem>
#include <mutex>
#include <stdexcept>
#include <thread>
#include <utility>

#include "nidevo/io/camera_io.hpp"
#include "nidevo/io/dataset.hpp"
#include "nidevo/sim/sequence.hpp"

namespace nidevo::cli {

namespace {

template <typename Fn>
void parallelFor(size_t n, Fn&& fn) {
  const size_t workers = std::max(1u, std::thread::hardware_concurrency());
  std::atomic<size_t> next{0};
  std::exception_ptr error;
  std::mutex error_mutex;
  std::vector<std::thread> threads;
  for (size_t w = 0; w < workers; ++w) {
    threads.emplace_back([&] {
      for (size_t i = next++; i < n; i = next++) {
        try {
          fn(i);
        } catch (...) {
          std::lock_guard<std::mutex> lock(error_mutex);
          if (!error) error = std::current_exception();
        }
      }
    });
  }
  for (auto& t : threads) t.join();
  if (error) std::rethrow_exception(error);
}

}  // namespace

namespace {

Camera presetNamed(const std::string& name) {
  auto preset = cameraPreset(name);
  if (!preset) {
    throw std::invalid_argument("unknown camera preset '" + name + "' (" + cameraPresetNames() +
                                ")");
  }
  return *preset;
}

// A synthetic scene's preset: the one asked for, icl for "auto".
std::string scenePresetName(const SequenceSource& src) {
  return src.camera == kAutoCamera ? "icl" : src.camera;
}

// The camera of a dataset folder without camera.txt (TumDataset reads that file itself): the
// preset asked for, else the preset its name implies. A wrong guess here gives wrong poses that
// look right (ICL's fy < 0 mirrors the scene), so with nothing to go on this refuses rather
// than guesses.
std::pair<Camera, std::string> datasetPreset(const std::string& folder, const std::string& asked) {
  const std::filesystem::path file = std::filesystem::path(folder) / "camera.txt";
  if (asked != kAutoCamera) return {presetNamed(asked), "preset " + asked + " (--camera)"};
  const auto implied = cameraPresetForFolderName(folder);
  if (!implied) {
    throw std::invalid_argument(
        folder +
        ": no camera.txt, and the folder's name names no known camera "
        "(freiburg1/fr1, freiburg2/fr2, freiburg3/fr3, icl/living_room/office_room): "
        "pass --camera (" +
        cameraPresetNames() + ") or write " + file.string());
  }
  return {presetNamed(*implied), "preset " + *implied + " (from the folder's name)"};
}

}  // namespace

synth::SequenceConfig syntheticSequenceConfig(const SequenceSource& src) {
  synth::SequenceConfig config;
  config.scene = src.scene;
  config.texture = synth::parseTextureRichness(src.texture);
  config.noise = synth::parseSensorNoise(src.noise);
  config.frames = int(src.max_frames ? std::min<size_t>(src.max_frames, size_t(src.frames))
                                     : size_t(src.frames));
  config.seed = src.seed;
  config.speed = src.speed;
  config.camera = presetNamed(scenePresetName(src));
  return config;
}

LoadedSequence loadSequence(const SequenceSource& src) {
  LoadedSequence out;
  if (!src.dataset.empty()) {
    const std::filesystem::path file = std::filesystem::path(src.dataset) / "camera.txt";
    auto [preset, camera_source] = std::filesystem::exists(file)
                                       ? std::pair(Camera{}, file.string())
                                       : datasetPreset(src.dataset, src.camera);
    if (src.frame_step < 1) throw std::invalid_argument("frame_step: must be at least 1");
    TumDataset ds(src.dataset, preset);
    const size_t step = src.frame_step;
    size_t n = (ds.size() + step - 1) / step;
    if (src.max_frames) n = std::min(n, src.max_frames);
    out.name = src.dataset;
    out.camera = ds.camera();
    out.camera_source = camera_source;
    out.frame_step = step;
    out.frames.resize(n);
    parallelFor(n, [&](size_t i) { out.frames[i] = ds.loadFrame(i * step); });
    // Timestamps of the ground truth are the frames' own, so evaluation matches them exactly.
    for (size_t i = 0; i < n; ++i) {
      if (const auto& truth = ds.entry(i * step).ground_truth) {
        out.ground_truth.push_back(*truth);
        out.ground_truth.back().timestamp = out.frames[i].timestamp;
      }
    }
    return out;
  }
  const synth::SequenceConfig config = syntheticSequenceConfig(src);
  const synth::SyntheticSequence seq(config);
  out.name = src.scene + " (" + src.texture + " texture, " + src.noise + " noise)";
  out.camera = config.camera;
  out.camera_source = "preset " + scenePresetName(src);
  out.frames.resize(size_t(config.frames));
  parallelFor(out.frames.size(), [&](size_t i) { out.frames[i] = seq.renderFrame(int(i)); });
  out.ground_truth = seq.groundTruthTrajectory();
  return out;
}

}  // namespace nidevo::cli
