// nidevo-run: offline odometry on a TUM/ICL-NUIM folder or a synthetic scene.
#include <algorithm>
#include <chrono>
#include <cstdio>
#include <iostream>
#include <stdexcept>

#include "absl/flags/flag.h"
#include "nidevo/cli/cli.hpp"
#include "nidevo/cli/odometry_flags.hpp"
#include "nidevo/eval/evaluation_report.hpp"
#include "nidevo/eval/metrics.hpp"
#include "nidevo/loader/frame_loader.hpp"
#include "nidevo/loader/sequence_flags.hpp"
#include "nidevo/odometry/odometry.hpp"
#include "nidevo/odometry/pipeline.hpp"

ABSL_FLAG(int, threads, 1, "1: all stages on one thread; 3: the three-stage pipeline");
ABSL_FLAG(std::string, out, "", "Write the estimated trajectory (TUM format) here");
ABSL_FLAG(std::string, plot, "", "Write a PNG plot against ground truth here");
ABSL_FLAG(std::string, frames_csv, "",
          "Write one CSV row per frame here: state, reason, rotation source, PSR, the pose "
          "check's figures and, with ground truth, the frame-to-frame error");

namespace {

double median(std::vector<double> v) {
  if (v.empty()) return 0;
  std::nth_element(v.begin(), v.begin() + long(v.size() / 2), v.end());
  return v[v.size() / 2];
}

// Rate, stage medians and tracking counts of a run; returns the estimated trajectory.
nidevo::Trajectory printSummary(const std::vector<nidevo::PoseEstimate>& poses, double secs,
                                int threads) {
  nidevo::Trajectory estimate;
  std::vector<double> t_normals, t_rotation, t_translation;
  int counts[3] = {0, 0, 0}, rot_keys = 0, trans_keys = 0;
  std::vector<double> psr;
  for (const auto& p : poses) {
    estimate.push_back(nidevo::StampedPose::fromPose(p.timestamp, p.T_world_cam));
    t_normals.push_back(p.times.normals_s);
    t_rotation.push_back(p.times.rotation_s);
    t_translation.push_back(p.times.translation_s);
    ++counts[int(p.state)];
    rot_keys += p.rotation_keyframe;
    trans_keys += p.translation_keyframe;
    if (p.psr > 0) psr.push_back(p.psr);
  }
  std::printf("odometry: %zu frames in %.3f s = %.1f frames/s (%d thread%s)\n", poses.size(), secs,
              double(poses.size()) / secs, threads, threads > 1 ? "s" : "");
  std::printf("stage medians: normals %.2f ms, rotation %.2f ms, translation %.2f ms\n",
              1e3 * median(t_normals), 1e3 * median(t_rotation), 1e3 * median(t_translation));
  std::printf(
      "tracking: %d OK, %d DEGRADED, %d LOST; keyframes: %d rotation, %d translation; "
      "median PSR %.1f\n",
      counts[0], counts[1], counts[2], rot_keys, trans_keys, median(psr));
  return estimate;
}

// One row per frame; the error columns are empty without ground truth or for unjudged frames.
void writeFramesCsv(const std::string& path, const std::vector<nidevo::PoseEstimate>& poses,
                    const std::vector<nidevo::FrameError>& errors) {
  FILE* f = std::fopen(path.c_str(), "w");
  if (!f) throw std::runtime_error("cannot write " + path);
  std::fprintf(
      f,
      "frame,timestamp,state,reason,rotation_source,planes,psr,kcc_rivals,kcc_ridge_u,kcc_ridge_v,"
      "hypothesis,"
      "inlier_fraction,overlap_fraction,residual_rms_m,ncc,constrained,depth_constrained,confirmed,"
      "predicted,grey_depth_gap_deg,grey_depth_gap_m,sigma_rotation_deg,sigma_translation_m,"
      "normal_noise_deg,depth_eigenvalues,eigenvalues,rotation_error_deg,translation_error_m\n");
  for (size_t i = 0; i < poses.size(); ++i) {
    const auto& p = poses[i];
    const auto& v = p.verification;
    std::fprintf(
        f,
        "%llu,%.6f,%s,\"%s\",%s,%d,%.2f,%d,%.3f,%.3f,%s,%.4f,%.4f,%.5f,%.4f,%d,%d,%d,%d,%."
        "4f,%.5f,%.5f,%.6f,%.3f,\"%.5f;%.5f;%.5f;%.5f;%.5f;%.5f\",\"%.5f;%.5f;%.5f;%.5f;%.5f;%."
        "5f\",",
        (unsigned long long)p.frame_index, p.timestamp, nidevo::toString(p.state), p.reason,
        nidevo::toString(p.rotation_source), p.planes_used, p.psr, p.kcc_rival_peaks, p.kcc_ridge_u,
        p.kcc_ridge_v, v.hypothesis, v.inlier_fraction, v.overlap_fraction, v.residual_rms_m, v.ncc,
        v.constrained_directions, v.depth_constrained_directions, v.confirmed_directions,
        int(v.predicted_directions), v.grey_depth_gap_deg, v.grey_depth_gap_m, v.sigma_rotation_deg,
        v.sigma_translation_m, v.normal_noise_deg, v.depth_eigenvalues[0], v.depth_eigenvalues[1],
        v.depth_eigenvalues[2], v.depth_eigenvalues[3], v.depth_eigenvalues[4],
        v.depth_eigenvalues[5], v.eigenvalues[0], v.eigenvalues[1], v.eigenvalues[2],
        v.eigenvalues[3], v.eigenvalues[4], v.eigenvalues[5]);
    if (i < errors.size() && errors[i].judged)
      std::fprintf(f, "%.4f,%.5f\n", errors[i].rotation_deg, errors[i].translation_m);
    else
      std::fprintf(f, ",\n");
  }
  std::fclose(f);
}

}  // namespace

