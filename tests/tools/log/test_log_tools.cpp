// aerie-log's library: info (types by fingerprint, counts, rates, logger losses told apart
// from producer skips, corrupt payloads, damage), export (TUM trajectories, PNG images, a
// stereo channel to a KITTI-style folder that the capture source reads back, tracks to OTB
// boxes), cut, and diff (by order, seq or utime; also through the executable, for its exit status).
#include <gtest/gtest.h>

#include <aerie/gt_pose_t.hpp>
#include <aerie/image_t.hpp>
#include <aerie/pose_t.hpp>
#include <aerie/stereo_image_t.hpp>
#include <aerie/track_t.hpp>

#include <sys/wait.h>

#include <cmath>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <opencv2/imgcodecs.hpp>
#include <sstream>

#include "air/capture/dataset_io.hpp"
#include "air/capture/stereo_sequence_source.hpp"
#include "air/track/eval/box_file_score.hpp"
#include "air/track/eval/sequence.hpp"
#include "common/bus/wire.hpp"
#include "common/image/image_message.hpp"
#include "common/logio/event_log.hpp"
#include "tests/support/test_support.hpp"
#include "tools/log/log_cut.hpp"
#include "tools/log/log_diff.hpp"
#include "tools/log/log_export.hpp"
#include "tools/log/log_info.hpp"
#include "tools/log/message_fields.hpp"

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

