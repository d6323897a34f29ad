// aerie-map's LCM side over memq://: queries, publication, commands, bad inputs.
#include <gtest/gtest.h>

// lcm-gen's decode() reads its hash through an out-parameter that GCC cannot follow.
#pragma GCC diagnostic push
#pragma GCC diagnostic ignored "-Wmaybe-uninitialized"
#include <aerie/map_response_t.hpp>
#include <aerie/octomap_t.hpp>
#include <aerie/process_status_t.hpp>
#pragma GCC diagnostic pop

#include <filesystem>
#include <fstream>
#include <limits>
#include <random>
#include <sstream>

#include "common/spherical/spherical_message.hpp"
#include "ground/map/map_service.hpp"
#include "tests/common/bus/reliability_data.hpp"
#include "tests/ground/map/room_fixture.hpp"
#include "tests/support/test_support.hpp"

namespace m = aerie::map;
using aerie::bus::ReceiveInfo;

namespace {

const aerie::spherical::Intrinsics kCam{260.0, 260.0, 187.5, 119.5, 0.12};
const cv::Size kSize(376, 240);

struct Harness {
  aerie::bus::Bus bus{"memq://"};
  aerie::bus::StatusReporter status{bus, "aerie-map"};
  int64_t now_us = 0;  // the node's clock (lock-step: the test moves it)
  m::MapService service;
  std::vector<aerie::map_response_t> responses;
  std::vector<aerie::octomap_t> maps;
  m::test::Room room;
  aerie::spherical::SphericalEncoder encoder{kCam, kSize};
  int64_t seq = 0;

  explicit Harness(m::MapServiceConfig cfg = {}) : service(bus, status, cfg, [this] { return now_us; }) {
    bus.subscribe<aerie::map_response_t>("MAP_RESPONSE_TEST",
                                         [this](const auto& r, const ReceiveInfo&) { responses.push_back(r); });
    bus.subscribe<aerie::octomap_t>("MAP_OCTOMAP", [this](const auto& r, const ReceiveInfo&) { maps.push_back(r); });
  }
  void spin() {
    while (bus.handle(0) > 0) {
    }
  }
  aerie::spherical_depth_t depth_msg(int64_t utime, const aerie::geometry::SE3& T, bool with_pose) {
    const auto d = encoder.encode_depth(m::test::render_depth(room, T, kCam, kSize));
    return aerie::spherical::to_message(d, utime, seq++, with_pose ? std::optional(T) : std::nullopt);
  }
  aerie::pose_t pose_msg(int64_t utime, const aerie::geometry::SE3& T) {
    aerie::pose_t p{};
    p.utime = utime;
    p.seq = seq++;
    T.to_wxyz(p.orientation);
    for (int i = 0; i < 3; ++i) p.position[i] = T.translation()[i];
    p.status = aerie::pose_t::OK;
    return p;
  }
  aerie::map_response_t query(int8_t kind, const Eigen::Vector3d& p, const Eigen::Vector3d& dir = {1, 0, 0},
                              double max_range = 5.0, int depth = 0) {
    aerie::map_query_t q{};
    q.utime = 42;
    q.seq = seq++;
    q.kind = kind;
    for (int i = 0; i < 3; ++i) {
      q.point[i] = p[i];
      q.direction[i] = dir[i];
    }
    q.max_range = max_range;
    q.depth = depth;
    q.reply_channel = "MAP_RESPONSE_TEST";
    responses.clear();
    bus.publish("MAP_QUERY", q);
    spin();
    EXPECT_EQ(responses.size(), 1u);
    if (responses.empty()) return {};
    EXPECT_EQ(responses.back().seq, q.seq);
    return responses.back();
  }
  int64_t counter(const std::string& name) const { return status.counter(name); }
};

// Four views of the room from its west half.
std::vector<aerie::geometry::SE3> views() {
  std::vector<aerie::geometry::SE3> v;
  for (int i = 0; i < 8; ++i) v.push_back(m::test::camera_pose({-1.0, 0.0, 1.2}, i * M_PI / 4));
  return v;
}

}  // namespace

