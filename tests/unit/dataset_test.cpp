#include "nidevo/io/dataset.hpp"

#include <gtest/gtest.h>

#include <filesystem>
#include <fstream>
#include <opencv2/core.hpp>
#include <opencv2/imgcodecs.hpp>

#include "nidevo/io/camera_io.hpp"
#include "nidevo/sim/sequence.hpp"

namespace nidevo {
namespace {

namespace fs = std::filesystem;

synth::SequenceConfig smallConfig() {
  synth::SequenceConfig c;
  c.camera = cameraPreset("icl")->subsampled(4);  // 160x120 keeps the test fast
  c.frames = 4;
  return c;
}

fs::path freshDir(const std::string& name) {
  fs::path dir = fs::temp_directory_path() / ("nidevo_ds_" + name);
  fs::remove_all(dir);
  return dir;
}

template <typename Fn>
void expectError(Fn&& fn, const std::string& needle) {
  try {
    fn();
    FAIL() << "no error, expected one containing '" << needle << "'";
  } catch (const std::exception& e) {
    EXPECT_NE(std::string(e.what()).find(needle), std::string::npos) << e.what();
  }
}

TEST(Associate, GreedyNearestWithinBound) {
  const std::vector<double> a = {0.0, 1.0, 2.0, 3.0};
  const std::vector<double> b = {0.005, 0.99, 1.015, 2.5, 3.019};
  auto pairs = associateByTimestamp(a, b, 0.02);
  ASSERT_EQ(pairs.size(), 3u);
  EXPECT_EQ(pairs[0], std::make_pair(size_t(0), size_t(0)));
  EXPECT_EQ(pairs[1], std::make_pair(size_t(1), size_t(1)));  // 0.99 is nearer than 1.015
  EXPECT_EQ(pairs[2], std::make_pair(size_t(3), size_t(4)));
}

TEST(TumDataset, ReadsWhatTheRendererWrote) {
  const auto cfg = smallConfig();
  synth::SyntheticSequence seq(cfg);
  const auto dir = freshDir("roundtrip");
  seq.writeTumFolder(dir.string());
  fs::remove(dir / "associations.txt");  // exercise rgb.txt + depth.txt association
  TumDataset ds(dir.string());
  ASSERT_EQ(ds.size(), 4u);
  EXPECT_TRUE(ds.hasGroundTruth());
  EXPECT_EQ(ds.camera().width, 160);
  EXPECT_DOUBLE_EQ(ds.camera().fy, cfg.camera.fy);
  for (size_t i = 0; i < ds.size(); ++i) {
    ASSERT_TRUE(ds.entry(i).ground_truth.has_value());
    EXPECT_TRUE(ds.entry(i).ground_truth->pose().isApprox(seq.groundTruth(int(i)), 1e-9));
    const RgbdFrame f = ds.loadFrame(i);
    const RgbdFrame g = seq.renderFrame(int(i));
    ASSERT_EQ(f.depth.width, g.depth.width);
    for (size_t k = 0; k < f.depth.size(); ++k) {
      ASSERT_NEAR(f.depth.data[k], g.depth.data[k], 0.5 / 5000 + 1e-6);
      ASSERT_NEAR(int(f.gray.data[k]), int(g.gray.data[k]), 1);
    }
  }
}

TEST(TumDataset, BadInputsGiveNamedErrors) {
  const auto cfg = smallConfig();
  synth::SyntheticSequence seq(cfg);
  const auto dir = freshDir("bad");
  seq.writeTumFolder(dir.string());

  expectError([] { TumDataset("/nonexistent/folder"); }, "not a directory");

  // Malformed list line.
  std::ofstream(dir / "associations.txt", std::ios::app) << "1.0 rgb/x.png\n";
  expectError([&] { TumDataset(dir.string()); }, "associations.txt:5");
  fs::remove(dir / "associations.txt");
  std::ofstream(dir / "depth.txt", std::ios::app) << "abc depth/000000.png\n";
  expectError([&] { TumDataset(dir.string()); }, "depth.txt:7: 'abc' is not a finite number");
  seq.writeTumFolder(dir.string());

  TumDataset ds(dir.string());
  // Missing file.
  fs::remove(dir / "rgb" / "000001.png");
  expectError([&] { ds.loadFrame(1); }, "rgb/000001.png: cannot read colour image");
  // Unreadable PNG.
  std::ofstream(dir / "depth" / "000002.png") << "not a png";
  expectError([&] { ds.loadFrame(2); }, "depth/000002.png: cannot read depth image");
  // Wrong bit depth.
  cv::imwrite((dir / "depth" / "000003.png").string(), cv::Mat(120, 160, CV_8UC1, cv::Scalar(9)));
  expectError([&] { ds.loadFrame(3); }, "000003.png: depth must be a 16-bit single-channel PNG");
  // Colour and depth of different sizes.
  cv::imwrite((dir / "depth" / "000000.png").string(), cv::Mat(60, 80, CV_16UC1, cv::Scalar(9)));
  expectError([&] { ds.loadFrame(0); }, "depth is 80x60 but colour");
  expectError([&] { ds.loadFrame(99); }, "frame 99 of 4");
}

}  // namespace
}  // namespace nidevo
