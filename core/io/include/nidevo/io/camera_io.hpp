#pragma once
// Cameras as the tools name them: built-in presets and a small text file format.
#include <istream>
#include <optional>
#include <string>

#include "nidevo/odometry/camera.hpp"

namespace nidevo {

// Built-in presets: "icl", "icl_fy_positive", "tum_fr1", "tum_fr2", "tum_fr3".
std::optional<Camera> cameraPreset(const std::string& name);
std::string cameraPresetNames();
// The preset a dataset folder's name implies, as TUM and ICL-NUIM name their downloads:
// "freiburg1"/"fr1" (and 2, 3) give "tum_fr1" (and 2, 3); "icl", "living_room" and
// "office_room" give "icl". Only the folder's own name counts, not its parents'. Empty when
// the name says nothing, or names two cameras.
std::optional<std::string> cameraPresetForFolderName(const std::string& folder);

// Text format: one "key value" pair per line (fx fy cx cy width height depth_scale, optional
// Brown-Conrady k1 k2 p1 p2 k3), '#' comments. Throws std::runtime_error naming the file and line
// on any problem.
Camera readCameraFile(const std::string& path);
// The same format from a stream; `source` names it in errors.
Camera parseCameraText(std::istream& in, const std::string& source);
void writeCameraFile(const std::string& path, const Camera& camera);

}  // namespace nidevo
