// aerie-sim end to end: the exported folders have one ground-truth line per image and
// readable calibration; bad configs fail with the key named.
#include <gtest/gtest.h>

#include <opencv2/imgcodecs.hpp>

#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <iterator>
#include <string>
#include <vector>

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

std::string read_all(const fs::path& p) {
  std::ifstream f(p, std::ios::binary);
  return std::string(std::istreambuf_iterator<char>(f), {});
}

std::vector<std::string> lines_of(const fs::path& p) {
  std::ifstream f(p);
  std::vector<std::string> out;
  for (std::string line; std::getline(f, line);) out.push_back(line);
  return out;
}

TEST(AerieSim, ExitSequencesAreDeterministicWithNaNRowsOutOfView) {
  const fs::path dir = aerie::test::scratch_dir("out");
  const fs::path cfg = write_config(
      dir, "exits: {width: 160, height: 120, wingspan_px: 24, in_frames_min: 3, in_frames_max: 5, "
           "out_frames_min: 4, out_frames_max: 6, pan_speed_px: 20, drift_speed_px: 4}\n");
  ASSERT_EQ(run("exits --config " + cfg.string() + " --out " + (dir / "a").string() + " --count 2"), 0);
  ASSERT_EQ(run("exits --config " + cfg.string() + " --out " + (dir / "b").string() + " --count 2 --name exits"), 0);
  for (const char* seq : {"exits_01", "exits_02"}) {
    const fs::path a = dir / "a" / seq, b = dir / "b" / seq;
    const auto gt = lines_of(a / "groundtruth.txt"), full = lines_of(a / "groundtruth_full.csv");
    const int n = count_files(a / "img");
    ASSERT_EQ(static_cast<int>(gt.size()), n);
    ASSERT_EQ(static_cast<int>(full.size()), n + 1);
    EXPECT_EQ(full[0], "frame,utime,visible,x,y,w,h,center_x,center_y,scale,angle_rad,visible_fraction,event");
    EXPECT_NE(gt[0], "NaN,NaN,NaN,NaN");  // trackers start on the first frame
    int nan_rows = 0;
    for (int k = 0; k < n; ++k) {
      // visible (3rd column) is 0 exactly where the visible fraction is under 1/4, and there
      // groundtruth.txt has NaN; elsewhere its box is the full file's.
      const std::string& row = full[k + 1];
      const size_t c2 = row.find(',', row.find(',') + 1);
      const bool visible = row[c2 + 1] == '1';
      const double fraction = std::stod(row.substr(row.find_last_of(',', row.rfind(',') - 1) + 1));
      EXPECT_EQ(visible, fraction >= 0.25) << seq << " " << row;
      EXPECT_EQ(gt[k] == "NaN,NaN,NaN,NaN", !visible) << seq << " frame " << k + 1;
      if (visible) {
        EXPECT_EQ(row.substr(c2 + 3, gt[k].size()), gt[k]) << seq << " frame " << k + 1;
      }
      nan_rows += visible ? 0 : 1;
    }
    EXPECT_GE(nan_rows, 3 * 4);  // three exits of at least 4 frames
    // Same seed, same bytes.
    for (const auto& e : fs::recursive_directory_iterator(a)) {
      if (!e.is_regular_file()) continue;
      EXPECT_EQ(read_all(e.path()), read_all(b / fs::relative(e.path(), a))) << e.path();
    }
  }
  EXPECT_NE(read_all(dir / "a" / "exits_01" / "groundtruth.txt"), read_all(dir / "a" / "exits_02" / "groundtruth.txt"));
  EXPECT_NE(run("exits --config " + write_config(dir, "exits: {exitz: 2}\n").string() + " --out " + dir.string()), 0);
  EXPECT_NE(run("exits --config " + write_config(dir, "intruder: {frames: 2}\n").string() + " --out " + dir.string()),
            0);
}

TEST(AerieSim, BadInputsFail) {
  const fs::path dir = aerie::test::scratch_dir("out");
  EXPECT_NE(run("stereo --config " + write_config(dir, "rig: {widht: 3}\n").string() + " --out " + dir.string()), 0);
  EXPECT_NE(run("stereo --config /nonexistent.yaml --out " + dir.string()), 0);
  EXPECT_NE(run("stereo"), 0);  // --out is required
  EXPECT_EQ(run("info --config " + write_config(dir, "world: {texels_per_metre: 20}\n").string()), 0);
}

}  // namespace
