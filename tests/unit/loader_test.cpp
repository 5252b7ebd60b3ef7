#include <gtest/gtest.h>

#include <filesystem>

#include "nidevo/io/camera_io.hpp"
#include "nidevo/loader/frame_loader.hpp"
#include "nidevo/sim/sequence.hpp"

namespace nidevo::cli {
namespace {

namespace fs = std::filesystem;

TEST(CameraPresetForFolderName, ReadsTumAndIclDownloadNames) {
  EXPECT_EQ(cameraPresetForFolderName("/data/rgbd_dataset_freiburg1_rpy"), "tum_fr1");
  EXPECT_EQ(cameraPresetForFolderName("/data/rgbd_dataset_freiburg2_desk/"), "tum_fr2");
  EXPECT_EQ(cameraPresetForFolderName("rgbd_dataset_freiburg3_long_office_household"), "tum_fr3");
  EXPECT_EQ(cameraPresetForFolderName("../shared/data/tum_fr1_rpy_first250"), "tum_fr1");
  EXPECT_EQ(cameraPresetForFolderName("FR2-xyz"), "tum_fr2");
  EXPECT_EQ(cameraPresetForFolderName("living_room_traj0_frei_png"), "icl");
  EXPECT_EQ(cameraPresetForFolderName("office_room_traj2"), "icl");
  EXPECT_EQ(cameraPresetForFolderName("icl_lr_kt1"), "icl");
}

TEST(CameraPresetForFolderName, SaysNothingWhenTheNameDoesNot) {
  EXPECT_FALSE(cameraPresetForFolderName("/data/my_recording"));
  EXPECT_FALSE(cameraPresetForFolderName("/data/fr10_run"));  // fr10 is not fr1
  EXPECT_FALSE(cameraPresetForFolderName("/data/afr1"));      // nor is afr1
  EXPECT_FALSE(cameraPresetForFolderName("/data/bicycle"));   // "icl" inside a word
  EXPECT_FALSE(cameraPresetForFolderName("/rgbd_dataset_freiburg1_x/session"));  // parent only
  EXPECT_FALSE(cameraPresetForFolderName("fr1_vs_fr2"));  // two cameras: no guess
}

// A small rendered folder named `name`, with or without its camera.txt.
fs::path renderedFolder(const std::string& name, bool keep_camera_file) {
  synth::SequenceConfig config;
  config.camera = cameraPreset("icl")->subsampled(4);
  config.frames = 2;
  const fs::path dir = fs::temp_directory_path() / "nidevo_loader_test" / name;
  fs::remove_all(dir);
  synth::SyntheticSequence(config).writeTumFolder(dir.string());
  if (!keep_camera_file) fs::remove(dir / "camera.txt");
  return dir;
}

TEST(LoadSequence, RefusesAFolderWithoutCameraWhoseNameImpliesNone) {
  SequenceSource src;
  src.dataset = renderedFolder("my_recording", false).string();
  try {
    loadSequence(src);
    FAIL() << "loaded without knowing the camera";
  } catch (const std::exception& e) {
    EXPECT_NE(std::string(e.what()).find("--camera"), std::string::npos) << e.what();
    EXPECT_NE(std::string(e.what()).find("my_recording"), std::string::npos) << e.what();
  }
}

TEST(LoadSequence, TakesCameraFileThenAskedPresetThenTheFoldersName) {
  SequenceSource src;
  src.dataset = renderedFolder("rgbd_dataset_freiburg3_x", true).string();
  src.camera = "tum_fr1";
  LoadedSequence seq = loadSequence(src);
  EXPECT_EQ(seq.camera.width, 160);  // camera.txt wins
  EXPECT_NE(seq.camera_source.find("camera.txt"), std::string::npos) << seq.camera_source;

  src.dataset = renderedFolder("rgbd_dataset_freiburg3_y", false).string();
  // The folder's 160x120 images do not fit a 640x480 preset: the loader says so.
  EXPECT_THROW(loadSequence(src), std::exception);
  src.camera = kAutoCamera;
  EXPECT_THROW(loadSequence(src), std::exception);
}

TEST(LoadSequence, NamesThePresetTheFoldersNameImplied) {
  synth::SequenceConfig config;
  config.camera = *cameraPreset("tum_fr3");
  config.frames = 1;
  const fs::path dir =
      fs::temp_directory_path() / "nidevo_loader_test" / "rgbd_dataset_freiburg3_z";
  fs::remove_all(dir);
  synth::SyntheticSequence(config).writeTumFolder(dir.string());
  fs::remove(dir / "camera.txt");
  SequenceSource src;
  src.dataset = dir.string();
  const LoadedSequence seq = loadSequence(src);
  EXPECT_EQ(seq.camera.fx, cameraPreset("tum_fr3")->fx);
  EXPECT_EQ(seq.camera_source, "preset tum_fr3 (from the folder's name)");
}

TEST(LoadSequence, FrameStepTakesEveryNthFrameWithItsOwnGroundTruth) {
  synth::SequenceConfig config;
  config.camera = cameraPreset("icl")->subsampled(4);
  config.frames = 7;
  const fs::path dir = fs::temp_directory_path() / "nidevo_loader_test" / "icl_step";
  fs::remove_all(dir);
  synth::SyntheticSequence(config).writeTumFolder(dir.string());
  SequenceSource src;
  src.dataset = dir.string();
  const LoadedSequence all = loadSequence(src);
  ASSERT_EQ(all.frames.size(), 7u);
  src.frame_step = 3;
  const LoadedSequence stepped = loadSequence(src);
  EXPECT_EQ(stepped.frame_step, 3u);
  ASSERT_EQ(stepped.frames.size(), 3u);  // frames 0, 3 and 6
  ASSERT_EQ(stepped.ground_truth.size(), 3u);
  for (size_t i = 0; i < 3; ++i) {
    EXPECT_EQ(stepped.frames[i].timestamp, all.frames[3 * i].timestamp);
    EXPECT_EQ(stepped.frames[i].depth.data, all.frames[3 * i].depth.data);
    EXPECT_EQ(stepped.ground_truth[i].timestamp, stepped.frames[i].timestamp);
    EXPECT_TRUE(stepped.ground_truth[i].pose().isApprox(all.ground_truth[3 * i].pose()));
  }
  src.max_frames = 2;  // counted after the step
  EXPECT_EQ(loadSequence(src).frames.size(), 2u);
  src.frame_step = 0;
  EXPECT_THROW(loadSequence(src), std::invalid_argument);
}

}  // namespace
}  // namespace nidevo::cli
