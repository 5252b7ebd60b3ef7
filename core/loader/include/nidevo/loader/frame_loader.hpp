#pragma once
// Loads a sequence into memory for the offline tools: a TUM/ICL-NUIM folder or a synthetic
// scene rendered on the fly (on all cores).
#include <string>
#include <vector>

#include "nidevo/io/trajectory.hpp"
#include "nidevo/odometry/camera.hpp"
#include "nidevo/odometry/image.hpp"
#include "nidevo/sim/sequence.hpp"

namespace nidevo::cli {

struct LoadedSequence {
  std::string name;
  Camera camera;
  std::string camera_source;  // where the camera came from, for the user to check
  std::vector<RgbdFrame> frames;
  Trajectory ground_truth;  // empty when the source has none
  size_t frame_step = 1;    // every frame_step-th frame of the folder was loaded
};

inline constexpr const char* kAutoCamera = "auto";

// "scene:office" style sources render synthetic sequences; anything else is a dataset folder.
struct SequenceSource {
  std::string dataset;  // folder, or empty
  std::string scene = "office";
  std::string texture = "rich";
  std::string noise = "none";
  int frames = 300;
  uint64_t seed = 1;
  double speed = 0.25;  // synthetic: mean camera speed along the path, m/s
  // Preset for a synthetic scene ("auto": icl), or for a folder without camera.txt ("auto":
  // the preset the folder's name implies, else an error).
  std::string camera = kAutoCamera;
  size_t max_frames = 0;  // 0: all (counted after frame_step)
  // Every n-th frame of a dataset folder, from its first: the same recording with the camera
  // moving n times as fast (or a sensor at 1/n of its rate), ground truth included.
  size_t frame_step = 1;
};

// Throws std::exception with a message naming what is wrong.
LoadedSequence loadSequence(const SequenceSource& source);
// The renderer's config of the source's synthetic scene (its dataset field is ignored).
synth::SequenceConfig syntheticSequenceConfig(const SequenceSource& source);

}  // namespace nidevo::cli
