#include "nidevo/io/dataset.hpp"

#include <algorithm>
#include <cmath>
#include <filesystem>
#include <fstream>
#include <opencv2/imgcodecs.hpp>
#include <opencv2/imgproc.hpp>
#include <stdexcept>

#include "nidevo/io/camera_io.hpp"
#include "nidevo/io/frame_conversion.hpp"
#include "nidevo/io/text_parse.hpp"

namespace fs = std::filesystem;

namespace nidevo {

std::vector<std::pair<size_t, size_t>> associateByTimestamp(const std::vector<double>& a,
                                                            const std::vector<double>& b,
                                                            double max_difference) {
  struct Candidate {
    double diff;
    size_t i, j;
  };
  std::vector<Candidate> candidates;
  // b is sorted in practice; a binary search keeps this O(n log n) for long sequences.
  std::vector<size_t> b_order(b.size());
  for (size_t j = 0; j < b.size(); ++j) b_order[j] = j;
  std::sort(b_order.begin(), b_order.end(), [&](size_t x, size_t y) { return b[x] < b[y]; });
  for (size_t i = 0; i < a.size(); ++i) {
    auto lo = std::lower_bound(b_order.begin(), b_order.end(), a[i] - max_difference,
                               [&](size_t j, double t) { return b[j] < t; });
    for (auto it = lo; it != b_order.end() && b[*it] <= a[i] + max_difference; ++it) {
      candidates.push_back({std::abs(a[i] - b[*it]), i, *it});
    }
  }
  std::sort(candidates.begin(), candidates.end(), [](const Candidate& x, const Candidate& y) {
    return x.diff != y.diff ? x.diff < y.diff : (x.i != y.i ? x.i < y.i : x.j < y.j);
  });
  std::vector<char> used_a(a.size(), 0), used_b(b.size(), 0);
  std::vector<std::pair<size_t, size_t>> pairs;
  for (const auto& c : candidates) {
    if (used_a[c.i] || used_b[c.j]) continue;
    used_a[c.i] = used_b[c.j] = 1;
    pairs.emplace_back(c.i, c.j);
  }
  std::sort(pairs.begin(), pairs.end(), [&](auto& x, auto& y) { return a[x.first] < a[y.first]; });
  return pairs;
}

namespace {

std::string lineError(const std::string& path, int line_no, const std::string& what) {
  return path + ":" + std::to_string(line_no) + ": " + what;
}

template <typename Fn>
void forEachDataLine(std::istream& in, const std::string& source, Fn&& fn) {
  std::string line;
  int line_no = 0;
  while (std::getline(in, line)) {
    ++line_no;
    auto fields = splitFields(line);
    if (fields.empty()) continue;
    try {
      fn(fields);
    } catch (const std::invalid_argument& e) {
      throw std::runtime_error(lineError(source, line_no, e.what()));
    }
  }
}

std::ifstream openList(const std::string& path) {
  std::ifstream in(path);
  if (!in) throw std::runtime_error(path + ": cannot open");
  return in;
}

}  // namespace

std::vector<TimedFile> parseFileList(std::istream& in, const std::string& source) {
  std::vector<TimedFile> files;
  forEachDataLine(in, source, [&](const std::vector<std::string>& f) {
    if (f.size() != 2) {
      throw std::invalid_argument("expected 'timestamp filename', got " + std::to_string(f.size()) +
                                  " fields");
    }
    files.push_back({parseDouble(f[0]), f[1]});
  });
  return files;
}

std::vector<TimedFile> readFileList(const std::string& path) {
  std::ifstream in = openList(path);
  return parseFileList(in, path);
}

std::vector<DatasetEntry> parseAssociations(std::istream& in, const std::string& source) {
  std::vector<DatasetEntry> entries;
  forEachDataLine(in, source, [&](const std::vector<std::string>& f) {
    if (f.size() < 4) {
      throw std::invalid_argument("expected 'ts_rgb rgb_file ts_depth depth_file', got " +
                                  std::to_string(f.size()) + " fields");
    }
    // TUM's associate.py writes rgb first; some tools write depth first: tell by the folder.
    DatasetEntry e;
    e.rgb = {parseDouble(f[0]), f[1]};
    e.depth = {parseDouble(f[2]), f[3]};
    if (e.rgb.path.rfind("depth", 0) == 0) std::swap(e.rgb, e.depth);
    entries.push_back(e);
  });
  return entries;
}

TumDataset::TumDataset(const std::string& folder, const Camera& fallback_camera,
                       double max_difference)
    : folder_(folder), camera_(fallback_camera) {
  if (!fs::is_directory(folder)) throw std::runtime_error(folder + ": not a directory");
  const fs::path dir(folder);
  if (fs::exists(dir / "camera.txt")) camera_ = readCameraFile((dir / "camera.txt").string());

  const fs::path assoc = dir / "associations.txt";
  if (fs::exists(assoc)) {
    std::ifstream in = openList(assoc.string());
    entries_ = parseAssociations(in, assoc.string());
  } else {
    const auto rgb = readFileList((dir / "rgb.txt").string());
    const auto depth = readFileList((dir / "depth.txt").string());
    std::vector<double> ta, tb;
    for (auto& r : rgb) ta.push_back(r.timestamp);
    for (auto& d : depth) tb.push_back(d.timestamp);
    for (auto [i, j] : associateByTimestamp(ta, tb, max_difference)) {
      DatasetEntry e;
      e.rgb = rgb[i];
      e.depth = depth[j];
      entries_.push_back(e);
    }
  }
  if (entries_.empty()) throw std::runtime_error(folder + ": no associated colour/depth frames");

  const fs::path gt = dir / "groundtruth.txt";
  if (fs::exists(gt)) {
    ground_truth_ = readTumTrajectory(gt.string());
    std::vector<double> ta, tb;
    for (auto& e : entries_) ta.push_back(e.depth.timestamp);
    for (auto& p : ground_truth_) tb.push_back(p.timestamp);
    for (auto [i, j] : associateByTimestamp(ta, tb, max_difference)) {
      entries_[i].ground_truth = ground_truth_[j];
    }
  }
}

RgbdFrame TumDataset::loadFrame(size_t i) const {
  if (i >= entries_.size()) {
    throw std::out_of_range("frame " + std::to_string(i) + " of " + std::to_string(size()));
  }
  const auto& e = entries_[i];
  const std::string rgb_path = (fs::path(folder_) / e.rgb.path).string();
  const std::string depth_path = (fs::path(folder_) / e.depth.path).string();

  const cv::Mat colour = cv::imread(rgb_path, cv::IMREAD_UNCHANGED);
  if (colour.empty()) throw std::runtime_error(rgb_path + ": cannot read colour image");
  if (colour.depth() != CV_8U) {
    throw std::runtime_error(rgb_path + ": colour image must be 8-bit per channel");
  }
  const cv::Mat depth = cv::imread(depth_path, cv::IMREAD_UNCHANGED | cv::IMREAD_ANYDEPTH);
  if (depth.empty()) throw std::runtime_error(depth_path + ": cannot read depth image");
  if (depth.type() != CV_16UC1) {
    throw std::runtime_error(depth_path + ": depth must be a 16-bit single-channel PNG");
  }
  if (depth.size() != colour.size()) {
    throw std::runtime_error(depth_path + ": depth is " + std::to_string(depth.cols) + "x" +
                             std::to_string(depth.rows) + " but colour " + rgb_path + " is " +
                             std::to_string(colour.cols) + "x" + std::to_string(colour.rows));
  }
  if (std::string err = camera_.checkImageSize(depth.cols, depth.rows); !err.empty())
    throw std::runtime_error(depth_path + ": " + err);
  RgbdFrame f;
  f.timestamp = e.depth.timestamp;
  if (std::string err = grayFrom8Bit(colour.ptr<uint8_t>(), colour.cols, colour.rows,
                                     colour.channels(), colour.step, ChannelOrder::kBgr, &f.gray);
      !err.empty())
    throw std::runtime_error(rgb_path + ": " + err);
  depthFrom16Bit(depth.ptr(), depth.cols, depth.rows, depth.step, camera_.depth_scale, &f.depth);
  return f;
}

}  // namespace nidevo
