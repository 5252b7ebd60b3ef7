#include "nidevo/loader/sequence_flags.hpp"

#include <algorithm>

#include "absl/flags/flag.h"
#include "nidevo/cli/cli.hpp"

NIDEVO_FLAG_HEADING("Input sequence");
ABSL_FLAG(std::string, dataset, "", "TUM/ICL-NUIM sequence folder (default: a synthetic scene)");
ABSL_FLAG(int, max_frames, 0, "Use at most this many frames (0: all)");
ABSL_FLAG(int, frame_step, 1,
          "Use every n-th frame of --dataset, from its first: the recording with the camera "
          "moving n times as fast (or a sensor at 1/n of its rate)");

namespace nidevo::cli {

SequenceSource sequenceSourceFromFlags() {
  SequenceSource src = sceneSourceFromFlags();
  src.dataset = absl::GetFlag(FLAGS_dataset);
  src.max_frames = size_t(std::max(0, absl::GetFlag(FLAGS_max_frames)));
  src.frame_step = size_t(std::max(0, absl::GetFlag(FLAGS_frame_step)));  // 0: the loader refuses
  return src;
}

}  // namespace nidevo::cli
