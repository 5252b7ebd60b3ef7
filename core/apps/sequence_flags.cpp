#include "sequence_flags.hpp"

#include <algorithm>

#include "absl/flags/flag.h"

ABSL_FLAG(std::string, dataset, "", "TUM/ICL-NUIM sequence folder (default: a synthetic scene)");
ABSL_FLAG(std::string, scene, "office",
          "Synthetic scene when no --dataset: office, corridor, corner, gap");
ABSL_FLAG(std::string, texture, "rich", "Synthetic texture: rich, low, none");
ABSL_FLAG(std::string, noise, "none", "Synthetic sensor noise: none, icl");
ABSL_FLAG(int, frames, 300, "Synthetic sequence length");
ABSL_FLAG(uint64_t, seed, 1, "Synthetic sequence seed");
ABSL_FLAG(std::string, camera, "icl",
          "Camera preset for a synthetic scene, or for a folder without camera.txt");
ABSL_FLAG(int, max_frames, 0, "Use at most this many frames (0: all)");

namespace nidevo::cli {

SequenceSource sequenceSourceFromFlags() {
  SequenceSource src;
  src.dataset = absl::GetFlag(FLAGS_dataset);
  src.scene = absl::GetFlag(FLAGS_scene);
  src.texture = absl::GetFlag(FLAGS_texture);
  src.noise = absl::GetFlag(FLAGS_noise);
  src.frames = absl::GetFlag(FLAGS_frames);
  src.seed = absl::GetFlag(FLAGS_seed);
  src.camera = absl::GetFlag(FLAGS_camera);
  src.max_frames = size_t(std::max(0, absl::GetFlag(FLAGS_max_frames)));
  return src;
}

}  // namespace nidevo::cli
