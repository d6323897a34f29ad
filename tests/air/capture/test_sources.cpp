// Frame sources on small inputs: an image folder with timestamps, the KITTI chunk
// (frames, calibration, ground-truth poses), the EuRoC excerpt (rectified output,
// the cam1 data.csv quirk), a video file; bad inputs give errors naming the file.
#include <gtest/gtest.h>

#include <filesystem>
#include <fstream>
#include <opencv2/imgcodecs.hpp>
#include <opencv2/imgproc.hpp>
#include <opencv2/videoio.hpp>

#include "air/capture/dataset_io.hpp"
#include "air/capture/image_folder_source.hpp"
#include "air/capture/output_format.hpp"
#include "air/capture/pacer.hpp"
#include "air/capture/sim_source.hpp"
#include "air/capture/source_factory.hpp"
#include "air/capture/stereo_sequence_source.hpp"
#include "air/capture/video_source.hpp"
#include "common/camera/calibration_io.hpp"
#include "tests/support/test_support.hpp"

namespace aerie::capture {
namespace {
namespace fs = std::filesystem;

const char* kKitti = "stereo_seq/KITTI_odom_06_f000-050";
const char* kEuroc = "stereo_seq/EuRoC_V1_01_easy_f000-094";

// The exception message of f(), or "" when it does not throw.
template <typename F>
std::string error_of(F&& f) {
  try {
    f();
  } catch (const std::exception& e) {
    return e.what();
  }
  return "";
}

#define EXPECT_ERROR_NAMES(expr, needle)                                   \
  do {                                                                     \
    const std::string msg_ = error_of([&] { (void)(expr); });              \
    EXPECT_NE(msg_.find(needle), std::string::npos) << "message: " << msg_; \
  } while (0)

cv::Mat pattern(int i, cv::Size size = {64, 48}) {
  // Smooth deterministic texture (survives JPEG) with the frame number written on it.
  cv::Mat img(size, CV_8UC1);
  cv::RNG rng(static_cast<uint64_t>(i) + 1);
  rng.fill(img, cv::RNG::UNIFORM, 0, 255);
  cv::GaussianBlur(img, img, {9, 9}, 3);
  cv::normalize(img, img, 0, 200, cv::NORM_MINMAX);
  cv::putText(img, std::to_string(i), {5, 30}, cv::FONT_HERSHEY_SIMPLEX, 0.8, cv::Scalar(255), 2);
  return img;
}

void write_text(const fs::path& p, const std::string& text) {
  std::ofstream f(p);
  f << text;
}

TEST(DatasetIo, ParseSecondsIsExact) {
  EXPECT_EQ(parse_seconds("1403715273.262143"), 1403715273262143);
  EXPECT_EQ(parse_seconds("0.000000e+00"), 0);
  EXPECT_EQ(parse_seconds("1.044989e-01"), 104499);
  EXPECT_EQ(parse_seconds("12"), 12'000'000);
  EXPECT_EQ(parse_seconds("0.1234565"), 123457);  // 7th decimal rounds
  EXPECT_EQ(parse_seconds("-1.5"), -1'500'000);
  EXPECT_FALSE(parse_seconds("abc"));
  EXPECT_FALSE(parse_seconds(""));
}

TEST(ImageFolderSource, SortedNamesAndTimestamps) {
  const auto dir = test::scratch_dir("folder");
  // Written out of order: the source sorts by name.
  for (const int i : {3, 0, 2, 1}) cv::imwrite((dir / ("f" + std::to_string(i) + ".png")).string(), pattern(i));
  write_text(dir / "notes.txt", "not an image");
  write_text(dir / "times.txt", "# seconds\n100.5\n100.55\n\n100.6\n100.7001\n");
  ImageFolderSource src(dir.string(), (dir / "times.txt").string(), 20, false);
  EXPECT_EQ(src.frame_count(), 4);
  EXPECT_EQ(src.size(), cv::Size(64, 48));
  EXPECT_FALSE(src.stereo());
  const int64_t expect_utime[] = {100'500'000, 100'550'000, 100'600'000, 100'700'100};
  Frame f;
  for (int i = 0; i < 4; ++i) {
    ASSERT_TRUE(src.next(f));
    EXPECT_EQ(f.index, i);
    EXPECT_EQ(f.utime, expect_utime[i]);
    EXPECT_EQ(cv::norm(f.left, pattern(i), cv::NORM_INF), 0) << "frame " << i;
  }
  EXPECT_FALSE(src.next(f));
  src.seek(2);
  ASSERT_TRUE(src.next(f));
  EXPECT_EQ(f.index, 2);
}

TEST(ImageFolderSource, NominalRateWithoutTimestamps) {
  const auto dir = test::scratch_dir("folder");
  for (int i = 0; i < 3; ++i) cv::imwrite((dir / (std::to_string(i) + ".png")).string(), pattern(i));
  ImageFolderSource src(dir.string(), "", 25, true);
  Frame f;
  src.seek(2);
  ASSERT_TRUE(src.next(f));
  EXPECT_EQ(f.utime, 80'000);
  EXPECT_EQ(f.left.type(), CV_8UC3);
}

TEST(ImageFolderSource, BadInputsNameTheFile) {
  const auto dir = test::scratch_dir("folder");
  EXPECT_ERROR_NAMES(ImageFolderSource((dir / "missing").string(), "", 20, false), "missing");
  EXPECT_ERROR_NAMES(ImageFolderSource(dir.string(), "", 20, false), "no images");
  for (int i = 0; i < 3; ++i) cv::imwrite((dir / (std::to_string(i) + ".png")).string(), pattern(i));
  write_text(dir / "times.txt", "1\n2\n");
  EXPECT_ERROR_NAMES(ImageFolderSource(dir.string(), (dir / "times.txt").string(), 20, false), "times.txt: 2 timestamps for 3 images");
  write_text(dir / "bad_times.txt", "1\nx\n3\n");
  EXPECT_ERROR_NAMES(ImageFolderSource(dir.string(), (dir / "bad_times.txt").string(), 20, false), "bad_times.txt:2");
}

// An unreadable frame mid-run is reported (naming the file) and skipped.
TEST(ImageFolderSource, UnreadableFrameIsSkipped) {
  const auto dir = test::scratch_dir("folder");
  for (int i = 0; i < 4; ++i) cv::imwrite((dir / (std::to_string(i) + ".png")).string(), pattern(i));
  write_text(dir / "2.png", "garbage, not a PNG");
  ImageFolderSource src(dir.string(), "", 20, false);
  Frame f;
  ASSERT_TRUE(src.next(f));
  ASSERT_TRUE(src.next(f));
  EXPECT_ERROR_NAMES(src.next(f), (dir / "2.png").string());
  ASSERT_TRUE(src.next(f));
  EXPECT_EQ(f.index, 3);
  EXPECT_EQ(cv::norm(f.left, pattern(3), cv::NORM_INF), 0);
}

TEST(KittiSource, FramesCalibrationAndGroundTruth) {
  AERIE_REQUIRE_DATA(kKitti);
  const auto dir = test::shared_data(kKitti);
  StereoSequenceSource src(load_kitti(dir.string()), false);
  EXPECT_EQ(src.frame_count(), 51);
  EXPECT_TRUE(src.stereo());
  EXPECT_EQ(src.size(), cv::Size(1226, 370));
  const auto r = src.rectified();
  ASSERT_TRUE(r);
  EXPECT_DOUBLE_EQ(r->fx, 707.0912);
  EXPECT_DOUBLE_EQ(r->cx, 601.8873);
  EXPECT_DOUBLE_EQ(r->cy, 183.1104);
  EXPECT_NEAR(r->baseline, 379.8145 / 707.0912, 1e-9);

  const auto poses = read_kitti_poses((dir / "poses.txt").string());
  const auto times = read_timestamps((dir / "times.txt").string());
  src.seek(50);
  Frame f;
  ASSERT_TRUE(src.next(f));
  EXPECT_EQ(f.index, 50);
  EXPECT_EQ(f.utime, times[50]);
  EXPECT_EQ(f.utime, 5'195'994);  // times.txt: 5.195994
  // Already rectified: the images are published as stored.
  EXPECT_EQ(cv::norm(f.left, cv::imread((dir / "image_l/000050.png").string(), cv::IMREAD_GRAYSCALE), cv::NORM_INF), 0);
  EXPECT_EQ(cv::norm(f.right, cv::imread((dir / "image_r/000050.png").string(), cv::IMREAD_GRAYSCALE), cv::NORM_INF), 0);
  ASSERT_TRUE(f.gt_pose);
  EXPECT_EQ(f.gt_pose->frame_id, "kitti");
  EXPECT_LT((f.gt_pose->T_world_camera.translation() - poses[50].translation()).norm(), 1e-12);
  // ~60 m driven forward (z) over the chunk.
  EXPECT_NEAR(f.gt_pose->T_world_camera.translation().norm(), 59.9, 1.0);
}

TEST(KittiSource, BadInputsNameTheFile) {
  AERIE_REQUIRE_DATA(kKitti);
  const auto data = test::shared_data(kKitti);
  const auto dir = test::scratch_dir("kitti");
  EXPECT_ERROR_NAMES(load_kitti((dir / "nope").string()), "nope");
  EXPECT_ERROR_NAMES(load_kitti(dir.string()), "image_0/ and image_1/");
  fs::create_directory_symlink(data / "image_l", dir / "image_l");
  fs::create_directory_symlink(data / "image_r", dir / "image_r");
  EXPECT_ERROR_NAMES(load_kitti(dir.string()), "calib.txt");
  // A calibration of a larger camera: the principal point is outside these images.
  write_text(dir / "calib.txt",
             "2000 0 1500 0 0 2000 900 0 0 0 1 0\n2000 0 1500 -1000 0 2000 900 0 0 0 1 0\n");
  EXPECT_ERROR_NAMES(load_kitti(dir.string()), "calib.txt (left camera): principal point");
  fs::copy_file(data / "calib.txt", dir / "calib.txt", fs::copy_options::overwrite_existing);
  write_text(dir / "times.txt", "0\n0.1\n");
  EXPECT_ERROR_NAMES(load_kitti(dir.string()), "times.txt: 2 times for 51 frames");
  fs::remove(dir / "times.txt");
  const auto s = load_kitti(dir.string());
  EXPECT_EQ(s.utimes[10], 1'000'000);  // no times.txt: 10 Hz
  EXPECT_TRUE(s.gt.empty());
}

TEST(EurocSource, RectifiedPairsDrivenByCam0) {
  AERIE_REQUIRE_DATA(kEuroc);
  const auto dir = test::shared_data(kEuroc);
  const auto seq = load_euroc(dir.string(), (dir / "groundtruth/V101_gt.txt").string());
  // cam1/data.csv has 4 more rows than there are images: cam0 drives.
  EXPECT_EQ(seq.left.size(), 95u);
  for (const auto& r : seq.right) EXPECT_TRUE(fs::exists(r)) << r;
  StereoSequenceSource src(seq, false);
  EXPECT_EQ(src.size(), cv::Size(752, 480));
  const camera::StereoRectifier reference(camera::read_euroc_stereo((dir / "mav0").string()));
  const auto r = src.rectified();
  ASSERT_TRUE(r);
  EXPECT_DOUBLE_EQ(r->fx, reference.rectified().fx);
  EXPECT_DOUBLE_EQ(r->cx, reference.rectified().cx);
  EXPECT_NEAR(r->baseline, 0.110, 0.001);

  src.seek(7);
  Frame f;
  ASSERT_TRUE(src.next(f));
  EXPECT_EQ(f.index, 7);
  EXPECT_EQ(f.utime, seq.utimes[7]);
  const std::string name = fs::path(seq.left[7]).stem().string();  // <ns>.png
  EXPECT_EQ(f.utime, std::stoll(name) / 1000);
  cv::Mat l, rr;
  reference.rectify(cv::imread(seq.left[7], cv::IMREAD_GRAYSCALE), cv::imread(seq.right[7], cv::IMREAD_GRAYSCALE), l, rr);
  EXPECT_EQ(cv::norm(f.left, l, cv::NORM_INF), 0);
  EXPECT_EQ(cv::norm(f.right, rr, cv::NORM_INF), 0);

  // Ground truth: body pose (TUM) composed with cam0's T_BS and the rectifying rotation.
  ASSERT_TRUE(f.gt_pose);
  const auto body = read_tum((dir / "groundtruth/V101_gt.txt").string());
  const auto T_wb = interpolate(body, f.utime, 100'000);
  ASSERT_TRUE(T_wb);
  const auto T_bs = camera::read_euroc_camera((dir / "mav0/cam0/sensor.yaml").string()).T_body_sensor;
  const auto expect = *T_wb * T_bs;
  EXPECT_LT((f.gt_pose->T_world_camera.translation() - expect.translation()).norm(), 1e-9);
  // The optical axes differ only by the small rectifying rotation.
  const double angle = geometry::rotation_angle(expect.rotation_matrix().transpose() * f.gt_pose->T_world_camera.rotation_matrix());
  EXPECT_GT(angle, 1e-5);
  EXPECT_LT(angle, 0.05);
}

// A scratch EuRoC folder: the first n cam0/cam1 rows of the excerpt (images linked).
fs::path euroc_copy(const std::string& name, int n) {
  const auto src = test::shared_data(kEuroc) / "mav0";
  const auto dir = test::scratch_dir(name);
  for (const char* cam : {"cam0", "cam1"}) {
    fs::create_directories(dir / "mav0" / cam);
    fs::copy_file(src / cam / "sensor.yaml", dir / "mav0" / cam / "sensor.yaml");
    fs::create_directory_symlink(src / cam / "data", dir / "mav0" / cam / "data");
    std::ifstream in(src / cam / "data.csv");
    std::ofstream out(dir / "mav0" / cam / "data.csv");
    std::string line;
    for (int i = 0; i <= n && std::getline(in, line); ++i) out << line << "\n";
  }
  return dir;
}

TEST(EurocSource, Cam0RowWithoutCam1IsAnUnreadableFrame) {
  AERIE_REQUIRE_DATA(kEuroc);
  const auto dir = euroc_copy("euroc", 5);
  // Drop cam1's row of frame 2.
  const auto csv = dir / "mav0/cam1/data.csv";
  std::ifstream in(csv);
  std::vector<std::string> lines;
  for (std::string l; std::getline(in, l);) lines.push_back(l);
  in.close();
  lines.erase(lines.begin() + 3);
  std::ofstream out(csv);
  for (const auto& l : lines) out << l << "\n";
  out.close();

  StereoSequenceSource src(load_euroc(dir.string()), false);
  EXPECT_EQ(src.frame_count(), 5);
  Frame f;
  ASSERT_TRUE(src.next(f));
  ASSERT_TRUE(src.next(f));
  EXPECT_ERROR_NAMES(src.next(f), "no right image");
  ASSERT_TRUE(src.next(f));
  EXPECT_EQ(f.index, 3);
  EXPECT_FALSE(f.gt_pose);  // no ground truth in this folder
}

TEST(EurocSource, CalibrationSizeMismatchNamesTheFiles) {
  AERIE_REQUIRE_DATA(kEuroc);
  const auto dir = euroc_copy("euroc", 3);
  for (const char* cam : {"cam0", "cam1"}) {
    const auto yaml = dir / "mav0" / cam / "sensor.yaml";
    std::ifstream in(yaml);
    std::string text((std::istreambuf_iterator<char>(in)), {});
    in.close();
    text.replace(text.find("[752, 480]"), 10, "[640, 480]");
    write_text(yaml, text);
  }
  const std::string msg = error_of([&] { StereoSequenceSource(load_euroc(dir.string()), false); });
  EXPECT_NE(msg.find("sensor.yaml"), std::string::npos) << msg;
  EXPECT_NE(msg.find("640x480"), std::string::npos) << msg;
  EXPECT_NE(msg.find("752x480"), std::string::npos) << msg;
  EXPECT_NE(msg.find(".png"), std::string::npos) << msg;
}

TEST(EurocSource, MissingFilesAreNamed) {
  AERIE_REQUIRE_DATA(kEuroc);
  const auto dir = test::scratch_dir("euroc");
  EXPECT_ERROR_NAMES(load_euroc((dir / "none").string()), "none");
  fs::create_directories(dir / "mav0" / "cam0");
  EXPECT_ERROR_NAMES(load_euroc(dir.string()), "cam0/data.csv");
}

TEST(VideoFileSource, ReadsFramesWithTheFileRate) {
  const auto dir = test::scratch_dir("video");
  const auto file = (dir / "clip.avi").string();
  cv::VideoWriter w(file, cv::VideoWriter::fourcc('M', 'J', 'P', 'G'), 15.0, {64, 48}, true);
  if (!w.isOpened()) GTEST_SKIP() << "OpenCV cannot write MJPG/AVI here";
  for (int i = 0; i < 6; ++i) {
    cv::Mat c;
    cv::cvtColor(pattern(i), c, cv::COLOR_GRAY2BGR);
    w.write(c);
  }
  w.release();
  VideoFileSource src(file, 0, false);
  EXPECT_EQ(src.frame_count(), 6);
  EXPECT_EQ(src.size(), cv::Size(64, 48));
  Frame f;
  int n = 0;
  while (src.next(f)) {
    EXPECT_EQ(f.left.type(), CV_8UC1);
    EXPECT_EQ(f.utime, std::llround(n * 1e6 / 15.0));
    EXPECT_LT(cv::norm(f.left, pattern(n), cv::NORM_L1) / f.left.total(), 12.0) << "JPEG-compressed frame " << n;
    ++n;
  }
  EXPECT_EQ(n, 6);
  EXPECT_ERROR_NAMES(VideoFileSource((dir / "none.avi").string(), 20, false), "none.avi");
  write_text(dir / "junk.avi", "not a video");
  EXPECT_ERROR_NAMES(VideoFileSource((dir / "junk.avi").string(), 20, false), "junk.avi");
}

SourceOptions source(const std::string& type, const std::string& path = "") {
  SourceOptions o;
  o.type = type;
  o.path = path;
  return o;
}

// The simulator source: frames at the rig size, times from start_utime, ground truth
// equal to the simulator's own, and the helipad box in the image when it is visible.
TEST(SimSource, FramesTimesAndGroundTruth) {
  SimSourceOptions o;
  o.start_utime = 5'000'000;
  SimSource src(o, 188, 120, false, 10.0);
  EXPECT_TRUE(src.stereo());
  EXPECT_EQ(src.size(), cv::Size(188, 120));
  const auto r = src.rectified();
  ASSERT_TRUE(r);
  EXPECT_DOUBLE_EQ(r->baseline, 0.12);
  EXPECT_NEAR(r->fx, 94.0 / std::tan(49.0 * CV_PI / 180), 1e-9);  // 98 deg horizontal field of view
  EXPECT_GT(src.frame_count(), 400);  // about a minute at 10 Hz

  const auto world = sim::World::room(sim::WorldConfig{});
  sim::RigConfig rig;
  rig.width = 188;
  rig.height = 120;
  const sim::StereoSimulation reference(world, rig, sim::Trajectory::demo_flight(world, 0.8), 10.0, 5'000'000);
  EXPECT_EQ(src.frame_count(), reference.frame_count());
  // A frame with the helipad in view (found from the ground truth alone, without rendering).
  int k = -1;
  for (int i = 0; i < reference.frame_count() && k < 0; i += 5) {
    sim::StereoFrame probe;
    reference.renderer().project_helipad(reference.trajectory().pose(reference.time_of(i)) * reference.T_body_left(), probe);
    if (probe.target_visible) k = i;
  }
  ASSERT_GE(k, 0) << "the helipad is never in view";
  src.seek(k);
  Frame f;
  ASSERT_TRUE(src.next(f));
  const auto expect = reference.frame(k);
  EXPECT_EQ(f.index, k);
  EXPECT_EQ(f.utime, 5'000'000 + k * 100'000);
  EXPECT_EQ(cv::norm(f.left, expect.left, cv::NORM_INF), 0);
  EXPECT_EQ(cv::norm(f.right, expect.right, cv::NORM_INF), 0);
  ASSERT_TRUE(f.gt_pose);
  EXPECT_EQ(f.gt_pose->frame_id, "sim");
  EXPECT_LT((f.gt_pose->T_world_camera.translation() - expect.T_world_left.translation()).norm(), 1e-12);
  ASSERT_TRUE(f.gt_box);
  EXPECT_TRUE(expect.target_visible);
  EXPECT_TRUE(f.gt_box->visible);
  EXPECT_EQ(f.gt_box->box, expect.target_box);
  EXPECT_EQ(f.gt_box->target, "helipad");

  SimSourceOptions bad;
  bad.trajectory = "loop-the-loop";
  EXPECT_ERROR_NAMES(SimSource(bad, 0, 0, false, 20), "loop-the-loop");
}

TEST(KittiSource, DownloadLayoutFindsItsPosesAndAGivenFileIsUsed) {
  // Issue 18: dataset/sequences/NN with dataset/poses/NN.txt gave frames but no GT_POSE.
  AERIE_REQUIRE_DATA(kKitti);
  const auto data = test::shared_data(kKitti);
  const auto root = test::scratch_dir("kitti_download");
  const auto seq = root / "dataset" / "sequences" / "06";
  fs::create_directories(seq);
  fs::create_directories(root / "dataset" / "poses");
  for (const char* f : {"image_l", "image_r"}) fs::create_directory_symlink(data / f, seq / f);
  fs::copy_file(data / "calib.txt", seq / "calib.txt");
  fs::copy_file(data / "times.txt", seq / "times.txt");
  EXPECT_TRUE(load_kitti(seq.string()).gt.empty());  // no poses anywhere: frames without truth
  fs::copy_file(data / "poses.txt", root / "dataset" / "poses" / "06.txt");
  const auto poses = read_kitti_poses((data / "poses.txt").string());
  const StereoSequence found = load_kitti(seq.string());
  ASSERT_EQ(found.gt.size(), 51u);
  EXPECT_LT((found.gt[50]->translation() - poses[50].translation()).norm(), 1e-12);
  // An explicit poses file (--groundtruth) wins; a missing one is an error naming it.
  EXPECT_EQ(load_kitti(seq.string(), (data / "poses.txt").string()).gt.size(), 51u);
  EXPECT_ERROR_NAMES(load_kitti(seq.string(), (root / "nope.txt").string()), "nope.txt: KITTI poses file does not exist");
}

TEST(SourceFactory, BadOptionsAreExplained) {
  EXPECT_ERROR_NAMES(make_source(source("lidar")), "unknown source type 'lidar'");
  SourceOptions folder = source("folder", "/tmp");
  folder.groundtruth = "poses.txt";  // was silently ignored
  EXPECT_ERROR_NAMES(make_source(folder), "--groundtruth) applies to euroc and kitti sources, not to 'folder'");
  EXPECT_ERROR_NAMES(make_source(source("kitti")), "needs a path");
  EXPECT_ERROR_NAMES(make_source(source("v4l2", "/dev/video-none")), "/dev/video-none");
}

OutputOptions output(int width, int height, double downscale) {
  OutputOptions o;
  o.width = width;
  o.height = height;
  o.downscale = downscale;
  return o;
}

TEST(OutputFormat, DownscaleScalesImagesIntrinsicsAndBoxes) {
  OutputFormat fmt(output(0, 0, 2.0), {752, 480});
  EXPECT_EQ(fmt.size(), cv::Size(376, 240));
  camera::RectifiedStereo in{400, 410, 375.5, 239.5, 0.11, {752, 480}};
  const auto out = fmt.apply(in);
  EXPECT_DOUBLE_EQ(out.fx, 200);
  EXPECT_DOUBLE_EQ(out.fy, 205);
  EXPECT_DOUBLE_EQ(out.cx, 187.5);  // the image centre stays the centre
  EXPECT_DOUBLE_EQ(out.cy, 119.5);
  EXPECT_DOUBLE_EQ(out.baseline, 0.11);

  Frame f;
  f.left = cv::Mat(480, 752, CV_8UC3, cv::Scalar(10, 20, 30));
  f.right = f.left.clone();
  f.gt_box = GroundTruthBox{"helipad", true, {99.5, 199.5, 40, 20}, {}};
  f.gt_box->corners[1] = {139.5, 199.5};
  fmt.apply(f);
  EXPECT_EQ(f.left.size(), cv::Size(376, 240));
  EXPECT_EQ(f.left.type(), CV_8UC1);  // gray by default
  EXPECT_EQ(f.right.size(), cv::Size(376, 240));
  EXPECT_DOUBLE_EQ(f.gt_box->box.x, 49.5);
  EXPECT_DOUBLE_EQ(f.gt_box->box.width, 20);
  EXPECT_DOUBLE_EQ(f.gt_box->corners[1].x, 69.5);

  EXPECT_THROW(OutputFormat(output(100, 0, 1), {752, 480}), std::invalid_argument);
  EXPECT_THROW(OutputFormat(output(0, 0, 0.5), {752, 480}), std::invalid_argument);
  Frame wrong;
  wrong.left = cv::Mat(100, 100, CV_8UC1);
  EXPECT_THROW(fmt.apply(wrong), FrameError);
}

TEST(Pacer, RealTimeMultiplesAndAsFastAsPossible) {
  Pacer real(1.0), twice(2.0), fast(0.0);
  EXPECT_EQ(real.due(5'000'000, 100), 100);
  EXPECT_EQ(real.due(5'050'000, 999), 50'100);
  EXPECT_EQ(twice.due(0, 0), 0);
  EXPECT_EQ(twice.due(100'000, 0), 50'000);
  EXPECT_EQ(fast.due(123'456'789, 42), 42);
  EXPECT_THROW(Pacer(-1), std::invalid_argument);
}

}  // namespace
}  // namespace aerie::capture
