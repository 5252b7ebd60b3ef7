#include "nidevo/loader/sequence_flags.hpp"

#include <algorithm>

#include "absl/flags/flag.h"
#include "nidevo/cli/cli.hpp"

NIDEVO_FLAG_HEADING("Input sequence");
ABSL_FLAG(std::string, dataset, "", "TUM/ICL-NUIM sequence folder (default: a synthetic scene)");
ABSL_FLAG(int, max_frames, 0, "Use at most this many frames (0: all)");

namespace nidevo::cli {

SequenceSource sequenceSourceFromFlags() {
  SequenceSource src = sceneSourceFromFlags();
  src.dataset = absl::GetFlag(FLAGS_dataset);
  src.max_frames = size_t(std::max(0, absl::GetFlag(FLAGS_max_frames)));
  return src;
}

}  // namespace nidevo::cli
