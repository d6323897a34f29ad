// aerie-sim end to end: the exported folders have one ground-truth line per image and
// readable calibration; bad configs fail with the key named.
#include <gtest/gtest.h>

#include <opencv2/imgcodecs.hpp>

#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <string>

#include "common/camera/calibration_io.hpp"
#include "tests/support/test_support.hpp"

namespace fs = std::filesystem;

namespace {

int run(const std::string& args) {
  const std::string cmd = std::string(AERIE_SIM_EXE) + " " + args + " > /dev/null 2>&1";
  const int rc = std::system(cmd.c_str());
  return WIFEXITED(rc) ? WEXITSTATUS(rc) : -1;
}

int count_lines(const fs::path& p, bool skip_comments = true) {
  std::ifstream f(p);
  std::string line;
  int n = 0;
  while (std::getline(f, line))
    if (!line.empty() && !(skip_comments && line[0] == '#')) ++n;
  return n;
}

int count_files(const fs::path& dir) {
  return static_cast<int>(std::distance(fs::directory_iterator(dir), fs::directory_iterator{}));
}

fs::path write_config(const fs::path& dir, const std::string& text) {
  const fs::path p = dir / "sim.yaml";
  std::ofstream(p) << text;
  return p;
}

TEST(AerieSim, StereoExportIsAKittiFolder) {
  const fs::path dir = aerie::test::scratch_dir("out");
  const fs::path cfg = write_config(dir, "world: {texels_per_metre: 40}\nrig: {width: 94, height: 60}\n");
  ASSERT_EQ(run("stereo --config " + cfg.string() + " --out " + (dir / "seq").string() + " --every 50 --max-frames 6"), 0);
  EXPECT_EQ(count_files(dir / "seq" / "image_0"), 6);
  EXPECT_EQ(count_files(dir / "seq" / "image_1"), 6);
  EXPECT_EQ(count_files(dir / "seq" / "depth_0"), 6);
  EXPECT_EQ(count_lines(dir / "seq" / "poses.txt"), 6);
  EXPECT_EQ(count_lines(dir / "seq" / "times.txt"), 6);
  EXPECT_EQ(count_lines(dir / "seq" / "poses_world_tum.txt"), 6);
  const cv::Mat img = cv::imread((dir / "seq" / "image_0" / "000005.png").string(), cv::IMREAD_UNCHANGED);
  EXPECT_EQ(img.size(), cv::Size(94, 60));
  const cv::Mat depth = cv::imread((dir / "seq" / "depth_0" / "000005.png").string(), cv::IMREAD_UNCHANGED);
  EXPECT_EQ(depth.type(), CV_16U);
  // Both calibration files read back as the same rig.
  const auto kitti = aerie::camera::read_stereo_calibration((dir / "seq" / "calib.txt").string(), 94, 60);
  const auto yaml = aerie::camera::read_stereo_calibration((dir / "seq" / "calib.yaml").string());
  EXPECT_NEAR(kitti.baseline(), 0.12, 1e-9);
  EXPECT_NEAR(yaml.baseline(), 0.12, 1e-9);
  EXPECT_NEAR(kitti.left.fx, 47.0 / std::tan(49.0 * M_PI / 180.0), 1e-6);
  EXPECT_NEAR(yaml.left.fx, kitti.left.fx, 1e-6);
}

TEST(AerieSim, TrackingSequencesAreOtbFolders) {
  const fs::path dir = aerie::test::scratch_dir("out");
  const fs::path cfg = write_config(
      dir, "world: {texels_per_metre: 40}\nrig: {width: 94, height: 60}\ntrajectory: {speed: 1.5}\n"
           "intruder: {width: 160, height: 120, frames: 7, wingspan_px: 30}\n");
  ASSERT_EQ(run("landing --config " + cfg.string() + " --out " + (dir / "land").string()), 0);
  const int n = count_files(dir / "land" / "img");
  EXPECT_GT(n, 5);
  EXPECT_EQ(count_lines(dir / "land" / "groundtruth.txt"), n);
  EXPECT_EQ(count_lines(dir / "land" / "groundtruth_full.csv"), n + 1);  // + header
  ASSERT_EQ(run("intruder --config " + cfg.string() + " --out " + (dir / "intr").string() + " --ext jpg"), 0);
  EXPECT_EQ(count_files(dir / "intr" / "img"), 7);
  EXPECT_TRUE(fs::exists(dir / "intr" / "img" / "0007.jpg"));
  EXPECT_EQ(count_lines(dir / "intr" / "groundtruth.txt"), 7);
}

TEST(AerieSim, BadInputsFail) {
  const fs::path dir = aerie::test::scratch_dir("out");
  EXPECT_NE(run("stereo --config " + write_config(dir, "rig: {widht: 3}\n").string() + " --out " + dir.string()), 0);
  EXPECT_NE(run("stereo --config /nonexistent.yaml --out " + dir.string()), 0);
  EXPECT_NE(run("stereo"), 0);  // --out is required
  EXPECT_EQ(run("info --config " + write_config(dir, "world: {texels_per_metre: 20}\n").string()), 0);
}

}  // namespace