TEST(MapService, QueriesRoundTripOverMemq) {
  Harness h;
  int64_t t = 1'000'000;
  for (const auto& T : views()) {
    h.bus.publish("VO_DEPTH", h.depth_msg(t, T, true));
    t += 50'000;
  }
  h.spin();
  EXPECT_EQ(h.counter("frames_mapped"), 8);
  EXPECT_EQ(h.counter("pose_from_depth"), 8);

  // The west wall (x = -3) seen from (-1, 0, 1.2).
  auto r = h.query(aerie::map_query_t::RAY, {-1.0, 0.0, 1.2}, {-1.0, 0.0, 0.0}, 5.0);
  EXPECT_TRUE(r.error.empty()) << r.error;
  EXPECT_EQ(r.occupancy, aerie::map_response_t::OCCUPIED);
  EXPECT_NEAR(r.distance, 2.0, 0.15);
  EXPECT_NEAR(r.hit[0], -3.0, 0.1);
  EXPECT_NEAR(r.voxel_size, 0.1, 1e-9);

  r = h.query(aerie::map_query_t::OCCUPANCY, {r.hit[0], r.hit[1], r.hit[2]});
  EXPECT_EQ(r.occupancy, aerie::map_response_t::OCCUPIED);
  EXPECT_GT(r.probability, 0.5);
  r = h.query(aerie::map_query_t::OCCUPANCY, {-1.5, 0.0, 1.2});
  EXPECT_EQ(r.occupancy, aerie::map_response_t::FREE);
  r = h.query(aerie::map_query_t::OCCUPANCY, {-1.5, 0.0, 1.2}, {}, 0, 13);  // 0.8 m cells
  EXPECT_NEAR(r.voxel_size, 0.8, 1e-9);

  // Nearest obstacle from a point 0.5 m from the west wall, inside the room.
  r = h.query(aerie::map_query_t::NEAREST_OBSTACLE, {-2.5, 0.0, 1.2}, {}, 0);
  EXPECT_TRUE(r.error.empty()) << r.error;
  EXPECT_NEAR(r.distance, 0.5, 0.15);
  EXPECT_NEAR(r.hit[0], -3.0, 0.1);
  r = h.query(aerie::map_query_t::NEAREST_OBSTACLE, {-2.5, 0.0, 1.2}, {}, 0.3);  // search radius 0.3 m
  EXPECT_LT(r.distance, 0);

  // Bad queries get an error in the reply and a count.
  r = h.query(aerie::map_query_t::OCCUPANCY, {0, 0, 0}, {}, 0, 20);
  EXPECT_NE(r.error.find("depth"), std::string::npos) << r.error;
  r = h.query(99, {0, 0, 0});
  EXPECT_NE(r.error.find("unknown query kind"), std::string::npos) << r.error;
  r = h.query(aerie::map_query_t::RAY, {0, 0, 0}, {0, 0, 0});
  EXPECT_FALSE(r.error.empty());
  EXPECT_EQ(h.counter("query_errors"), 3);
}

TEST(MapService, MatchesPosesByUtimeAndCountsBadInputs) {
  Harness h;
  const auto T = views()[0];
  // Depth without a pose, then its VO_POSE: mapped with the VO pose.
  h.bus.publish("VO_DEPTH", h.depth_msg(1'000'000, T, false));
  h.spin();
  EXPECT_EQ(h.counter("depth_waiting_for_pose"), 1);
  EXPECT_EQ(h.counter("frames_mapped"), 0);
  h.bus.publish("VO_POSE", h.pose_msg(1'000'000, T));
  h.spin();
  EXPECT_EQ(h.counter("frames_mapped"), 1);
  EXPECT_EQ(h.counter("pose_from_vo"), 1);

  // A pose first, then its depth (without its own pose): matched at once.
  h.bus.publish("VO_POSE", h.pose_msg(1'050'000, T));
  h.bus.publish("VO_DEPTH", h.depth_msg(1'050'400, T, false));  // within the 1 ms tolerance
  h.spin();
  EXPECT_EQ(h.counter("frames_mapped"), 2);

  // Depth whose pose never comes: dropped once newer messages pass the wait, with a message.
  h.bus.publish("VO_DEPTH", h.depth_msg(1'100'000, T, false));
  h.bus.publish("VO_POSE", h.pose_msg(1'700'000, T));
  h.spin();
  EXPECT_EQ(h.counter("depth_without_pose"), 1);
  EXPECT_EQ(h.counter("frames_mapped"), 2);

  // A pose far in the future is held (the message-time policy); mapping goes on.
  h.bus.publish("VO_POSE", h.pose_msg(1'700'000 + 3600'000'000LL, T));
  h.spin();
  EXPECT_EQ(h.counter("VO.time_jumps"), 1);
  h.bus.publish("VO_DEPTH", h.depth_msg(1'750'000, T, true));
  h.spin();
  EXPECT_EQ(h.counter("frames_mapped"), 3);

  // Out of order: still mapped, and counted.
  h.bus.publish("VO_DEPTH", h.depth_msg(1'200'000, T, true));
  h.spin();
  EXPECT_EQ(h.counter("frames_mapped"), 4);
  EXPECT_EQ(h.counter("depth_out_of_order"), 1);

  // NaN in the pose, a negative range, an inconsistent grid, NaN ranges: malformed, dropped.
  auto bad = h.depth_msg(1'800'000, T, true);
  bad.position[0] = std::numeric_limits<double>::quiet_NaN();
  h.bus.publish("VO_DEPTH", bad);
  bad = h.depth_msg(1'800'000, T, true);
  bad.range[0] = -5;
  h.bus.publish("VO_DEPTH", bad);
  bad = h.depth_msg(1'800'000, T, true);
  bad.polar_step_rad = std::numeric_limits<float>::quiet_NaN();
  h.bus.publish("VO_DEPTH", bad);
  bad = h.depth_msg(1'800'000, T, true);
  bad.range_scale_m = std::numeric_limits<float>::quiet_NaN();  // NaN ranges (r = range * scale)
  h.bus.publish("VO_DEPTH", bad);
  aerie::pose_t bad_pose = h.pose_msg(1'800'000, T);
  bad_pose.orientation[0] = 3.0;
  h.bus.publish("VO_POSE", bad_pose);
  h.spin();
  EXPECT_EQ(h.counter("depth_malformed"), 4);
  EXPECT_EQ(h.counter("poses_invalid"), 1);
  EXPECT_EQ(h.counter("frames_mapped"), 4);
}

