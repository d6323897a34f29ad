// aerie-map's LCM side over memq://: queries, publication, commands, bad inputs.
#include <gtest/gtest.h>

// lcm-gen's decode() reads its hash through an out-parameter that GCC cannot follow.
#pragma GCC diagnostic push
#pragma GCC diagnostic ignored "-Wmaybe-uninitialized"
#include <aerie/map_response_t.hpp>
#include <aerie/octomap_t.hpp>
#pragma GCC diagnostic pop

#include <filesystem>
#include <limits>
#include <sstream>

#include "common/spherical/spherical_message.hpp"
#include "ground/map/map_service.hpp"
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
  m::MapService service;
  std::vector<aerie::map_response_t> responses;
  std::vector<aerie::octomap_t> maps;
  m::test::Room room;
  aerie::spherical::SphericalEncoder encoder{kCam, kSize};
  int64_t seq = 0;

  explicit Harness(m::MapServiceConfig cfg = {}) : service(bus, status, cfg) {
    bus.subscribe<aerie::map_response_t>("REPLY", [this](const auto& r, const ReceiveInfo&) { responses.push_back(r); });
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
    q.reply_channel = "REPLY";
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

  // A pose far in the future is rejected; mapping goes on.
  h.bus.publish("VO_POSE", h.pose_msg(1'700'000 + 3600'000'000LL, T));
  h.spin();
  EXPECT_EQ(h.counter("future_utime"), 1);
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

TEST(MapService, PublishesFullAndChangedRegionAndObeysCommands) {
  m::MapServiceConfig cfg;
  cfg.publish_period_s = 0.1;
  cfg.full_every = 3;
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
  const auto dir = aerie::test::scratch_dir("cmd");
  const std::string path = (dir / "saved.ot").string();
  aerie::map_cmd_t cmd{};
  cmd.command = aerie::map_cmd_t::SAVE;
  cmd.path = path;
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
  cmd.path = (dir / "nope.bt").string();
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
  try {
    m::MapServiceConfig::from_config(aerie::util::Config::parse("sensor_model:\n  hit: 1.5\n", "bad.yaml"));
    FAIL();
  } catch (const std::runtime_error& e) {
    EXPECT_NE(std::string(e.what()).find("bad.yaml"), std::string::npos);
    EXPECT_NE(std::string(e.what()).find("sensor_model/hit"), std::string::npos);
  }
}
