// aerie-log's library: info (types by fingerprint, counts, rates, dropped messages,
// corrupt payloads, damage), export (TUM trajectories, PNG images, a stereo channel
// to a KITTI-style folder that the capture source reads back) and cut.
#include <gtest/gtest.h>

#include <aerie/gt_pose_t.hpp>
#include <aerie/image_t.hpp>
#include <aerie/stereo_image_t.hpp>

#include <filesystem>
#include <fstream>
#include <opencv2/imgcodecs.hpp>
#include <sstream>

#include "air/capture/dataset_io.hpp"
#include "air/capture/stereo_sequence_source.hpp"
#include "common/image/image_message.hpp"
#include "common/logio/event_log.hpp"
#include "tests/support/test_support.hpp"
#include "tools/log/log_cut.hpp"
#include "tools/log/log_export.hpp"
#include "tools/log/log_info.hpp"

namespace aerie::logtools {
namespace {
namespace fs = std::filesystem;

template <typename Msg>
std::vector<uint8_t> encode(const Msg& m) {
  std::vector<uint8_t> buf(static_cast<size_t>(m.getEncodedSize()));
  m.encode(buf.data(), 0, static_cast<int>(buf.size()));
  return buf;
}

aerie::gt_pose_t pose(int64_t utime, int64_t seq) {
  aerie::gt_pose_t p{};
  p.utime = utime;
  p.seq = seq;
  p.frame_id = "sim";
  p.position[0] = 0.5 * static_cast<double>(seq);
  p.position[1] = -1.25;
  p.position[2] = 3.0;
  const Eigen::Quaterniond q(Eigen::AngleAxisd(0.1 * static_cast<double>(seq), Eigen::Vector3d(1, 2, 3).normalized()));
  p.orientation[0] = q.w();
  p.orientation[1] = q.x();
  p.orientation[2] = q.y();
  p.orientation[3] = q.z();
  return p;
}

cv::Mat texture(int i, cv::Size size = {40, 30}) {
  cv::Mat img(size, CV_8UC1);
  cv::RNG rng(static_cast<uint64_t>(i) + 7);
  rng.fill(img, cv::RNG::UNIFORM, 0, 256);
  return img;
}

aerie::stereo_image_t stereo(int64_t utime, int64_t seq) {
  aerie::stereo_image_t s;
  s.utime = utime;
  s.seq = seq;
  s.left = image::to_message(texture(static_cast<int>(2 * seq)), utime, seq);
  s.right = image::to_message(texture(static_cast<int>(2 * seq + 1)), utime, seq);
  s.fx = 200.5;
  s.fy = 201.25;
  s.cx = 19.5;
  s.cy = 14.5;
  s.baseline_m = 0.12;
  return s;
}

// 20 Hz for 1 s: GT_POSE (seq 4 missing: dropped), CAM_LEFT images (one corrupt),
// CAM_STEREO pairs, and a channel of bytes that no Aerie type matches.
fs::path make_log(const fs::path& dir) {
  const auto path = dir / "flight.lcm";
  logio::Writer w(path.string());
  const int64_t t0 = 1'700'000'000'000'000;
  for (int i = 0; i < 20; ++i) {
    const int64_t t = t0 + 50'000 * i;
    if (i != 4) {
      const auto b = encode(pose(t, i));
      w.write(t + 100, "GT_POSE", b.data(), b.size());
    }
    auto img = encode(image::to_message(texture(i), t, i));
    if (i == 7) img.resize(img.size() / 2);  // corrupt: cut short
    w.write(t + 200, "CAM_LEFT", img.data(), img.size());
    const auto st = encode(stereo(t, i));
    w.write(t + 300, "CAM_STEREO", st.data(), st.size());
    if (i % 5 == 0) {
      const std::string junk = "hello world, no fingerprint here";
      w.write(t + 400, "RAW", junk.data(), junk.size());
    }
  }
  return path;
}

const ChannelSummary& channel(const LogSummary& s, const std::string& name) {
  for (const auto& c : s.channels)
    if (c.channel == name) return c;
  throw std::runtime_error("no channel " + name);
}

TEST(LogInfo, TypesCountsRatesAndDrops) {
  const auto dir = test::scratch_dir("log");
  const auto s = summarize(make_log(dir).string());
  EXPECT_EQ(s.events, 19 + 20 + 20 + 4);
  EXPECT_TRUE(s.damage.empty());
  EXPECT_NEAR(s.duration_s, 0.95 + 0.0003 - 0.0001, 1e-9);
  ASSERT_EQ(s.channels.size(), 4u);
  const auto& gt = channel(s, "GT_POSE");
  EXPECT_EQ(gt.type, "aerie.gt_pose_t");
  EXPECT_EQ(gt.count, 19);
  EXPECT_EQ(gt.seq_gaps, 1);  // seq 4 never arrived
  EXPECT_NEAR(gt.rate_hz, 18.0 / 0.95, 1e-9);
  EXPECT_NEAR(gt.max_gap_s, 0.1, 1e-9);
  const auto& cam = channel(s, "CAM_LEFT");
  EXPECT_EQ(cam.type, "aerie.image_t");
  EXPECT_EQ(cam.count, 20);
  EXPECT_EQ(cam.undecodable, 1);
  EXPECT_EQ(cam.seq_gaps, 0);  // seq from the image metadata; the corrupt message is not a drop
  EXPECT_NEAR(cam.rate_hz, 20.0, 0.1);
  EXPECT_EQ(channel(s, "CAM_STEREO").type, "aerie.stereo_image_t");
  EXPECT_EQ(channel(s, "CAM_STEREO").seq_gaps, 0);
  EXPECT_NE(channel(s, "RAW").type.find("unknown"), std::string::npos);
  EXPECT_FALSE(channel(s, "RAW").has_seq);
  EXPECT_EQ(s.dropped(), 1);

  std::ostringstream table, json;
  print_summary(s, table);
  print_summary_json(s, json);
  EXPECT_NE(table.str().find("dropped messages (sequence gaps): 1"), std::string::npos) << table.str();
  EXPECT_NE(json.str().find("\"seq_gaps\": 1"), std::string::npos);
}

TEST(LogInfo, TruncatedLogStillSummarisesWhatPrecedes) {
  const auto dir = test::scratch_dir("log");
  const auto path = make_log(dir);
  const auto full = logio::read_all(path.string());
  const auto& cut_at = full.events[30];
  fs::resize_file(path, cut_at.offset + 40);
  const auto s = summarize(path.string());
  EXPECT_EQ(s.events, 30);
  ASSERT_EQ(s.damage.size(), 1u);
  EXPECT_EQ(s.damage[0].offset, cut_at.offset);
  EXPECT_EQ(s.damage[0].event_number, 30);
  std::ostringstream out;
  print_summary(s, out);
  EXPECT_NE(out.str().find("DAMAGE"), std::string::npos);
}

TEST(LogExport, PosesToTum) {
  const auto dir = test::scratch_dir("log");
  const auto r = export_channel(make_log(dir).string(), "GT_POSE", (dir / "out").string());
  EXPECT_EQ(r.type, "aerie.gt_pose_t");
  EXPECT_EQ(r.exported, 19);
  const auto traj = capture::read_tum((dir / "out/GT_POSE.tum").string());
  ASSERT_EQ(traj.size(), 19u);
  const int64_t t0 = 1'700'000'000'000'000;
  for (const int i : {0, 5, 19}) {
    const auto it = traj.find(t0 + 50'000 * i);
    ASSERT_NE(it, traj.end()) << i;
    const auto p = pose(0, i);
    EXPECT_NEAR(it->second.translation().x(), p.position[0], 1e-9);
    EXPECT_NEAR(it->second.translation().y(), p.position[1], 1e-9);
    EXPECT_NEAR(it->second.rotation().w(), p.orientation[0], 1e-9);
    EXPECT_NEAR(it->second.rotation().z(), p.orientation[3], 1e-9);
  }
  std::ifstream in(dir / "out/GT_POSE.tum");
  std::string first;
  std::getline(in, first);
  EXPECT_EQ(first.rfind("1700000000.000000 0.000000000 -1.250000000 3.000000000 ", 0), 0u) << first;
}

TEST(LogExport, ImagesToPngSkippingTheCorruptOne) {
  const auto dir = test::scratch_dir("log");
  const auto r = export_channel(make_log(dir).string(), "CAM_LEFT", (dir / "img").string());
  EXPECT_EQ(r.exported, 19);
  EXPECT_EQ(r.undecodable, 1);
  const auto files = capture::list_images((dir / "img").string());
  ASSERT_EQ(files.size(), 19u);
  EXPECT_EQ(cv::norm(cv::imread(files[8], cv::IMREAD_UNCHANGED), texture(9), cv::NORM_INF), 0);  // frame 7 skipped
  EXPECT_EQ(capture::read_timestamps((dir / "img/times.txt").string()).size(), 19u);
}

// Export a stereo channel, then play the folder with the KITTI source: same pixels,
// intrinsics, baseline and times.
TEST(LogExport, StereoToKittiFolderReadableByCapture) {
  const auto dir = test::scratch_dir("log");
  const auto r = export_channel(make_log(dir).string(), "CAM_STEREO", (dir / "kitti").string());
  EXPECT_EQ(r.exported, 20);
  capture::StereoSequenceSource src(capture::load_kitti((dir / "kitti").string()), false);
  EXPECT_EQ(src.frame_count(), 20);
  const auto rect = src.rectified();
  ASSERT_TRUE(rect);
  EXPECT_NEAR(rect->fx, 200.5, 1e-9);
  EXPECT_NEAR(rect->fy, 201.25, 1e-9);
  EXPECT_NEAR(rect->cx, 19.5, 1e-9);
  EXPECT_NEAR(rect->baseline, 0.12, 1e-12);
  capture::Frame f;
  for (int i = 0; i < 20; ++i) {
    ASSERT_TRUE(src.next(f));
    EXPECT_EQ(f.utime, 1'700'000'000'000'000 + 50'000 * i);
    EXPECT_EQ(cv::norm(f.left, texture(2 * i), cv::NORM_INF), 0);
    EXPECT_EQ(cv::norm(f.right, texture(2 * i + 1), cv::NORM_INF), 0);
  }
}

TEST(LogExport, ErrorsNameTheChannel) {
  const auto dir = test::scratch_dir("log");
  const auto log = make_log(dir).string();
  try {
    export_channel(log, "VO_POSE", (dir / "x").string());
    FAIL();
  } catch (const std::runtime_error& e) {
    const std::string m = e.what();
    EXPECT_NE(m.find("no messages on channel VO_POSE"), std::string::npos) << m;
    EXPECT_NE(m.find("CAM_STEREO"), std::string::npos) << m;
  }
}

TEST(LogExport, TruncatedLogExportsWhatPrecedes) {
  const auto dir = test::scratch_dir("log");
  const auto path = make_log(dir);
  const auto full = logio::read_all(path.string());
  fs::resize_file(path, full.events[25].offset + 10);
  const auto r = export_channel(path.string(), "GT_POSE", (dir / "out").string());
  // Events 0..24 hold frames 0..7 (frame 4 has no pose): 7 poses.
  EXPECT_EQ(r.exported, 7);
  ASSERT_EQ(r.damage.size(), 1u);
  EXPECT_EQ(capture::read_tum((dir / "out/GT_POSE.tum").string()).size(), 7u);
}

TEST(LogCut, TimeRangeFromTheStart) {
  const auto dir = test::scratch_dir("log");
  const auto log = make_log(dir).string();
  const auto out = (dir / "cut.lcm").string();
  const auto r = cut(log, 0.2, 0.4, out);
  EXPECT_TRUE(r.damage.empty());
  const auto cut_log = logio::read_all(out);
  ASSERT_EQ(static_cast<int64_t>(cut_log.events.size()), r.events_written);
  // Frames 4..7 (t - t0 in [0.2, 0.4) s relative to the first event at +100 µs):
  // frame 4 has no pose and one RAW, so 3 + 4 + 4 + 1 events.
  EXPECT_EQ(r.events_written, 12);
  for (size_t i = 0; i < cut_log.events.size(); ++i) EXPECT_EQ(cut_log.events[i].event_number, static_cast<int64_t>(i));
  const auto s = summarize(out);
  EXPECT_EQ(channel(s, "CAM_STEREO").count, 4);
  EXPECT_THROW(cut(log, 0.5, 0.1, out), std::invalid_argument);
  EXPECT_THROW(cut(log, 0, 1, log), std::invalid_argument);
}

TEST(LogCut, RefusesToOverwriteAnExistingOutputWithoutForce) {
  const auto dir = test::scratch_dir("log");
  const auto log = make_log(dir).string();
  const auto out = (dir / "cut.lcm").string();
  std::ofstream(out) << "a recording";
  try {
    cut(log, 0.2, 0.4, out);
    FAIL();
  } catch (const std::invalid_argument& e) {
    EXPECT_NE(std::string(e.what()).find("cut.lcm exists; pass --force to overwrite it"), std::string::npos) << e.what();
  }
  std::ifstream in(out);
  EXPECT_EQ(std::string((std::istreambuf_iterator<char>(in)), std::istreambuf_iterator<char>()), "a recording");
  EXPECT_EQ(cut(log, 0.2, 0.4, out, false, true).events_written, 12);  // --force
}

TEST(LogExport, RefusesANonEmptyOutputFolderWithoutForce) {
  const auto dir = test::scratch_dir("log");
  const auto log = make_log(dir).string();
  fs::create_directories(dir / "empty");
  const int64_t poses = export_channel(log, "GT_POSE", (dir / "empty").string()).exported;  // an empty folder is fine
  EXPECT_GT(poses, 0);
  const auto tum = dir / "empty" / "GT_POSE.tum";
  std::ofstream(tum) << "edited by hand\n";
  try {
    export_channel(log, "GT_POSE", (dir / "empty").string());
    FAIL();
  } catch (const std::runtime_error& e) {
    EXPECT_NE(std::string(e.what()).find("exists and is not an empty folder; pass --force"), std::string::npos) << e.what();
  }
  std::ifstream in(tum);
  EXPECT_EQ(std::string((std::istreambuf_iterator<char>(in)), std::istreambuf_iterator<char>()), "edited by hand\n");
  EXPECT_EQ(export_channel(log, "GT_POSE", (dir / "empty").string(), false, true).exported, poses);  // --force
  EXPECT_EQ(static_cast<int64_t>(capture::read_tum(tum.string()).size()), poses);
}

TEST(LogInfo, AnEmptyLogIsReportedAsEmpty) {
  const auto dir = test::scratch_dir("log");
  std::ofstream(dir / "empty.lcm").close();
  const auto s = summarize((dir / "empty.lcm").string());
  EXPECT_EQ(s.events, 0);
  std::ostringstream out;
  print_summary(s, out);
  EXPECT_NE(out.str().find("empty:    the log holds no events"), std::string::npos) << out.str();
  EXPECT_EQ(out.str().find("damage:   none"), std::string::npos) << out.str();
}

TEST(LogInfo, AHostilePayloadIsCountedAsCorrupt) {
  // The log of the reproducer aerie-log_info_segv_track_cmd_strlen_INT_MIN.lcm: a TRACK_CMD
  // whose string length is INT_MIN, between two good events.
  const auto dir = test::scratch_dir("log");
  const auto payload = [] {
    std::ifstream in(std::string(AERIE_SOURCE_DIR) + "/tests/data/reliability/track_cmd_strlen_INT_MIN.bin", std::ios::binary);
    return std::vector<uint8_t>(std::istreambuf_iterator<char>(in), std::istreambuf_iterator<char>());
  }();
  ASSERT_FALSE(payload.empty());
  const auto path = (dir / "hostile.lcm").string();
  {
    logio::Writer w(path);
    const uint8_t raw[3] = {1, 2, 3};
    w.write(1000, "RAW", raw, sizeof raw);
    w.write(2000, "TRACK_CMD", payload.data(), payload.size());
    w.write(3000, "RAW", raw, sizeof raw);
    w.close();
  }
  const auto s = summarize(path);
  EXPECT_EQ(s.events, 3);
  EXPECT_EQ(channel(s, "TRACK_CMD").undecodable, 1);
  EXPECT_TRUE(s.damage.empty());
}

}  // namespace
}  // namespace aerie::logtools