TEST(MapService, PosesAfterABackwardStepInTimeAreKeptForMatching) {
  m::MapServiceConfig cfg;
  cfg.pose_buffer = 10;
  Harness h(cfg);
  const auto T = views()[0];
  // A full buffer: 10 poses from 5.0 s.
  for (int i = 0; i < 10; ++i) h.bus.publish("VO_POSE", h.pose_msg(5'000'000 + i * 50'000, T));
  h.spin();
  // Time steps back 2 s (within the 10 s jump limit, so not a new time base): the new poses are
  // the earliest in the buffer, and the buffer evicts the oldest received, not the earliest.
  for (int i = 0; i < 3; ++i) {
    h.bus.publish("VO_POSE", h.pose_msg(3'000'000 + i * 50'000, T));
    h.bus.publish("VO_DEPTH", h.depth_msg(3'000'000 + i * 50'000, T, false));
  }
  h.spin();
  EXPECT_EQ(h.counter("VO.time_jumps"), 0);
  EXPECT_EQ(h.counter("pose_from_vo"), 3);
  EXPECT_EQ(h.counter("frames_mapped"), 3);
  EXPECT_EQ(h.counter("depth_waiting_for_pose"), 0);
}

TEST(MapService, RecoversFromA25SecondOutageAndARestartAndReportsTheOutage) {
  // Issue 20: after any VO outage longer than 10 s (and after one bogus future utime) the map
  // dropped every VO_POSE/VO_DEPTH for good as "N s ahead of the newest message". Lock-step:
  // the node clock moves with the frames, 20 Hz.
  m::MapServiceConfig cfg;
  cfg.publish_period_s = 0.5;
  Harness h(cfg);
  const auto v = views();
  int frame = 0;
  auto fly = [&](int64_t utime0, int frames) {  // VO_POSE + VO_DEPTH (without its own pose)
    for (int k = 0; k < frames; ++k, ++frame) {
      const auto& T = v[static_cast<size_t>(frame) % v.size()];
      const int64_t utime = utime0 + k * 50'000;
      h.bus.publish("VO_DEPTH", h.depth_msg(utime, T, false));
      h.bus.publish("VO_POSE", h.pose_msg(utime, T));
      h.spin();
      h.service.tick();
      h.now_us += 50'000;
    }
  };
  aerie::process_status_t published{};
  h.bus.subscribe<aerie::process_status_t>(h.status.channel(),
                                           [&](const auto& m, const ReceiveInfo&) { published = m; });
  auto health = [&] {
    h.status.publish_now();
    h.spin();
    return published.health;
  };
  h.now_us = 1'000'000'000;
  fly(1'000'000, 10);
  EXPECT_EQ(h.counter("frames_mapped"), 10);
  EXPECT_EQ(h.counter("VO.stale"), 0);

  // The camera stops for 25 s: the map reports VO stale after message_time.stale_timeout_s (2 s).
  for (int k = 0; k < 250; ++k, h.now_us += 100'000) h.service.tick();
  EXPECT_EQ(h.counter("VO.stale"), 1);
  EXPECT_EQ(h.counter("VO.outages"), 1);
  EXPECT_EQ(h.status.message().rfind("VO stale: no message for 2.", 0), 0u) << h.status.message();
  EXPECT_EQ(health(), aerie::process_status_t::WARN);
  EXPECT_EQ(published.message, h.status.message());

  // It restarts 25 s later: the first 2 messages (one frame's depth and pose) are held, the
  // 3rd re-synchronises, and every later frame is mapped; status OK again.
  const size_t maps_before = h.maps.size();
  fly(26'500'000, 20);
  EXPECT_EQ(h.counter("VO.time_jumps"), 2);
  EXPECT_EQ(h.counter("VO.time_resyncs"), 1);
  EXPECT_EQ(h.counter("frames_mapped"), 10 + 19);  // the first frame back (its depth and pose) was held
  EXPECT_EQ(h.counter("VO.stale"), 0);
  EXPECT_EQ(health(), aerie::process_status_t::OK) << published.message;
  EXPECT_GT(h.maps.size(), maps_before);  // publication goes on in the new message time

  // One bogus future utime is held and does not disturb the next frames.
  h.bus.publish("VO_POSE", h.pose_msg(std::numeric_limits<int64_t>::max(), v[0]));
  h.spin();
  fly(27'500'000, 5);
  EXPECT_EQ(h.counter("VO.time_jumps"), 3);
  EXPECT_EQ(h.counter("frames_mapped"), 29 + 5);

  // VO restarts from utime 0 (backwards): re-synchronised after 3 messages; the poses of the
  // old time base are dropped, so a depth at a reused utime is never matched with an old pose.
  fly(1'000'000, 10);  // the utimes of the first flight again
  EXPECT_EQ(h.counter("VO.time_resyncs"), 2);
  EXPECT_EQ(h.counter("frames_mapped"), 34 + 9);
  EXPECT_EQ(h.counter("VO.stale"), 0);
  EXPECT_EQ(health(), aerie::process_status_t::OK) << published.message;
}

TEST(MapService, PublishesFullAndChangedRegionAndObeysCommands) {
  const auto dir = aerie::test::scratch_dir("cmd");
  m::MapServiceConfig cfg;
  cfg.publish_period_s = 0.1;
  cfg.full_every = 3;
  cfg.files_directory = dir.string();
  Harness h(cfg);
  int64_t t = 0;
  for (const auto& T : views()) {
    h.bus.publish("VO_DEPTH", h.depth_msg(t, T, true));
    t += 60'000;  // 8 frames over 0.42 s: a publication at most every 0.1 s of message time
  }
  h.spin();
  // Frames at 0, 60, ..., 420 ms; publications at 0, 120, 240, 360 ms: full, changed, changed, full.
  ASSERT_EQ(h.maps.size(), 4u);
  const std::vector<int64_t> utimes{0, 120'000, 240'000, 360'000};
  for (size_t i = 0; i < 4; ++i) {
    EXPECT_EQ(h.maps[i].utime, utimes[i]);
    EXPECT_EQ(h.maps[i].full, i % 3 == 0) << i;
  }
  for (const auto& msg : h.maps) {
    ASSERT_EQ(msg.length, static_cast<int32_t>(msg.data.size()));
    std::istringstream in(std::string(msg.data.begin(), msg.data.end()));
    octomap::OcTree tree(0.1);
    ASSERT_TRUE(tree.readBinary(in)) << "seq " << msg.seq;
    EXPECT_GT(tree.size(), 0u);
    EXPECT_DOUBLE_EQ(tree.getResolution(), 0.1);
  }
  // A changed region holds less than the whole map.
  EXPECT_LT(h.maps[2].length, h.maps[3].length);
  EXPECT_LT(h.maps[2].bbox_max[1] - h.maps[2].bbox_min[1], h.maps[3].bbox_max[1] - h.maps[3].bbox_min[1] + 1e-9);

  // Commands: save, clear, load, publish.
  const std::string path = (dir / "saved.ot").string();
  aerie::map_cmd_t cmd{};
  cmd.command = aerie::map_cmd_t::SAVE;
  cmd.path = "saved.ot";  // a name in files.directory
  h.bus.publish("MAP_CMD", cmd);
  h.spin();
  ASSERT_TRUE(std::filesystem::exists(path));
  const Eigen::Vector3d inside(-1.5, 0.0, 1.2);
  EXPECT_EQ(h.query(aerie::map_query_t::OCCUPANCY, inside).occupancy, aerie::map_response_t::FREE);
  cmd.command = aerie::map_cmd_t::CLEAR;
  h.bus.publish("MAP_CMD", cmd);
  h.spin();
  EXPECT_EQ(h.query(aerie::map_query_t::OCCUPANCY, inside).occupancy, aerie::map_response_t::UNKNOWN);
  cmd.command = aerie::map_cmd_t::LOAD;
  h.bus.publish("MAP_CMD", cmd);
  h.spin();
  EXPECT_EQ(h.query(aerie::map_query_t::OCCUPANCY, inside).occupancy, aerie::map_response_t::FREE);
  h.maps.clear();
  cmd.command = aerie::map_cmd_t::PUBLISH_FULL;
  h.bus.publish("MAP_CMD", cmd);
  h.spin();
  ASSERT_EQ(h.maps.size(), 1u);
  EXPECT_TRUE(h.maps[0].full);
  cmd.command = aerie::map_cmd_t::LOAD;
  cmd.path = "nope.bt";
  h.bus.publish("MAP_CMD", cmd);
  h.spin();
  EXPECT_EQ(h.counter("command_errors"), 1);
  EXPECT_EQ(h.counter("commands_done"), 4);
}

TEST(MapService, ConfigFileKeysAreRead) {
  const auto cfg = m::MapServiceConfig::from_config(
      aerie::util::Config::load((aerie::test::source_dir() / "config" / "map.yaml").string()));
  EXPECT_DOUBLE_EQ(cfg.occupancy.resolution, 0.1);
  EXPECT_DOUBLE_EQ(cfg.occupancy.sensor_model.max_range, 5.0);
  EXPECT_DOUBLE_EQ(cfg.occupancy.pointcloud_max_z, 6.0);
  EXPECT_DOUBLE_EQ(cfg.occupancy.stereo.focal_px, 163.0);
  EXPECT_EQ(cfg.full_every, 10);
  EXPECT_EQ(cfg.response_channel, "MAP_RESPONSE");
  EXPECT_EQ(cfg.message_time.max_jump_us, 10'000'000);
  EXPECT_EQ(cfg.message_time.resync_messages, 3);
  EXPECT_EQ(cfg.message_time.stale_timeout_us, 2'000'000);
  try {
    m::MapServiceConfig::from_config(aerie::util::Config::parse("sensor_model:\n  hit: 1.5\n", "bad.yaml"));
    FAIL();
  } catch (const std::runtime_error& e) {
    EXPECT_NE(std::string(e.what()).find("bad.yaml"), std::string::npos);
    EXPECT_NE(std::string(e.what()).find("sensor_model/hit"), std::string::npos);
  }
}

namespace {

// A harness whose map holds the room seen from its west half; MAP_CMD files go to `dir`.
void map_room(Harness& h) {
  int64_t t = 1'000'000;
  for (const auto& T : views()) {
    h.bus.publish("VO_DEPTH", h.depth_msg(t, T, true));
    t += 50'000;
  }
  h.spin();
}

void command(Harness& h, int8_t kind, const std::string& path) {
  aerie::map_cmd_t cmd{};
  cmd.command = kind;
  cmd.path = path;
  h.bus.publish("MAP_CMD", cmd);
  h.spin();
}

std::string slurp(const std::filesystem::path& p) {
  std::ifstream in(p, std::ios::binary);
  return {std::istreambuf_iterator<char>(in), std::istreambuf_iterator<char>()};
}

const Eigen::Vector3d kInside(-1.5, 0.0, 1.2);

}  // namespace

TEST(MapService, SaveAndLoadAreConfinedToTheFilesDirectory) {
  const auto root = aerie::test::scratch_dir("confined");
  m::MapServiceConfig cfg;
  cfg.files_directory = (root / "maps").string();  // created by the first SAVE
  Harness h(cfg);
  map_room(h);
  std::ofstream(root / "outside.ot") << "precious";
  // Paths that leave the directory, or are not plain map names: refused, nothing written.
  const std::vector<std::string> bad{(root / "abs.ot").string(), "../outside.ot", "../escape.ot", "sub/x.ot",
                                     ".hidden.ot", "map.txt", "", std::string(65, 'a') + ".ot"};
  for (const auto& p : bad) command(h, aerie::map_cmd_t::SAVE, p);
  EXPECT_EQ(h.counter("command_errors"), static_cast<int64_t>(bad.size()));
  EXPECT_NE(h.status.message().find("is not a plain map file name"), std::string::npos) << h.status.message();
  EXPECT_FALSE(std::filesystem::exists(root / "abs.ot"));
  EXPECT_FALSE(std::filesystem::exists(root / "escape.ot"));
  EXPECT_EQ(slurp(root / "outside.ot"), "precious");
  for (const auto& p : bad) command(h, aerie::map_cmd_t::LOAD, p);
  EXPECT_EQ(h.counter("command_errors"), 2 * static_cast<int64_t>(bad.size()));

  // SAVE never overwrites: the second save of a name is a new version.
  const auto maps = root / "maps";
  command(h, aerie::map_cmd_t::SAVE, "room.ot");
  ASSERT_TRUE(std::filesystem::exists(maps / "room.ot"));
  const std::string first = slurp(maps / "room.ot");
  std::ofstream(maps / "room-1.ot") << "an older version";
  command(h, aerie::map_cmd_t::SAVE, "room.ot");
  EXPECT_EQ(slurp(maps / "room.ot"), first);
  EXPECT_EQ(slurp(maps / "room-1.ot"), "an older version");
  ASSERT_TRUE(std::filesystem::exists(maps / "room-2.ot"));
  EXPECT_NE(h.status.message().find("room-2.ot"), std::string::npos) << h.status.message();

  // A symbolic link in the directory is neither followed by SAVE nor read by LOAD.
  std::filesystem::create_symlink(root / "outside.ot", maps / "link.ot");
  command(h, aerie::map_cmd_t::SAVE, "link.ot");
  EXPECT_EQ(slurp(root / "outside.ot"), "precious");
  EXPECT_TRUE(std::filesystem::exists(maps / "link-1.ot"));
  const int64_t errors = h.counter("command_errors");
  command(h, aerie::map_cmd_t::LOAD, "link.ot");
  EXPECT_EQ(h.counter("command_errors"), errors + 1);
  EXPECT_NE(h.status.message().find("is a symbolic link"), std::string::npos) << h.status.message();
  command(h, aerie::map_cmd_t::LOAD, "room-2.ot");
  EXPECT_EQ(h.counter("command_errors"), errors + 1);
  EXPECT_EQ(h.query(aerie::map_query_t::OCCUPANCY, kInside).occupancy, aerie::map_response_t::FREE);

  // Without files.directory, SAVE and LOAD over LCM are off.
  Harness off;
  command(off, aerie::map_cmd_t::SAVE, "room.ot");
  EXPECT_EQ(off.counter("command_errors"), 1);
  EXPECT_NE(off.status.message().find("files.directory is not set"), std::string::npos) << off.status.message();
}

TEST(MapService, LoadChecksTheFileAndKeepsTheOldMap) {
  const auto dir = aerie::test::scratch_dir("load");
  m::MapServiceConfig cfg;
  cfg.files_directory = dir.string();
  Harness h(cfg);
  map_room(h);
  // Files of the reproducers: resolutions 1e300 and 1e-300, a .ot with a garbage body, trailing bytes.
  std::ostringstream bt, ot;
  h.service.map().tree().writeBinaryConst(bt);
  h.service.map().tree().write(ot);
  auto with = [](std::string s, const std::string& from, const std::string& to) {
    const auto at = s.find(from);
    EXPECT_NE(at, std::string::npos) << from;
    return at == std::string::npos ? s : s.replace(at, from.size(), to);
  };
  std::ofstream(dir / "res_1e300.bt") << with(bt.str(), "res 0.1\n", "res 1e+300\n");
  std::ofstream(dir / "res_1e-300.bt") << with(bt.str(), "res 0.1\n", "res 1e-300\n");
  std::string garbage = ot.str();
  std::mt19937 rng(7);
  for (size_t i = garbage.find("data\n") + 5; i < garbage.size(); ++i) garbage[i] = static_cast<char>(rng());
  std::ofstream(dir / "garbage.ot") << garbage;
  std::ofstream(dir / "trailing.bt") << bt.str() << "trailing bytes";
  const size_t nodes = h.service.map().tree().size();
  const std::vector<std::pair<std::string, std::string>> bad{
      {"res_1e300.bt", "resolution 1000000"}, {"res_1e-300.bt", "resolution 0.000000 m, outside [0.010000"},
      {"garbage.ot", "garbage data?"}, {"trailing.bt", "followed by bytes"}};  // garbage: too deep or odd log-odds
  int64_t errors = 0;
  for (const auto& [file, why] : bad) {
    command(h, aerie::map_cmd_t::LOAD, file);
    EXPECT_EQ(h.counter("command_errors"), ++errors) << file;
    EXPECT_NE(h.status.message().find(why), std::string::npos) << file << ": " << h.status.message();
    // The live map is the old one.
    EXPECT_DOUBLE_EQ(h.service.map().params().resolution, 0.1) << file;
    EXPECT_EQ(h.service.map().tree().size(), nodes) << file;
    EXPECT_EQ(h.query(aerie::map_query_t::OCCUPANCY, kInside).occupancy, aerie::map_response_t::FREE) << file;
  }
  // The nearest-obstacle query of the reproducer (it crashed DynamicEDT3D after res_1e300.bt):
  // its reply channel FZ_RESPONSE is not a map reply channel, so it is refused; the same query
  // on MAP_RESPONSE_TEST is answered from the old map.
  const auto payload = aerie::test::read_bytes(aerie::test::reliability_data_dir() / "map_query_nearest_obstacle_origin.bin");
  h.bus.publish_raw("MAP_QUERY", payload.data(), static_cast<unsigned>(payload.size()));
  h.spin();
  EXPECT_EQ(h.counter("query_reply_refused"), 1);
  const auto origin = h.query(aerie::map_query_t::NEAREST_OBSTACLE, Eigen::Vector3d::Zero());
  EXPECT_TRUE(origin.error.empty()) << origin.error;
  const auto near = h.query(aerie::map_query_t::NEAREST_OBSTACLE, kInside);
  EXPECT_GT(near.distance, 0.0);
  EXPECT_TRUE(near.error.empty()) << near.error;
}

TEST(MapService, RepliesOnlyOnTheDocumentedReplyChannels) {
  EXPECT_TRUE(m::valid_reply_channel("MAP_RESPONSE", "MAP_RESPONSE"));
  EXPECT_TRUE(m::valid_reply_channel("MAP_RESPONSE_PILOT_2", "MAP_RESPONSE"));
  EXPECT_TRUE(m::valid_reply_channel("MAP_RESPONSE_" + std::string(32, 'x'), "MAP_RESPONSE"));
  for (const std::string& c : std::vector<std::string>{"CTRL_CMD", "MAP_RESPONSE_", "MAP_RESPONSEX", "MAP_RESPONSE_a/b",
                                                      "map_response", "MAP_RESPONSE_" + std::string(33, 'x')})
    EXPECT_FALSE(m::valid_reply_channel(c, "MAP_RESPONSE")) << c;
  Harness h;
  int ctrl = 0;
  h.bus.subscribe<aerie::map_response_t>("CTRL_CMD", [&](const auto&, const ReceiveInfo&) { ++ctrl; });
  aerie::map_query_t q{};
  q.kind = aerie::map_query_t::OCCUPANCY;
  q.reply_channel = "CTRL_CMD";
  h.bus.publish("MAP_QUERY", q);
  h.spin();
  EXPECT_EQ(ctrl, 0);
  EXPECT_EQ(h.counter("query_reply_refused"), 1);
  EXPECT_NE(h.status.message().find("reply channel 'CTRL_CMD' is not MAP_RESPONSE"), std::string::npos)
      << h.status.message();
  h.query(aerie::map_query_t::OCCUPANCY, kInside);  // MAP_RESPONSE_TEST: answered
}

TEST(MapService, ConfigRefusesUnknownKeysAndValuesOutsideTheirRanges) {
  // Duplicate keys are refused by the parser itself, the rest by the config's reader.
  const auto load = [](const std::string& text) {
    m::MapServiceConfig::from_config(aerie::util::Config::parse(text, "map.yaml"));
  };
  const std::vector<std::pair<std::string, std::string>> cases{
      {"resolution: 1e308\n", "key 'resolution' = 1e+308 is outside its valid range [0.01, 10] (line 1)"},
      {"resolution: 1e-300\n", "key 'resolution' = 1e-300 is outside"},
      {"sensor_model:\n  max_range: 1e308\n", "key 'sensor_model.max_range' = 1e+308 is outside its valid range [0.01, 1000] (line 2)"},
      {"distance_map:\n  max_cells: 0\n", "'distance_map.max_cells' = 0 is outside"},
      {"distance_map:\n  max_cells: -5\n", "'distance_map.max_cells' = -5 is outside"},
      {"publish:\n  period_s: .nan\n", "'publish.period_s' = nan is outside its valid range [0, 3600]"},
      {"publish:\n  period_s: -1\n", "'publish.period_s' = -1 is outside"},
      {"matching:\n  pose_buffer: -1\n", "'matching.pose_buffer' = -1 is outside its valid range [1, 100000]"},
      {"message_time:\n  max_jump_s: 1e308\n", "message_time: key 'max_jump_s' = 1e+308 is outside its valid range"},
      {"message_time:\n  resync_messages: -1\n", "message_time: key 'resync_messages' = -1 is outside"},
      {"matching:\n  max_future_us: 10000000\n", "unknown key 'matching.max_future_us'"},
      {"resolutoin: 0.1\n", "unknown key 'resolutoin' (line 1"},
      {"sensor_model: 5\n", "'sensor_model' is a section of keys, not a value (line 1)"},
      {"- resolution: 0.1\n", "expected a map of keys, not a list"},
      {"resolution: 0.1\nresolution: 0.2\n", "duplicate key 'resolution' (line 1 and line 2)"},
  };
  aerie::test::expect_refusals(load, cases);
  EXPECT_EQ(aerie::test::refusal(load, "publish:\n  period_s: 0\n"), "");  // 0 = never publish
}

// Issue 46: 400 MAP_CMD SAVEs wrote 400 files. SAVE writes at most files.max_files files and
// files.max_bytes bytes per run; the refusals are counted with their reason.
TEST(MapService, SaveIsBoundedInFilesAndBytesPerRun) {
  const auto dir = aerie::test::scratch_dir("save_bounds");
  m::MapServiceConfig cfg;
  cfg.files_directory = dir.string();
  ASSERT_EQ(cfg.max_files, 100);  // the default
  Harness h(cfg);
  map_room(h);
  for (int i = 0; i < 400; ++i) command(h, aerie::map_cmd_t::SAVE, "room.ot");
  const auto files = [&] {
    return std::distance(std::filesystem::directory_iterator(dir), std::filesystem::directory_iterator());
  };
  EXPECT_EQ(files(), 100);
  EXPECT_TRUE(std::filesystem::exists(dir / "room-99.ot"));
  EXPECT_FALSE(std::filesystem::exists(dir / "room-100.ot"));
  EXPECT_EQ(h.counter("save_refused.max_files"), 300);
  EXPECT_EQ(h.counter("command_errors"), 300);
  EXPECT_EQ(h.counter("files_saved"), 100);
  EXPECT_EQ(h.service.files_saved(), 100);
  EXPECT_NE(h.status.message().find("100 map files written in this run (files.max_files = 100)"), std::string::npos)
      << h.status.message();
  const int64_t one = static_cast<int64_t>(std::filesystem::file_size(dir / "room.ot"));
  EXPECT_EQ(h.counter("bytes_saved"), 100 * one);

  // Bytes: room for one map and a half; the second save is taken back and refused.
  const auto dir2 = aerie::test::scratch_dir("save_bytes");
  cfg.files_directory = dir2.string();
  cfg.max_bytes = one + one / 2;
  Harness b(cfg);
  map_room(b);
  command(b, aerie::map_cmd_t::SAVE, "room.ot");
  ASSERT_TRUE(std::filesystem::exists(dir2 / "room.ot"));
  command(b, aerie::map_cmd_t::SAVE, "room.ot");
  EXPECT_FALSE(std::filesystem::exists(dir2 / "room-1.ot"));
  EXPECT_EQ(b.counter("save_refused.max_bytes"), 1);
  EXPECT_NE(b.status.message().find("would pass files.max_bytes = " + std::to_string(one + one / 2)), std::string::npos)
      << b.status.message();
  EXPECT_EQ(b.service.bytes_saved(), one);
  // A bad name is refused by its own reason, before any quota; LOAD keeps working.
  for (const std::string& bad : std::vector<std::string>{"a..ot", "../room.ot", std::string(200, 'x') + ".ot", "room\n.ot"})
    command(b, aerie::map_cmd_t::SAVE, bad);
  EXPECT_EQ(b.counter("save_refused.bad_name"), 4);
  EXPECT_EQ(b.status.message().find('\n'), std::string::npos) << "control characters are not logged";
  command(b, aerie::map_cmd_t::LOAD, "a..ot");
  EXPECT_EQ(b.counter("load_refused.bad_name"), 1);
  const int64_t errors = b.counter("command_errors");
  command(b, aerie::map_cmd_t::LOAD, "room.ot");
  EXPECT_EQ(b.counter("command_errors"), errors);
  EXPECT_EQ(b.counter("commands_done"), 2);  // the first SAVE and the LOAD
  EXPECT_EQ(b.query(aerie::map_query_t::OCCUPANCY, kInside).occupancy, aerie::map_response_t::FREE);

  // Without files.directory: counted as off.
  Harness off;
  command(off, aerie::map_cmd_t::SAVE, "room.ot");
  command(off, aerie::map_cmd_t::LOAD, "room.ot");
  EXPECT_EQ(off.counter("save_refused.off"), 1);
  EXPECT_EQ(off.counter("load_refused.off"), 1);
}

TEST(MapService, SaveBoundsAreConfigKeysWithRanges) {
  const auto shipped = m::MapServiceConfig::from_config(
      aerie::util::Config::load((aerie::test::source_dir() / "config" / "map.yaml").string()));
  EXPECT_EQ(shipped.max_files, 100);
  EXPECT_EQ(shipped.max_bytes, int64_t{1} << 30);
  const auto cfg = m::MapServiceConfig::from_config(
      aerie::util::Config::parse("files:\n  max_files: 7\n  max_bytes: 2000000\n", "map.yaml"));
  EXPECT_EQ(cfg.max_files, 7);
  EXPECT_EQ(cfg.max_bytes, 2000000);
  const auto load = [](const std::string& text) {
    m::MapServiceConfig::from_config(aerie::util::Config::parse(text, "map.yaml"));
  };
  aerie::test::expect_refusals(load, std::vector<std::pair<std::string, std::string>>{
                                         {"files:\n  max_files: 0\n", "'files.max_files' = 0 is outside its valid range [1, 100000]"},
                                         {"files:\n  max_bytes: 10\n", "'files.max_bytes' = 10 is outside"},
                                     });
}
