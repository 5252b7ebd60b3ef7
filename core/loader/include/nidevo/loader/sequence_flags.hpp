#pragma once
// The flags that pick a sequence, shared by nidevo-run, nidevo-client and nidevo-synth:
// "Input sequence" (--dataset, --max_frames) and "Synthetic scene" (--scene, --texture, --noise,
// --frames, --seed, --camera).
#include "nidevo/loader/frame_loader.hpp"

namespace nidevo::cli {

// Both groups: a dataset folder, or the synthetic scene when --dataset is empty.
SequenceSource sequenceSourceFromFlags();
// The synthetic scene's group only (a program that links just this has no --dataset).
SequenceSource sceneSourceFromFlags();

}  // namespace nidevo::cli
