// Accuracy on a real recording: the first 250 frames of TUM RGB-D fr1/rpy (Kinect, motion
// capture ground truth, CC BY 4.0; ../shared/data/README.md), read through the normal dataset
// reader with the tum_fr1 preset (TUM's distortion coefficients). The bounds are the figures of the
// commit that added this test, so that any regression shows; they are to be tightened as the
// odometry improves, never loosened. Peers on the same frames are in the README, "Results".
//
// Every figure here moves with the FFT's rounding: FFTW_ESTIMATE picks a different algorithm on
// another host (the same binary gave 0.0373 m on the machine of 2026-12-07 evening and 0.0421 m on
// the next session's), and each algorithm rounds differently. Since 2026-12-07 (late) each bound
// covers the spread over 15 runs with `--fft_measure` (each a timed, possibly different algorithm)
// plus this host's plan, with a margin of about 1 % of the frames for the OK counts
// (docs/accuracy.md, "How far the FFT's rounding moves the figures"). A bound that only held
// for one host's rounding guarded luck, not the method.
#include <gtest/gtest.h>
#include <unistd.h>

#include <cstdlib>
#include <filesystem>

#include "nidevo/eval/metrics.hpp"
#include "nidevo/io/camera_io.hpp"
#include "nidevo/io/dataset.hpp"
#include "nidevo/odometry/odometry.hpp"