TEST(LogCut, ExcludesTheChannelsAReplayWillPublishAgain) {
  const auto dir = test::scratch_dir("log");
  const auto log = make_log(dir).string();
  const auto out = (dir / "cut.lcm").string();
  const auto all = summarize(log);
  const auto r = cut(log, 0, std::numeric_limits<double>::infinity(), out, false, false, "GT_.*|CAM_STEREO");
  const auto s = summarize(out);
  for (const auto& c : all.channels) {
    const bool gone = c.channel.starts_with("GT_") || c.channel == "CAM_STEREO";
    const bool kept = std::any_of(s.channels.begin(), s.channels.end(), [&](const auto& k) { return k.channel == c.channel; });
    EXPECT_EQ(kept, !gone) << c.channel;
    if (kept) {
      EXPECT_EQ(channel(s, c.channel).count, c.count) << c.channel;
    }
  }
  EXPECT_GT(r.events_written, 0);
  EXPECT_LT(r.events_written, r.events_read);
  try {
    cut(log, 0, 1, (dir / "x.lcm").string(), false, false, "GT_(");
    FAIL() << "accepted a bad regular expression";
  } catch (const std::invalid_argument& e) {
    EXPECT_NE(std::string(e.what()).find("--exclude 'GT_(' is not a regular expression"), std::string::npos) << e.what();
  }
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


aerie::track_t track(int64_t utime, int64_t seq, int8_t status, double x, double y, int64_t frames_skipped = 0) {
  aerie::track_t m{};
  m.utime = utime;
  m.seq = seq;
  m.tracker = "ipsl";
  m.camera = "CAM_DOWN";
  m.status = status;
  if (status != aerie::track_t::IDLE) {
    m.x = x;
    m.y = y;
    m.scale = 1;
    m.width = 40;
    m.height = 20;
    m.confidence = 0.75f;
  }
  m.frames_skipped = frames_skipped;
  return m;
}

aerie::track_level_t level(int n) {
  aerie::track_level_t l{};
  l.npoints = n;
  for (int i = 0; i < n; ++i) {
    l.u.push_back(static_cast<float>(i));
    l.v.push_back(static_cast<float>(2 * i));
    l.score.push_back(0.5f);
  }
  return l;
}

// What info tells apart: GT_POSE (own numbering) misses seq 4: the logger lost it. VO_POSE
// copies the stereo pair's seq and has none for pairs 2, 5, 6: aerie-vo skipped them. TRACK
// reports 4 skipped frames in frames_skipped. LCM's self-test string is there too, and two
// events are missing from the numbering (taken out of the log after recording).
TEST(LogInfo, LoggerLossIsToldApartFromProducerSkips) {
  const auto dir = test::scratch_dir("log");
  const auto path = (dir / "flight.lcm").string();
  {
    logio::Writer w(path);
    logio::Event ev;
    auto put = [&](int64_t utime, const std::string& channel, std::vector<uint8_t> data) {
      ev.utime = utime;
      ev.channel = channel;
      ev.data = std::move(data);
      w.write(ev, true);
      ++ev.event_number;
    };
    const std::string self_test = "lcm self test";
    put(0, "LCM_SELF_TEST", {self_test.begin(), self_test.end()});
    const int64_t skipped[] = {2, 2, 3, 5, 5, 6};
    for (int i = 0; i < 10; ++i) {
      const int64_t t = 1'000'000 + 50'000 * i;
      if (i != 4) put(t, "GT_POSE", encode(pose(t, i)));
      if (i != 2 && i != 5 && i != 6) {
        aerie::pose_t vo{};
        vo.utime = t;
        vo.seq = i;
        vo.orientation[0] = 1;
        put(t + 30'000, "VO_POSE", encode(vo));
      }
      if (i < 6) put(t + 40'000, "TRACK", encode(track(t, i, aerie::track_t::TRACKING, 100, 50, skipped[i])));
      if (i == 7) ev.event_number += 2;
    }
    w.close();
  }
  const auto s = summarize(path);
  EXPECT_EQ(s.event_number_gaps, 2);
  const auto& gt = channel(s, "GT_POSE");
  EXPECT_FALSE(gt.seq_follows_frames);
  EXPECT_EQ(gt.logger_lost(), 1);
  EXPECT_EQ(gt.producer_skipped(), 0);
  const auto& vo = channel(s, "VO_POSE");
  EXPECT_TRUE(vo.seq_follows_frames);
  EXPECT_EQ(vo.seq_gaps, 3);
  EXPECT_EQ(vo.logger_lost(), 0);
  EXPECT_EQ(vo.producer_skipped(), 3);
  const auto& tr = channel(s, "TRACK");
  EXPECT_EQ(tr.seq_gaps, 0);
  EXPECT_EQ(tr.frames_skipped, 4);  // 2 -> 6 during the log; the 2 before its first message are not counted
  EXPECT_EQ(tr.producer_skipped(), 4);
  EXPECT_EQ(s.dropped(), 4);
  EXPECT_EQ(s.logger_lost(), 1);
  EXPECT_EQ(s.producer_skipped(), 7);
  EXPECT_EQ(channel(s, "LCM_SELF_TEST").type, "lcm self-test (string)");

  std::ostringstream table, json;
  print_summary(s, table);
  print_summary_json(s, json);
  const std::string t = table.str();
  const auto has = [&](const std::string& text) { return t.find(text) != std::string::npos; };
  EXPECT_TRUE(has("dropped messages (sequence gaps): 4, of which logger lost 1, skipped by producers 3\n")) << t;
  EXPECT_TRUE(has("\nlogger lost: 1 (published, never recorded: GT_POSE 1)\n")) << t;
  EXPECT_TRUE(has("\nskipped by producers (by design, per channel): TRACK 4, VO_POSE 3 (camera frames without a "
                  "result)\n"))
      << t;
  EXPECT_NE(t.find("events missing from the log's numbering: 2"), std::string::npos) << t;
  EXPECT_NE(t.find("LCM_SELF_TEST      lcm self-test (string)"), std::string::npos) << t;
  EXPECT_EQ(t.find("unknown"), std::string::npos) << t;
  EXPECT_NE(json.str().find("\"logger_lost\": 1,"), std::string::npos) << json.str();
  EXPECT_NE(json.str().find("\"producer_skipped\": 7,"), std::string::npos) << json.str();
}

TEST(LogInfo, NothingLostNothingSkipped) {
  const auto dir = test::scratch_dir("log");
  const auto path = (dir / "clean.lcm").string();
  {
    logio::Writer w(path);
    for (int i = 0; i < 3; ++i) {
      const auto b = encode(pose(1000 * i, i));
      w.write(1000 * i, "GT_POSE", b.data(), b.size());
    }
  }
  std::ostringstream out;
  print_summary(summarize(path), out);
  EXPECT_NE(out.str().find("dropped messages (sequence gaps): 0\nlogger lost: 0\n"
                           "skipped by producers (by design, per channel): none\n"),
            std::string::npos)
      << out.str();
}

// One row per TRACK message; the OTB file holds the top-left corner and size, NaN while IDLE,
// and reads back with the OTB reader the tracker benchmark uses.
TEST(LogExport, TrackToOtbBoxes) {
  const auto dir = test::scratch_dir("log");
  const auto path = (dir / "track.lcm").string();
  {
    logio::Writer w(path);
    const int8_t status[] = {aerie::track_t::IDLE, aerie::track_t::TRACKING, aerie::track_t::TRACKING,
                             aerie::track_t::LOST};
    for (int i = 0; i < 4; ++i) {
      const auto b = encode(track(1'700'000'000'000'000 + 50'000 * i, i, status[i], 100.5 + i, 60));
      w.write(50'000 * i, "TRACK", b.data(), b.size());
    }
  }
  const auto r = export_channel(path, "TRACK", (dir / "out").string());
  EXPECT_EQ(r.type, "aerie.track_t");
  EXPECT_EQ(r.exported, 4);
  std::ifstream csv(dir / "out/TRACK.csv");
  std::vector<std::string> rows;
  for (std::string line; std::getline(csv, line);) rows.push_back(line);
  ASSERT_EQ(rows.size(), 5u);
  EXPECT_EQ(rows[0], "t,seq,x,y,w,h,status,confidence");
  EXPECT_EQ(rows[1], "1700000000.000000,0,NaN,NaN,NaN,NaN,IDLE,0.000");
  EXPECT_EQ(rows[2], "1700000000.050000,1,81.500,50.000,40.000,20.000,TRACKING,0.750");
  EXPECT_EQ(rows[4], "1700000000.150000,3,83.500,50.000,40.000,20.000,LOST,0.750");
  const auto boxes = track::eval::read_boxes(dir / "out/TRACK.txt");
  ASSERT_EQ(boxes.size(), 4u);
  EXPECT_FALSE(track::eval::is_valid_box(boxes[0]));
  EXPECT_EQ(boxes[2], cv::Rect2d(82.5, 50, 40, 20));  // centre (102.5, 60), 40 x 20
}

// The tracker skipped frames 3 and 7 of its camera: the OTB file still has one row per source
// frame, NaN where no track exists, so row i lines up with frame i of groundtruth.txt.
TEST(LogExport, TrackHasOneRowPerSourceFrame) {
  const auto dir = test::scratch_dir("log");
  const auto path = (dir / "track.lcm").string();
  const int64_t t0 = 1'700'000'000'000'000;
  {
    logio::Writer w(path);
    for (int i = 0; i < 10; ++i) {
      const int64_t t = t0 + 50'000 * i;
      const auto img = encode(image::to_message(texture(i), t, 100 + i));
      w.write(t, "CAM_MONO", img.data(), img.size());
      if (i == 3 || i == 7) continue;
      auto tr = track(t, i, aerie::track_t::TRACKING, 100.5 + i, 60);
      tr.camera = "CAM_MONO";
      const auto b = encode(tr);
      w.write(t + 20'000, "TRACK", b.data(), b.size());
    }
  }
  const auto r = export_channel(path, "TRACK", (dir / "out").string());
  EXPECT_EQ(r.exported, 8);
  EXPECT_EQ(r.camera, "CAM_MONO");
  EXPECT_EQ(r.frames, 10);
  EXPECT_EQ(r.skipped_frames, 2);
  EXPECT_TRUE(r.notes.empty());
  const auto boxes = track::eval::read_boxes(dir / "out/TRACK.txt");
  ASSERT_EQ(boxes.size(), 10u);  // the source's frame count
  for (int i = 0; i < 10; ++i) {
    EXPECT_EQ(track::eval::is_valid_box(boxes[i]), i != 3 && i != 7) << i;
    if (i != 3 && i != 7) {
      EXPECT_EQ(boxes[i], cv::Rect2d(80.5 + i, 50, 40, 20)) << i;  // frame i's own box
    }
  }
  std::ifstream csv(dir / "out/TRACK.csv");
  std::vector<std::string> rows;
  for (std::string line; std::getline(csv, line);) rows.push_back(line);
  ASSERT_EQ(rows.size(), 11u);
  EXPECT_EQ(rows[4], "1700000000.150000,103,NaN,NaN,NaN,NaN,SKIPPED,NaN");  // the frame's own seq
  EXPECT_EQ(rows[5], "1700000000.200000,4,84.500,50.000,40.000,20.000,TRACKING,0.750");
  // Scored against the sequence's ground truth (the true box of every frame), frame by frame:
  // the 8 tracked frames are exact, the 2 skipped ones failures.
  std::vector<cv::Rect2d> gt;
  for (int i = 0; i < 10; ++i) gt.emplace_back(80.5 + i, 50, 40, 20);
  track::eval::write_boxes(dir / "groundtruth.txt", gt);
  const auto scored = track::eval::score_box_file(dir / "out/TRACK.txt", dir / "groundtruth.txt");
  EXPECT_EQ(scored.missing, 2);
  EXPECT_NEAR(scored.score.auc, 0.8 * 20.0 / 21.0, 1e-12);
  EXPECT_NEAR(scored.score.precision20, 0.8, 1e-12);

  // Tracks that name another camera than the one in the log: one row per message, and a note;
  // --camera names the source.
  {
    logio::Writer w((dir / "other.lcm").string());
    for (const auto& ev : logio::read_all(path).events) {
      auto out = ev;
      if (ev.channel == "TRACK") {
        auto m = bus::decode_bounded<aerie::track_t>(ev.data.data(), ev.data.size());
        m.camera = "CAM_LEFT";
        out.data = encode(m);
      }
      w.write(out);
    }
  }
  const auto plain = export_channel((dir / "other.lcm").string(), "TRACK", (dir / "plain").string());
  EXPECT_EQ(plain.frames, 0);
  EXPECT_EQ(track::eval::read_boxes(dir / "plain/TRACK.txt").size(), 8u);
  ASSERT_EQ(plain.notes.size(), 1u);
  EXPECT_NE(plain.notes[0].find("no frames of CAM_LEFT in the log"), std::string::npos) << plain.notes[0];
  const auto named =
      export_channel((dir / "other.lcm").string(), "TRACK", (dir / "named").string(), false, false, "CAM_MONO");
  EXPECT_EQ(named.frames, 10);
  EXPECT_EQ(track::eval::read_boxes(dir / "named/TRACK.txt").size(), 10u);
}

TEST(MessageFields, NamesTheFieldOfTheLargestDifference) {
  auto a = track(1000, 3, aerie::track_t::TRACKING, 100, 50);
  a.levels = {level(2), level(3)};
  a.nlevels = 2;
  auto b = a;
  b.x += 2.5;
  b.levels[1].u[2] += 3.5f;
  b.tracker = "ct";
  auto ea = encode(a), eb = encode(b);
  auto f = compare_fields(ea.data(), ea.size(), eb.data(), eb.size());
  ASSERT_TRUE(f.comparable);
  EXPECT_EQ(f.type, "aerie.track_t");
  EXPECT_EQ(f.field, "levels[1].u[2]");
  EXPECT_DOUBLE_EQ(f.max_abs, 3.5);
  EXPECT_EQ(f.text, "tracker");
  EXPECT_EQ(f.shape, "");

  b.corners[2][1] = 7;  // a two-dimensional array: row-major indices
  b.levels.pop_back();  // levels cannot be paired any more: reported, skipped
  b.nlevels = 1;
  eb = encode(b);
  f = compare_fields(ea.data(), ea.size(), eb.data(), eb.size());
  EXPECT_EQ(f.field, "corners[2][1]");
  EXPECT_DOUBLE_EQ(f.max_abs, 7);
  EXPECT_EQ(f.shape, "levels: 2 vs 1 elements");

  b = a;
  b.confidence = NAN;
  eb = encode(b);
  f = compare_fields(ea.data(), ea.size(), eb.data(), eb.size());
  EXPECT_EQ(f.field, "confidence");
  EXPECT_TRUE(std::isinf(f.max_abs));

  const std::string text = "not a message";
  const auto* bytes = reinterpret_cast<const uint8_t*>(text.data());
  EXPECT_FALSE(compare_fields(ea.data(), ea.size(), bytes, text.size()).comparable);
  ea.resize(ea.size() - 3);  // truncated: does not decode
  EXPECT_FALSE(compare_fields(ea.data(), ea.size(), eb.data(), eb.size()).comparable);
}

// B: the log of make_log with GT_POSE message 6 moved by 0.75 m in y, one pixel of the right
// image of stereo pair 3 changed by 64, and the last CAM_LEFT image missing.
fs::path make_changed_log(const fs::path& a, const fs::path& dir) {
  const auto path = dir / "changed.lcm";
  const auto events = logio::read_all(a.string()).events;
  logio::Writer w(path.string());
  int64_t gt = 0, stereo_pairs = 0, cam = 0;
  for (auto ev : events) {
    if (ev.channel == "GT_POSE" && gt++ == 6) {
      auto p = bus::decode_bounded<aerie::gt_pose_t>(ev.data.data(), ev.data.size());
      p.position[1] += 0.75;
      ev.data = encode(p);
    }
    if (ev.channel == "CAM_STEREO" && stereo_pairs++ == 3) {
      auto st = bus::decode_bounded<aerie::stereo_image_t>(ev.data.data(), ev.data.size());
      st.right.data[123] ^= 0x40;  // 64 brighter or darker
      ev.data = encode(st);
    }
    if (ev.channel == "CAM_LEFT" && ++cam == 20) continue;
    w.write(ev);
  }
  return path;
}

const ChannelDiff& channel(const LogDiff& d, const std::string& name) {
  for (const auto& c : d.channels)
    if (c.channel == name) return c;
  throw std::runtime_error("no channel " + name);
}

TEST(LogDiff, IdenticalLogs) {
  const auto a = make_log(test::scratch_dir("a")), b = make_log(test::scratch_dir("b"));
  const auto d = diff_logs(a.string(), b.string());
  EXPECT_TRUE(d.same());
  ASSERT_EQ(d.channels.size(), 4u);
  EXPECT_EQ(channel(d, "GT_POSE").identical, 19);
  EXPECT_EQ(channel(d, "CAM_LEFT").identical, 20);  // the corrupt one too: the same bytes
  std::ostringstream out;
  print_diff(d, out);
  EXPECT_NE(out.str().find("same: every message of the 4 channel(s) compared is identical"), std::string::npos)
      << out.str();
}

TEST(LogDiff, CountsIdenticalMessagesAndTheLargestFieldDifference) {
  const auto dir = test::scratch_dir("log");
  const auto a = make_log(dir);
  const auto b = make_changed_log(a, dir);
  const auto d = diff_logs(a.string(), b.string());
  EXPECT_FALSE(d.same());
  const auto& gt = channel(d, "GT_POSE");
  EXPECT_EQ(gt.type, "aerie.gt_pose_t");
  EXPECT_EQ(gt.count_a, 19);
  EXPECT_EQ(gt.count_b, 19);
  EXPECT_EQ(gt.identical, 18);
  EXPECT_EQ(gt.field, "position[1]");
  EXPECT_NEAR(gt.max_abs, 0.75, 1e-12);
  EXPECT_EQ(gt.at, 6);
  EXPECT_FALSE(gt.same());
  const auto& st = channel(d, "CAM_STEREO");
  EXPECT_EQ(st.identical, 19);
  EXPECT_EQ(st.field, "right.data[123]");
  EXPECT_EQ(st.at, 3);
  EXPECT_EQ(st.max_abs, 64);
  const auto& cam = channel(d, "CAM_LEFT");
  EXPECT_EQ(cam.count_a, 20);
  EXPECT_EQ(cam.count_b, 19);
  EXPECT_EQ(cam.identical, 19);
  EXPECT_FALSE(cam.same());
  EXPECT_TRUE(channel(d, "RAW").same());
  EXPECT_NE(channel(d, "RAW").type.find("unknown"), std::string::npos);

  std::ostringstream out;
  print_diff(d, out);
  EXPECT_NE(out.str().find("GT_POSE            aerie.gt_pose_t                19       19         18  position[1] 0.75 "
                           "(message 6)\n"),
            std::string::npos)
      << out.str();
  EXPECT_NE(out.str().find("different: 3 of 4 channel(s): CAM_LEFT, CAM_STEREO, GT_POSE"), std::string::npos)
      << out.str();

  const auto only = diff_logs(a.string(), b.string(), {"RAW", "CAM_LEFT"});
  ASSERT_EQ(only.channels.size(), 2u);
  EXPECT_FALSE(only.same());
  EXPECT_TRUE(diff_logs(a.string(), b.string(), {"RAW"}).same());
  try {
    diff_logs(a.string(), b.string(), {"RAW", "VO_POSE"});
    FAIL();
  } catch (const std::invalid_argument& e) {
    EXPECT_NE(std::string(e.what()).find("no channel VO_POSE in "), std::string::npos) << e.what();
  }
}

// Messages are paired by order: a message missing from the middle of a channel shifts the
// pairs after it, and the note says what no number shows.
TEST(LogDiff, PairsByOrderWithinTheChannel) {
  const auto dir = test::scratch_dir("log");
  auto write = [&](const std::string& name, std::vector<aerie::track_t> msgs) {
    logio::Writer w((dir / name).string());
    for (const auto& m : msgs) {
      const auto b = encode(m);
      w.write(m.utime, "TRACK", b.data(), b.size());
    }
    return (dir / name).string();
  };
  auto t0 = track(0, 0, aerie::track_t::TRACKING, 10, 10), t1 = track(100, 1, aerie::track_t::TRACKING, 11, 10),
       t2 = track(200, 2, aerie::track_t::TRACKING, 12, 10);
  const auto a = write("a.lcm", {t0, t1, t2});
  t1.levels = {level(1)};
  t1.nlevels = 1;
  const auto b = write("b.lcm", {t0, t1});
  const auto d = diff_logs(a, b);
  const auto& c = channel(d, "TRACK");
  EXPECT_EQ(c.count_a, 3);
  EXPECT_EQ(c.count_b, 2);
  EXPECT_EQ(c.identical, 1);
  EXPECT_EQ(c.field, "nlevels");  // message 1: only the levels differ, and their count
  EXPECT_EQ(c.max_abs, 1);
  EXPECT_EQ(c.at, 1);
  EXPECT_EQ(c.note, "message 1: levels: 0 vs 1 elements");
}

TEST(LogDiff, ADamagedOrMissingLogIsRefusedNamingTheFile) {
  const auto dir = test::scratch_dir("log");
  const auto a = make_log(dir);
  const auto b = dir / "cut_short.lcm";
  fs::copy_file(a, b);
  fs::resize_file(b, fs::file_size(b) - 10);
  try {
    diff_logs(a.string(), b.string());
    FAIL();
  } catch (const std::runtime_error& e) {
    const std::string m = e.what();
    EXPECT_NE(m.find(b.string() + ": truncated at byte"), std::string::npos) << m;
  }
  try {
    diff_logs(a.string(), (dir / "nope.lcm").string());
    FAIL();
  } catch (const std::runtime_error& e) {
    EXPECT_NE(std::string(e.what()).find("nope.lcm: no such log file"), std::string::npos) << e.what();
  }
}

struct Run {
  int status;
  std::string out, err;
};

Run aerie_log(const std::string& args, const fs::path& dir) {
  const auto out = dir / "stdout.txt", err = dir / "stderr.txt";
  const std::string cmd = (test::binary_dir() / "bin" / "aerie-log").string() + " " + args + " > " + out.string() +
                          " 2> " + err.string();
  const int rc = std::system(cmd.c_str());
  auto slurp = [](const fs::path& p) {
    std::ifstream in(p);
    return std::string((std::istreambuf_iterator<char>(in)), std::istreambuf_iterator<char>());
  };
  return {WIFEXITED(rc) ? WEXITSTATUS(rc) : -1, slurp(out), slurp(err)};
}

// The exit status is the interface scripts use: 0 same, 1 different, 2 usage or unreadable log.
TEST(LogDiff, ExitStatusOfTheCommand) {
  const auto dir = test::scratch_dir("log");
  const auto a = make_log(dir);
  const auto b = make_changed_log(a, dir);
  const auto run_dir = test::scratch_dir("run");
  EXPECT_EQ(aerie_log("diff " + a.string() + " " + a.string(), run_dir).status, 0);
  const auto differ = aerie_log("diff " + a.string() + " " + b.string(), run_dir);
  EXPECT_EQ(differ.status, 1);
  EXPECT_NE(differ.out.find("position[1] 0.75 (message 6)"), std::string::npos) << differ.out;
  EXPECT_EQ(aerie_log("diff " + a.string() + " " + b.string() + " --channels RAW,CAM_STEREO", run_dir).status, 1);
  EXPECT_EQ(aerie_log("diff " + a.string() + " " + b.string() + " --channels RAW", run_dir).status, 0);
  EXPECT_EQ(aerie_log("diff --channels RAW " + a.string() + " " + b.string(), run_dir).status, 0);

  const auto missing = aerie_log("diff " + a.string() + " " + (dir / "nope.lcm").string(), run_dir);
  EXPECT_EQ(missing.status, 2);
  EXPECT_NE(missing.err.find("nope.lcm: no such log file"), std::string::npos) << missing.err;
  fs::resize_file(b, fs::file_size(b) - 10);
  const auto truncated = aerie_log("diff " + a.string() + " " + b.string(), run_dir);
  EXPECT_EQ(truncated.status, 2);
  EXPECT_NE(truncated.err.find(b.string() + ": truncated at byte"), std::string::npos) << truncated.err;
  EXPECT_EQ(aerie_log("diff " + a.string(), run_dir).status, 2);  // B missing
  EXPECT_EQ(aerie_log("diff " + a.string() + " " + a.string() + " --bogus", run_dir).status, 2);
  EXPECT_EQ(aerie_log("diff " + a.string() + " " + a.string() + " --channels NOPE", run_dir).status, 2);
  const auto help = aerie_log("diff --help", run_dir);
  EXPECT_EQ(help.status, 0);
  EXPECT_NE(help.out.find("paired by their order within the channel"), std::string::npos) << help.out;
}

// A live run against its replay: B misses frame 2 (a frame the live chain skipped) on every
// keyed channel. Pairing by position shifts every pair after it; by seq or utime exactly one
// frame is missing in B and the rest are identical.
fs::path make_frames_log(const fs::path& path, int skip) {
  logio::Writer w(path.string());
  const int64_t t0 = 1'700'000'000'000'000;
  for (int i = 0; i < 20; ++i) {
    const int64_t t = t0 + 50'000 * i;
    if (i != skip) {
      const auto img = encode(image::to_message(texture(i), t, i));
      w.write(t + 100, "CAM_LEFT", img.data(), img.size());
      const auto tr = encode(track(t, i, aerie::track_t::TRACKING, 100.0 + i, 60));
      w.write(t + 200, "TRACK", tr.data(), tr.size());
      const auto gt = encode(pose(t, i));
      w.write(t + 300, "GT_POSE", gt.data(), gt.size());
    }
    if (i % 5 == 0) {
      const std::string junk = "no fingerprint, no key " + std::to_string(i);
      w.write(t + 400, "RAW", junk.data(), junk.size());
    }
  }
  return path;
}

TEST(LogDiff, PairsBySeqOrUtimeAfterASkippedFrame) {
  const auto dir = test::scratch_dir("log");
  const auto a = make_frames_log(dir / "live.lcm", -1).string(), b = make_frames_log(dir / "replay.lcm", 2).string();

  const auto by_order = diff_logs(a, b);
  for (const char* name : {"CAM_LEFT", "TRACK", "GT_POSE"}) {
    const auto& c = channel(by_order, name);
    EXPECT_EQ(c.paired_by, PairBy::Order);
    EXPECT_EQ(c.count_a, 20);
    EXPECT_EQ(c.count_b, 19);
    EXPECT_EQ(c.matched, 19);
    EXPECT_EQ(c.identical, 2) << name;  // frames 0 and 1; then frame i of A against frame i + 1 of B
    EXPECT_EQ(c.differing(), 17) << name;
    EXPECT_EQ(c.missing_b, 1);
  }

  for (const PairBy by : {PairBy::Utime, PairBy::Seq}) {
    const auto d = diff_logs(a, b, {}, by);
    EXPECT_EQ(d.pair_by, by);
    EXPECT_FALSE(d.same());
    for (const char* name : {"CAM_LEFT", "TRACK", "GT_POSE"}) {
      const auto& c = channel(d, name);
      EXPECT_EQ(c.paired_by, by) << name;
      EXPECT_EQ(c.matched, 19) << name;
      EXPECT_EQ(c.identical, 19) << name;
      EXPECT_EQ(c.differing(), 0) << name;
      EXPECT_EQ(c.missing_a, 0) << name;
      EXPECT_EQ(c.missing_b, 1) << name;
      EXPECT_TRUE(c.field.empty()) << name;
      EXPECT_FALSE(c.same());
    }
    // RAW has no type, so no key: paired by order, and identical.
    EXPECT_EQ(channel(d, "RAW").paired_by, PairBy::Order);
    EXPECT_TRUE(channel(d, "RAW").same());
    std::ostringstream out;
    print_diff(d, out);
    const std::string row = std::string(to_string(by)) + (by == PairBy::Seq ? "   " : " ") +
                            "       20       19       19         0         1        19         0  -\n";
    EXPECT_NE(out.str().find("TRACK              aerie.track_t            " + row), std::string::npos) << out.str();
    EXPECT_NE(out.str().find("different: 3 of 4 channel(s): CAM_LEFT, GT_POSE, TRACK"), std::string::npos)
        << out.str();
  }

  // A changed field is shown at its frame, not at a message index.
  const auto events = logio::read_all(b).events;
  {
    logio::Writer w((dir / "changed.lcm").string());
    for (auto ev : events) {
      if (ev.channel == "TRACK") {
        auto m = bus::decode_bounded<aerie::track_t>(ev.data.data(), ev.data.size());
        if (m.seq == 9) m.x += 2.5;
        ev.data = encode(m);
      }
      w.write(ev);
    }
  }
  const auto& tr = channel(diff_logs(a, (dir / "changed.lcm").string(), {"TRACK"}, PairBy::Seq), "TRACK");
  EXPECT_EQ(tr.identical, 18);
  EXPECT_EQ(tr.differing(), 1);
  EXPECT_EQ(tr.field, "x");
  EXPECT_EQ(tr.at_what, "seq");
  EXPECT_EQ(tr.at, 9);

  // Through the command: the option, its exit status, its refusal.
  const auto run_dir = test::scratch_dir("run");
  const auto run = aerie_log("diff " + a + " " + b + " --pair utime", run_dir);
  EXPECT_EQ(run.status, 1);
  EXPECT_NE(run.out.find("missing B"), std::string::npos) << run.out;
  EXPECT_EQ(aerie_log("diff " + a + " " + a + " --pair seq", run_dir).status, 0);
  EXPECT_EQ(aerie_log("diff " + a + " " + b + " --pair frame", run_dir).status, 2);
  EXPECT_THROW(pair_by_from_string("frame"), std::invalid_argument);
}

TEST(LogInfo, HostileSequenceNumbersSaturateInsteadOfOverflowing) {
  // Fuzzing (fuzz/regressions/event_log/seq_gap_sum_overflow.lcm): seq and frames_skipped read
  // from a log were subtracted and summed in int64_t, which a crafted log overflows.
  const auto dir = test::scratch_dir("log");
  const auto path = (dir / "seq.lcm").string();
  {
    logio::Writer w(path);
    for (int64_t seq : {INT64_MIN + 1, INT64_MAX - 1, int64_t{0}, INT64_MAX}) {
      aerie::track_t t{};
      t.utime = 1000;
      t.seq = seq;
      t.frames_skipped = seq > 0 ? seq : 0;
      t.tracker = "x";
      t.camera = "x";
      std::vector<uint8_t> b(static_cast<size_t>(t.getEncodedSize()));
      t.encode(b.data(), 0, static_cast<int>(b.size()));
      w.write(seq == 0 ? INT64_MIN / 2 : INT64_MAX / 2, "TRACK", b.data(), b.size());
    }
  }
  const auto s = summarize(path);
  ASSERT_EQ(s.channels.size(), 1u);
  EXPECT_EQ(s.channels[0].seq_gaps, INT64_MAX);
  EXPECT_GE(s.channels[0].frames_skipped, 0);
  EXPECT_EQ(s.producer_skipped(), INT64_MAX);
  EXPECT_TRUE(std::isfinite(s.duration_s));
}

}  // namespace
}  // namespace aerie::logtools
