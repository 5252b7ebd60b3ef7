#include "absl/flags/flag.h"
#include "nidevo/cli/cli.hpp"
#include "nidevo/loader/sequence_flags.hpp"

NIDEVO_FLAG_HEADING("Synthetic scene");
ABSL_FLAG(std::string, scene, "office",
          "Synthetic scene when there is no --dataset: office, corridor, corner, gap, hall");
ABSL_FLAG(std::string, texture, "rich", "Synthetic texture richness: rich, low, none");
ABSL_FLAG(std::string, noise, "none",
          "Synthetic sensor noise: none, icl (ICL-NUIM-like depth and RGB noise), kinect (a "
          "structured-light sensor: coarser depth steps, holes, shorter range)");
ABSL_FLAG(int, frames, 300, "Synthetic sequence length in frames");
ABSL_FLAG(double, speed, 0.25, "Synthetic camera's mean speed along its path, m/s");
ABSL_FLAG(uint64_t, seed, 1, "Seed of the synthetic handheld shake and sensor noise");
ABSL_FLAG(std::string, camera, "auto",
          "Camera preset (icl, icl_fy_positive, tum_fr1, tum_fr2, tum_fr3) of a synthetic scene "
          "(auto: icl), or of a dataset folder without camera.txt (auto: the preset the folder's "
          "name implies, e.g. rgbd_dataset_freiburg1_rpy gives tum_fr1; an error if it implies "
          "none)");

namespace nidevo::cli {

SequenceSource sceneSourceFromFlags() {
  SequenceSource src;
  src.scene = absl::GetFlag(FLAGS_scene);
  src.texture = absl::GetFlag(FLAGS_texture);
  src.noise = absl::GetFlag(FLAGS_noise);
  src.frames = absl::GetFlag(FLAGS_frames);
  src.seed = absl::GetFlag(FLAGS_seed);
  src.speed = absl::GetFlag(FLAGS_speed);
  src.camera = absl::GetFlag(FLAGS_camera);
  return src;
}

}  // namespace nidevo::cli