namespace nidevo {
namespace {

std::string clipFolder() {
  if (const char* dir = std::getenv("NIDEVO_REAL_DATA")) return dir;
  return NIDEVO_SHARED_DATA "/tum_fr1_rpy_first250";
}

struct RealRun {
  double ate_rmse = 0;
  double rpe_rotation_max_deg = 0;
  int counts[3] = {0, 0, 0};
  SilentFailures silent;
};

// Every `step`-th frame: the same recording with the camera `step` times as fast.
RealRun runClip(const std::string& folder, size_t step = 1) {
  const TumDataset dataset(folder, *cameraPreset("tum_fr1"));
  Odometry odometry(dataset.camera(), OdometryConfig{});
  Trajectory estimate, reference;
  std::vector<bool> ok;
  RealRun run;
  for (size_t i = 0; i < dataset.size(); i += step) {
    const PoseEstimate p = odometry.track(dataset.loadFrame(i));
    ++run.counts[int(p.state)];
    estimate.push_back(StampedPose::fromPose(p.timestamp, p.T_world_cam));
    ok.push_back(p.state == TrackingState::kOk);
  }
  const auto matched = matchByTimestamp(estimate, dataset.groundTruth(), 0.02);
  run.ate_rmse = computeAte(matched).translation.rmse;
  run.rpe_rotation_max_deg = computeRpe(matched).rotation.max;
  run.silent = countSilentFailures(estimate, ok, dataset.groundTruth(), 2.0, 0.05, 0.02);
  std::printf(
      "tum fr1/rpy, every %zu of %zu frames: ATE RMSE %.4f m, RPE rotation max %.1f deg; %d OK, %d "
      "DEGRADED, "
      "%d LOST; silent failures %d of %d OK frames\n",
      step, dataset.size(), run.ate_rmse, run.rpe_rotation_max_deg, run.counts[0], run.counts[1],
      run.counts[2], run.silent.count, run.silent.judged);
  return run;
}

TEST(RealData, TumFr1RpyNoWorseThanTheRecordedBaseline) {
  const std::string folder = clipFolder();
  if (!std::filesystem::is_directory(folder))
    GTEST_SKIP() << folder << " not found (set NIDEVO_REAL_DATA to the clip's folder)";
  const RealRun run = runClip(folder);
  // Baseline of 2026-12-01 (before the robust-odometry work): ATE 1.646 m; 19 OK frames, 18 of
  // them judged, 4 of those silent failures. With the pose check: ATE 0.079 m, 249 OK, 3 silent;
  // with the KCC prior and jumps along unmeasured directions not OK: 0.042 m, 243 OK, 2 silent.
  // With the grey-value polish and the hypothesis rules: 0.0383 m, 246 OK, 2 silent. With the
  // grey-depth gap rule (2026-12-04): 0.0373 m, 232 OK, 0 silent; the OK bound keeps the rule
  // from buying honesty with caution. Since the frame after one out of step is DEGRADED too
  // (2026-12-06; the poses unchanged): 229 OK, the 4 frames it took off OK 0.5-2.0 deg off their
  // previous frame (the OK frames: median 0.38 deg), one of them 2.00 deg. Since two hypotheses
  // that fit alike further apart than OK allows are not OK (2026-12-07, ok_needs_hypotheses_to_
  // agree; the poses unchanged): 216 OK, the 13 frames it took off OK 0.52 deg and 5.1 mm off at
  // the median (the OK frames: 0.38 deg and 3.1 mm), and the OK frames' p95 0.91 to 0.86 deg.
  // The best peer (OpenCV RgbdICPOdometry) gets 0.0409 m on these frames. The bound was the
  // peer's until the FFT's rounding was measured: over 16 runs with different FFT plans the ATE is
  // 0.0379 to 0.0433 m (the peer beaten in 11) and 212 to 217 frames are OK, never a silent one.
  EXPECT_LE(run.ate_rmse, 0.045);
  EXPECT_EQ(run.silent.count, 0);
  EXPECT_GE(run.counts[0], 210);
  EXPECT_LT(run.rpe_rotation_max_deg, 5.0);  // no frame's motion off by more than 5 deg
  EXPECT_EQ(run.counts[0] + run.counts[1] + run.counts[2], 250);
}

// The same recording two and three times as fast (every 2nd and 3rd frame: up to 11 and 16 deg
// per frame), which no setting was chosen on. Bounds: the figures of the commit that added this
// test (2026-12-04: 0.0439 m with 2 silent failures of 100 OK frames, and 0.0919 m with 1 of
// 50; since unverified frames that depth fixes keep the motion, 0.0421 m and 0.0934 m; since the
// grey-depth gap rule, no silent failure at either speed, 97 and 51 frames OK; since
// ok_needs_hypotheses_to_agree, 93 and 49; over 7 and 12 runs with different FFT plans
// 0.0389-0.0438 m with 94-101 OK, and 0.0706-0.0711 m with 43-46 OK, at most 6.52 deg, never a
// silent failure); the best peers measured on the same frames, OpenCV's ICPOdometry: 0.054 m (7
// silent) and 0.077 m (14 silent), docs/accuracy.md "How we compare".
TEST(RealData, TumFr1RpyTwiceAndThreeTimesAsFastNoWorseThanTheRecordedBaseline) {
  const std::string folder = clipFolder();
  if (!std::filesystem::is_directory(folder))
    GTEST_SKIP() << folder << " not found (set NIDEVO_REAL_DATA to the clip's folder)";
  const RealRun twice = runClip(folder, 2);
  EXPECT_LE(twice.ate_rmse, 0.046);
  EXPECT_EQ(twice.silent.count, 0);
  EXPECT_GE(twice.counts[0], 92);
  EXPECT_EQ(twice.counts[0] + twice.counts[1] + twice.counts[2], 125);
  const RealRun thrice = runClip(folder, 3);
  // 0.0934 m until coarse to fine's gate grew with its levels' pixels (align_coarse_gate_growth),
  // which took frame 18's error from 10.5 to 1.4 deg and changed no other frame's by more than
  // 0.1 deg, for all that moved the ATE to 0.0979 m (the old error had offset drift elsewhere):
  // the largest frame error is the sharper guard (docs/accuracy.md, "Coarse to fine with a gate
  // that grows with the level").
  EXPECT_LE(thrice.ate_rmse, 0.100);
  EXPECT_LT(thrice.rpe_rotation_max_deg, 7.0);
  EXPECT_EQ(thrice.silent.count, 0);
  EXPECT_GE(thrice.counts[0], 42);
  EXPECT_EQ(thrice.counts[0] + thrice.counts[1] + thrice.counts[2], 84);
}

// The same recording played backwards (scripts/reverse_tum.py: the frames in reverse order, time
// mirrored), as recorded, twice and three times as fast: other frame pairs, every motion reversed,
// and no setting chosen on them. Bounds: the best peer's ATE on the same frames (OpenCV
// RgbdICPOdometry 0.0458 m as recorded, RgbdOdometry 0.0620 m twice as fast; `nidevo-bench
// --scenes "" --datasets build/tum_fr1_rpy_reversed --frame_step N`) and no silent failure, the
// figures of the commit that added the test (0.0436 m and 0.0457 m; 219 and 85 frames OK, 209
// and 84 since ok_needs_hypotheses_to_agree).
TEST(RealData, TumFr1RpyPlayedBackwardsNoWorseThanTheBestPeer) {
  const std::string folder = clipFolder();
  if (!std::filesystem::is_directory(folder))
    GTEST_SKIP() << folder << " not found (set NIDEVO_REAL_DATA to the clip's folder)";
  const std::filesystem::path reversed =
      std::filesystem::temp_directory_path() / ("nidevo_reversed_" + std::to_string(getpid()));
  const std::string command =
      "python3 '" NIDEVO_REVERSE_TUM "' '" + folder + "' '" + reversed.string() + "'";
  ASSERT_EQ(std::system(command.c_str()), 0) << command;
  const RealRun once = runClip(reversed.string());
  const RealRun twice = runClip(reversed.string(), 2);
  const RealRun thrice = runClip(reversed.string(), 3);
  std::filesystem::remove_all(reversed);
  // Over 7 runs with different FFT plans: 0.0421-0.0430 m with 209-213 OK; in 4 of them frame 208
  // is OK and 5.2 cm off; in one of the others it is OK and 4.5 cm off: a silent failure that the
  // rounding decides, open in docs/accuracy.md. Twice as fast: 0.0454-0.0457 m, 84-86 OK, never
  // silent.
  EXPECT_LE(once.ate_rmse, 0.0458);
  EXPECT_LE(once.silent.count, 1);
  EXPECT_GE(once.counts[0], 207);
  EXPECT_LE(twice.ate_rmse, 0.0620);
  EXPECT_EQ(twice.silent.count, 0);
  EXPECT_GE(twice.counts[0], 83);
  // Three times as fast: 0.1947 m until coarse to fine's gate grew with its levels' pixels, then
  // 0.0750 m with 61 frames OK, 57 since ok_needs_hypotheses_to_agree (the best peer,
  // RgbdICPOdometry: 0.0650 m); over 7 FFT plans 0.0749-0.0766 m with 55 OK. Its one
  // silent failure (frame 49, 2.1 deg) is open (docs/accuracy.md).
  EXPECT_LE(thrice.ate_rmse, 0.080);
  EXPECT_LE(thrice.silent.count, 1);
  EXPECT_GE(thrice.counts[0], 54);
}

}  // namespace
}  // namespace nidevo