int main(int argc, char** argv) {
  auto args = nidevo::cli::init(
      argc, argv,
      "Runs NIDEVO odometry offline on a TUM/ICL-NUIM folder or a synthetic scene, writes the "
      "trajectory, prints the rate and, with ground truth, the ATE.\n"
      "Usage: nidevo-run [--dataset DIR | --scene office --texture rich --noise none] "
      "[--out traj.txt] [--threads 3]");
  if (!args.empty()) return nidevo::cli::usageError("unexpected argument '" + args[0] + "'");
  const int threads = absl::GetFlag(FLAGS_threads);
  if (threads != 1 && threads != 3) return nidevo::cli::usageError("--threads must be 1 or 3");
  try {
    const nidevo::OdometryConfig config = nidevo::cli::odometryConfigFromFlags();
    const nidevo::cli::SequenceSource src = nidevo::cli::sequenceSourceFromFlags();
    const auto load_start = std::chrono::steady_clock::now();
    const auto seq = nidevo::cli::loadSequence(src);
    const double load_s =
        std::chrono::duration<double>(std::chrono::steady_clock::now() - load_start).count();
    std::printf("sequence: %s, %zu frames %dx%d, camera %s (loaded in %.1f s)\n", seq.name.c_str(),
                seq.frames.size(), seq.camera.width, seq.camera.height, seq.camera_source.c_str(),
                load_s);

    nidevo::Odometry odometry(seq.camera, config);
    auto source = [&](size_t i) -> const nidevo::RgbdFrame& { return seq.frames[i]; };
    const auto start = std::chrono::steady_clock::now();
    const auto poses = threads == 3 ? nidevo::runPipelined(odometry, seq.frames.size(), source)
                                    : nidevo::runSequential(odometry, seq.frames.size(), source);
    const double secs =
        std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();

    const nidevo::Trajectory estimate = printSummary(poses, secs, threads);
    const std::string out = absl::GetFlag(FLAGS_out);
    if (!out.empty()) {
      nidevo::writeTumTrajectory(out, estimate);
      std::printf("trajectory written to %s\n", out.c_str());
    }
    const std::string frames_csv = absl::GetFlag(FLAGS_frames_csv);
    if (!frames_csv.empty()) {
      writeFramesCsv(frames_csv, poses,
                     seq.ground_truth.empty()
                         ? std::vector<nidevo::FrameError>{}
                         : nidevo::frameToFrameErrors(estimate, seq.ground_truth, 0.005));
      std::printf("per-frame figures written to %s\n", frames_csv.c_str());
    }
    if (!seq.ground_truth.empty()) {
      std::printf("\n");
      nidevo::cli::printEvaluation(estimate, seq.ground_truth, 0.005, 1, absl::GetFlag(FLAGS_plot),
                                   seq.name + ": ");
      std::vector<bool> ok;
      for (const auto& p : poses) ok.push_back(p.state == nidevo::TrackingState::kOk);
      const auto silent =
          nidevo::countSilentFailures(estimate, ok, seq.ground_truth, 2.0, 0.05, 0.005);
      std::printf(
          "silent failures (OK, but over 2 deg or 5 cm off since the previous frame): %d of %d "
          "OK frames\n",
          silent.count, silent.judged);
    }
  } catch (const std::exception& e) {
    std::cerr << "nidevo-run: " << e.what() << "\n";
    return 1;
  }
  return 0;
}
