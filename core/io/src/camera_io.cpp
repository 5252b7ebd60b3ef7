#include "nidevo/io/camera_io.hpp"

#include <algorithm>
#include <cctype>
#include <cmath>
#include <filesystem>
#include <fstream>
#include <map>
#include <regex>
#include <sstream>
#include <stdexcept>

namespace nidevo {

std::optional<Camera> cameraPreset(const std::string& name) {
  auto make = [](double fx, double fy, double cx, double cy, Distortion d = {}) {
    Camera c;
    c.distortion = d;
    c.fx = fx;
    c.fy = fy;
    c.cx = cx;
    c.cy = cy;
    c.width = 640;
    c.height = 480;
    c.depth_scale = 5000.0;
    return c;
  };
  if (name == "icl") return make(481.2, -480.0, 319.5, 239.5);
  if (name == "icl_fy_positive") return make(481.2, 480.0, 319.5, 239.5);
  // TUM's published calibrations (vision.in.tum.de, "file formats"): fr1 and fr2 with their
  // plumb_bob coefficients; fr3's images are already undistorted.
  if (name == "tum_fr1")
    return make(517.3, 516.5, 318.6, 255.3, {0.2624, -0.9531, -0.0054, 0.0026, 1.1633});
  if (name == "tum_fr2")
    return make(520.9, 521.0, 325.1, 249.7, {0.2312, -0.7849, -0.0033, -0.0001, 0.9172});
  if (name == "tum_fr3") return make(535.4, 539.2, 320.1, 247.6);
  return std::nullopt;
}

std::string cameraPresetNames() { return "icl, icl_fy_positive, tum_fr1, tum_fr2, tum_fr3"; }

std::optional<std::string> cameraPresetForFolderName(const std::string& folder) {
  std::string name = std::filesystem::path(folder).lexically_normal().filename().string();
  if (name.empty())
    name = std::filesystem::path(folder).lexically_normal().parent_path().filename().string();
  std::transform(name.begin(), name.end(), name.begin(),
                 [](unsigned char c) { return char(std::tolower(c)); });
  // Word boundaries keep "fr1" from matching inside "fr10" or "xfr1".
  static const std::pair<std::regex, const char*> kNames[] = {
      {std::regex("freiburg1|(^|[^a-z0-9])fr1($|[^0-9])"), "tum_fr1"},
      {std::regex("freiburg2|(^|[^a-z0-9])fr2($|[^0-9])"), "tum_fr2"},
      {std::regex("freiburg3|(^|[^a-z0-9])fr3($|[^0-9])"), "tum_fr3"},
      {std::regex("(^|[^a-z])icl($|[^a-z])|living_?room|office_?room"), "icl"},
  };
  std::optional<std::string> found;
  for (const auto& [pattern, preset] : kNames) {
    if (!std::regex_search(name, pattern)) continue;
    if (found) return std::nullopt;
    found = preset;
  }
  return found;
}

Camera readCameraFile(const std::string& path) {
  std::ifstream in(path);
  if (!in) throw std::runtime_error(path + ": cannot open camera file");
  return parseCameraText(in, path);
}

Camera parseCameraText(std::istream& in, const std::string& path) {
  std::map<std::string, double> values;
  std::string line;
  int line_no = 0;
  while (std::getline(in, line)) {
    ++line_no;
    auto hash = line.find('#');
    if (hash != std::string::npos) line.erase(hash);
    std::istringstream ss(line);
    std::string key;
    if (!(ss >> key)) continue;
    double value;
    std::string extra;
    if (!(ss >> value) || (ss >> extra)) {
      throw std::runtime_error(path + ":" + std::to_string(line_no) +
                               ": expected 'key value', got '" + line + "'");
    }
    static const char* kKeys[] = {"fx",          "fy", "cx", "cy", "width", "height",
                                  "depth_scale", "k1", "k2", "p1", "p2",    "k3"};
    bool known = false;
    for (const char* k : kKeys) known = known || key == k;
    if (!known) {
      throw std::runtime_error(path + ":" + std::to_string(line_no) + ": unknown key '" + key +
                               "' (expected fx fy cx cy width height depth_scale k1 k2 p1 p2 k3)");
    }
    values[key] = value;
  }
  Camera c;
  for (const char* k : {"fx", "fy", "cx", "cy", "width", "height"}) {
    if (!values.count(k)) throw std::runtime_error(path + ": missing key '" + std::string(k) + "'");
  }
  c.fx = values["fx"];
  c.fy = values["fy"];
  c.cx = values["cx"];
  c.cy = values["cy"];
  // Checked before the cast: a double outside int's range has no int value (found by fuzzing).
  for (const char* k : {"width", "height"}) {
    const double v = values[k];
    if (!(v >= 1 && v <= 8192 && v == std::floor(v)))
      throw std::runtime_error(path + ": " + k + " must be a whole number in 1..8192");
  }
  c.width = int(values["width"]);
  c.height = int(values["height"]);
  if (values.count("depth_scale")) c.depth_scale = values["depth_scale"];
  Distortion& d = c.distortion;
  for (auto [key, field] :
       {std::pair{"k1", &d.k1}, {"k2", &d.k2}, {"p1", &d.p1}, {"p2", &d.p2}, {"k3", &d.k3}})
    if (values.count(key)) *field = values[key];
  if (auto err = c.validate(); !err.empty()) throw std::runtime_error(path + ": " + err);
  return c;
}

void writeCameraFile(const std::string& path, const Camera& c) {
  std::ofstream out(path);
  if (!out) throw std::runtime_error(path + ": cannot write camera file");
  out.precision(10);
  out << "# nidevo camera: pinhole intrinsics, image size, raw depth units per metre\n"
      << "fx " << c.fx << "\nfy " << c.fy << "\ncx " << c.cx << "\ncy " << c.cy << "\nwidth "
      << c.width << "\nheight " << c.height << "\ndepth_scale " << c.depth_scale << "\n";
  if (!c.distortion.none()) {
    const Distortion& d = c.distortion;
    out << "# Brown-Conrady distortion (plumb_bob)\nk1 " << d.k1 << "\nk2 " << d.k2 << "\np1 "
        << d.p1 << "\np2 " << d.p2 << "\nk3 " << d.k3 << "\n";
  }
  if (!out) throw std::runtime_error(path + ": write failed");
}

}  // namespace nidevo
