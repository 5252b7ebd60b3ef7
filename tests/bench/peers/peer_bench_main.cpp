// nidevo-bench: this project's odometry and its peers on the same frames, in one process, frame
// to frame from an identity initial guess, default parameters (only the camera set), one thread.
#include <algorithm>
#include <cctype>
#include <chrono>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <iostream>

#include "absl/flags/flag.h"
#include "absl/strings/str_split.h"
#include "method.hpp"
#include "nidevo/cli/cli.hpp"
#include "nidevo/eval/metrics.hpp"
#include "nidevo/io/trajectory.hpp"
#include "nidevo/loader/frame_loader.hpp"
#include "report.hpp"

#if NIDEVO_HAVE_OPENCV_RGBD
#include <opencv2/core/utility.hpp>
#endif
#if NIDEVO_HAVE_OPEN3D
#include <omp.h>
#endif

NIDEVO_FLAG_HEADING("Sequences and output");
ABSL_FLAG(std::string, scenes, "office/rich/none,office/low/icl,corridor/low/icl,corner/rich/none",
          "Synthetic sequences, scene/texture/noise, comma-separated (empty: none)");
ABSL_FLAG(int, frames, 300, "Frames of each synthetic sequence");
ABSL_FLAG(uint64_t, seed, 1, "Seed of the synthetic sequences");
ABSL_FLAG(std::string, datasets, "", "TUM/ICL-NUIM folders, comma-separated");
ABSL_FLAG(std::string, camera, "auto",
          "Camera preset of a dataset folder without camera.txt (auto: the one its name implies)");
ABSL_FLAG(int, max_frames, 0, "At most this many frames of each dataset (0: all)");
ABSL_FLAG(int, frame_step, 1,
          "Every n-th frame of each dataset: the recording with the camera n times as fast "
          "(named with _xN)");
ABSL_FLAG(std::string, methods, "",
          "Methods to run, comma-separated (default: nidevo and every peer of this build)");
ABSL_FLAG(std::string, csv, "", "Write the results as CSV here");
ABSL_FLAG(std::string, json, "", "Write the results as JSON here");
ABSL_FLAG(std::string, trajectories, "",
          "Write each estimate (and the ground truth) as TUM files under this folder");

namespace {

using nidevo::bench::Method;
using nidevo::bench::MethodRun;

double percentile(std::vector<double> v, double q) {
  if (v.empty()) return 0;
  std::sort(v.begin(), v.end());
  return v[std::min(v.size() - 1, size_t(q * double(v.size() - 1) + 0.5))];
}

std::vector<nidevo::cli::SequenceSource> sequencesFromFlags() {
  std::vector<nidevo::cli::SequenceSource> out;
  for (absl::string_view item :
       absl::StrSplit(absl::GetFlag(FLAGS_scenes), ',', absl::SkipEmpty())) {
    const std::vector<std::string> parts = absl::StrSplit(item, '/');
    if (parts.size() != 3)
      throw std::invalid_argument("--scenes: '" + std::string(item) +
                                  "' is not scene/texture/noise");
    nidevo::cli::SequenceSource src;
    src.scene = parts[0];
    src.texture = parts[1];
    src.noise = parts[2];
    src.frames = absl::GetFlag(FLAGS_frames);
    src.seed = absl::GetFlag(FLAGS_seed);
    out.push_back(src);
  }
  for (absl::string_view dir :
       absl::StrSplit(absl::GetFlag(FLAGS_datasets), ',', absl::SkipEmpty())) {
    nidevo::cli::SequenceSource src;
    src.dataset = std::string(dir);
    src.camera = absl::GetFlag(FLAGS_camera);
    src.max_frames = size_t(std::max(0, absl::GetFlag(FLAGS_max_frames)));
    src.frame_step = size_t(std::max(0, absl::GetFlag(FLAGS_frame_step)));  // 0: refused
    out.push_back(src);
  }
  return out;
}

std::vector<std::unique_ptr<Method>> methodsFromFlags() {
  std::vector<std::unique_ptr<Method>> all;
  all.push_back(nidevo::bench::makeNidevo());
  for (auto& peer : nidevo::bench::makePeers()) all.push_back(std::move(peer));
  const std::string wanted = absl::GetFlag(FLAGS_methods);
  if (wanted.empty()) return all;
  std::vector<std::unique_ptr<Method>> chosen;
  for (absl::string_view name : absl::StrSplit(wanted, ',', absl::SkipEmpty())) {
    auto it =
        std::find_if(all.begin(), all.end(), [&](const auto& m) { return m && m->name() == name; });
    if (it == all.end())
      throw std::invalid_argument("--methods: no method '" + std::string(name) + "' in this build");
    chosen.push_back(std::move(*it));
  }
  return chosen;
}

// A dataset is named by its folder's last component, and _xN when every N-th frame was used.
std::string displayName(const nidevo::cli::LoadedSequence& seq) {
  const std::filesystem::path path(seq.name);
  if (!std::filesystem::is_directory(path)) return seq.name;
  const std::string folder = path.filename().string();
  return seq.frame_step > 1 ? folder + "_x" + std::to_string(seq.frame_step) : folder;
}

// A file-system-safe tag of a sequence's name.
std::string tagOf(const std::string& name) {
  std::string tag;
  for (char c : name) tag += std::isalnum(static_cast<unsigned char>(c)) ? c : '_';
  return tag;
}

MethodRun runMethod(Method& method, const nidevo::cli::LoadedSequence& seq) {
  method.start(seq.camera);
  nidevo::Trajectory estimate;
  std::vector<bool> good;
  std::vector<double> ms;
  MethodRun run;
  run.sequence = displayName(seq);
  run.method = method.name();
  run.frames = seq.frames.size();
  for (const auto& frame : seq.frames) {
    const auto t0 = std::chrono::steady_clock::now();
    const nidevo::bench::Step step = method.track(frame);
    ms.push_back(
        std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - t0).count());
    estimate.push_back(nidevo::StampedPose::fromPose(frame.timestamp, step.T_world_cam));
    good.push_back(step.reported_good);
    run.failures += !step.reported_good;
  }
  // The loader gives ground truth the frames' own timestamps: matching is exact.
  const auto matched = nidevo::matchByTimestamp(estimate, seq.ground_truth, 0.005);
  run.ate_rmse_m = nidevo::computeAte(matched).translation.rmse;
  const auto rpe = nidevo::computeRpe(matched, 1);
  run.rpe_translation_rmse_m = rpe.translation.rmse;
  run.rpe_rotation_rmse_deg = rpe.rotation.rmse;
  run.silent_failures =
      nidevo::countSilentFailures(estimate, good, seq.ground_truth, 2.0, 0.05, 0.005).count;
  run.median_ms = percentile(ms, 0.5);
  run.p95_ms = percentile(ms, 0.95);
  const std::string dir = absl::GetFlag(FLAGS_trajectories);
  if (!dir.empty()) {
    const std::filesystem::path folder = std::filesystem::path(dir) / tagOf(run.sequence);
    std::filesystem::create_directories(folder);
    nidevo::writeTumTrajectory((folder / (run.method + ".txt")).string(), estimate);
    nidevo::writeTumTrajectory((folder / "groundtruth.txt").string(), seq.ground_truth);
  }
  return run;
}

