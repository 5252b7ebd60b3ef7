#pragma once
// The randomized stress suite: sequences whose scene, motion, sensor, lens and exposure are all
// drawn from one seed, with what real indoor scenes and sensors have and the built-in scenes do
// not (see makeRandomScene). Sequence k of the suite is stressSequenceConfig(k).
#include <cstdint>
#include <string>

#include "nidevo/sim/sequence.hpp"

namespace nidevo::synth {

// 150-300 frames at 30 Hz of scene random:SEED; sensor none, ICL-like or structured light; lens
// distortion (Brown-Conrady) on half of them; auto-exposure jumps of 10-30 % on half of them;
// an ICL-NUIM or TUM camera.
SequenceConfig stressSequenceConfig(uint64_t seed);
// One line naming what was drawn, e.g. "random:3, 212 frames, kinect noise, distorted, exposure".
std::string describe(const SequenceConfig& config);

}  // namespace nidevo::synth
