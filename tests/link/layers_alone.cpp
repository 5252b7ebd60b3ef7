// One program per library (NIDEVO_LAYER picks which), each linked against that library alone:
// a library that calls into one it does not link fails to build here.
#include <cstdio>
#include <string>

#if NIDEVO_LAYER_IO
#include "nidevo/io/camera_io.hpp"
#include "nidevo/io/dataset.hpp"
#include "nidevo/io/trajectory.hpp"
#elif NIDEVO_LAYER_SIM
#include "nidevo/sim/sequence.hpp"
#elif NIDEVO_LAYER_EVAL
#include "nidevo/eval/metrics.hpp"
#elif NIDEVO_LAYER_CLI
#include "nidevo/cli/cli.hpp"
#include "nidevo/cli/odometry_flags.hpp"
#elif NIDEVO_LAYER_LOADER
#include "nidevo/loader/frame_loader.hpp"
#endif

int main(int argc, char** argv) {
#if NIDEVO_LAYER_IO
  (void)argc, (void)argv;
  try {
    nidevo::TumDataset missing("/nonexistent-nidevo-folder");
    return 1;
  } catch (const std::exception&) {
  }
  nidevo::StampedPose pose;
  std::printf("io alone: %s; %s\n", nidevo::cameraPresetNames().c_str(),
              nidevo::formatTumLine(pose).c_str());
  return nidevo::cameraPreset("tum_fr1") ? 0 : 1;
#elif NIDEVO_LAYER_SIM
  (void)argc, (void)argv;
  nidevo::synth::SequenceConfig config;
  config.frames = 2;
  config.camera = config.camera.subsampled(4);
  const nidevo::synth::SyntheticSequence sequence(config);
  const nidevo::RgbdFrame frame = sequence.renderFrame(1);
  std::printf("sim alone: rendered %dx%d\n", frame.depth.width, frame.depth.height);
  return frame.depth.empty() ? 1 : 0;
#elif NIDEVO_LAYER_EVAL
  (void)argc, (void)argv;
  nidevo::Trajectory a;
  for (int i = 0; i < 5; ++i) {
    nidevo::StampedPose p;
    p.timestamp = i;
    p.translation = {0.1 * i, 0, 0};
    a.push_back(p);
  }
  const auto ate = nidevo::computeAte(nidevo::matchByTimestamp(a, a));
  std::printf("eval alone: ATE of a trajectory against itself %.9f m\n", ate.translation.rmse);
  return ate.translation.rmse < 1e-9 ? 0 : 1;
#elif NIDEVO_LAYER_CLI
  nidevo::cli::init(argc, argv, "layers_alone");
  const nidevo::OdometryConfig config = nidevo::cli::odometryConfigFromFlags();
  std::printf("cli alone: cell_size %d\n", config.cell_size);
  // The flags' defaults (printed as short decimals) read back to the config's own floats.
  const nidevo::OdometryConfig d;
  const bool same_floats =
      config.align_confirm_eigenvalue == d.align_confirm_eigenvalue &&
      config.align_confirm_step_m == d.align_confirm_step_m &&
      config.align_converged_m == d.align_converged_m && config.align_join_m == d.align_join_m &&
      config.align_min_eigenvalue == d.align_min_eigenvalue &&
      config.align_photometric_weight == d.align_photometric_weight &&
      config.kcc_label_sigma == d.kcc_label_sigma && config.kcc_prior_ratio == d.kcc_prior_ratio &&
      config.min_plane_fraction == d.min_plane_fraction &&
      config.projection_border_fade == d.projection_border_fade &&
      config.psr_bound == d.psr_bound && config.reference_min_overlap == d.reference_min_overlap &&
      config.verify_max_rms_m == d.verify_max_rms_m &&
      config.verify_min_inliers == d.verify_min_inliers &&
      config.verify_min_ncc == d.verify_min_ncc;
  if (!same_floats) std::printf("cli alone: a flag's default differs from OdometryConfig's\n");
  return config.validate().empty() && same_floats ? 0 : 1;
#elif NIDEVO_LAYER_LOADER
  (void)argc, (void)argv;
  nidevo::cli::SequenceSource source;
  source.frames = 2;
  const auto config = nidevo::cli::syntheticSequenceConfig(source);
  std::printf("loader alone: scene %s, %d frames\n", config.scene.c_str(), config.frames);
  return config.frames == 2 ? 0 : 1;
#endif
}
