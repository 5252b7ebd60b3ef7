#pragma once
// TUM RGB-D / ICL-NUIM sequence folders, read frame by frame.
#include <istream>
#include <optional>
#include <string>
#include <vector>

#include "nidevo/io/trajectory.hpp"
#include "nidevo/odometry/camera.hpp"
#include "nidevo/odometry/image.hpp"

namespace nidevo {

struct TimedFile {
  double timestamp = 0.0;
  std::string path;  // relative to the sequence folder
};

struct DatasetEntry {
  TimedFile rgb;
  TimedFile depth;
  std::optional<StampedPose> ground_truth;  // nearest ground-truth pose within the bound
};

// Pairs a with b by nearest timestamp within max_difference, greedily by smallest difference and
// each element used once (TUM's associate.py). Returns index pairs sorted by a's timestamp.
std::vector<std::pair<size_t, size_t>> associateByTimestamp(const std::vector<double>& a,
                                                            const std::vector<double>& b,
                                                            double max_difference);

// Reads "timestamp filename" lists (rgb.txt, depth.txt). Throws naming file and line.
std::vector<TimedFile> readFileList(const std::string& path);
// The same from a stream; `source` names it in errors.
std::vector<TimedFile> parseFileList(std::istream& in, const std::string& source);
// associations.txt: "ts_rgb rgb_file ts_depth depth_file" (or depth first) per line; entries
// without ground truth. Throws naming source and line.
std::vector<DatasetEntry> parseAssociations(std::istream& in, const std::string& source);

class TumDataset {
 public:
  // Reads the lists of `folder`: associations.txt if present, otherwise rgb.txt + depth.txt
  // associated within max_difference seconds; groundtruth.txt if present. Camera: `camera.txt`
  // in the folder if present, else `fallback_camera`. Throws std::runtime_error on bad input.
  explicit TumDataset(const std::string& folder, const Camera& fallback_camera = Camera{},
                      double max_difference = 0.02);

  size_t size() const { return entries_.size(); }
  const DatasetEntry& entry(size_t i) const { return entries_[i]; }
  const Camera& camera() const { return camera_; }
  const std::string& folder() const { return folder_; }
  bool hasGroundTruth() const { return !ground_truth_.empty(); }
  const Trajectory& groundTruth() const { return ground_truth_; }

  // Loads frame i: grey from the colour PNG/JPEG, depth from the 16-bit PNG scaled to metres.
  // Throws std::runtime_error naming the file on unreadable images, wrong bit depth or sizes.
  RgbdFrame loadFrame(size_t i) const;

 private:
  std::string folder_;
  Camera camera_;
  std::vector<DatasetEntry> entries_;
  Trajectory ground_truth_;
};

}  // namespace nidevo