void writeFile(const std::string& path, const std::string& text) {
  std::ofstream out(path);
  out << text;
  if (!out) throw std::runtime_error(path + ": cannot write");
}

}  // namespace

int main(int argc, char** argv) {
  // One thread for every method.
#if NIDEVO_HAVE_OPENCV_RGBD
  cv::setNumThreads(1);
#endif
#if NIDEVO_HAVE_OPEN3D
  omp_set_num_threads(1);
#endif
  const auto args = nidevo::cli::init(
      argc, argv,
      "Runs NIDEVO and the peer RGB-D odometries of this build (OpenCV-contrib rgbd, Open3D) on "
      "the "
      "same frames: ATE, RPE, failures each method reports, silent failures (reported good but "
      "over 2 deg or 5 cm off since the previous frame), time per frame on one thread.\n"
      "Usage: nidevo-bench [--scenes office/rich/none,...] [--datasets DIR,...] [--csv out.csv]");
  if (!args.empty()) return nidevo::cli::usageError("unexpected argument '" + args[0] + "'");
  try {
    auto methods = methodsFromFlags();
    std::vector<MethodRun> runs;
    for (const auto& source : sequencesFromFlags()) {
      const auto seq = nidevo::cli::loadSequence(source);
      if (seq.ground_truth.empty()) throw std::runtime_error(seq.name + ": no ground truth");
      std::vector<MethodRun> these;
      for (auto& method : methods) these.push_back(runMethod(*method, seq));
      std::cout << nidevo::bench::formatTable(these) << std::endl;
      runs.insert(runs.end(), these.begin(), these.end());
    }
    std::cout << "summary over " << runs.size() / std::max<size_t>(1, methods.size())
              << " sequences\n"
              << nidevo::bench::formatSummary(runs);
    if (!absl::GetFlag(FLAGS_csv).empty())
      writeFile(absl::GetFlag(FLAGS_csv), nidevo::bench::formatCsv(runs));
    if (!absl::GetFlag(FLAGS_json).empty())
      writeFile(absl::GetFlag(FLAGS_json), nidevo::bench::formatJson(runs));
  } catch (const std::exception& e) {
    std::cerr << "nidevo-bench: " << e.what() << "\n";
    return 1;
  }
  return 0;
}
