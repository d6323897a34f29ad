// Writes the seed corpora (fuzz/corpus/<target>/) and the regression inputs
// (fuzz/regressions/<target>/) of the fuzz targets (docs/fuzz.md):
//   fuzz_make_corpus FUZZ_DIR [--log FLIGHT.lcm] [--reliability DIR]
// Seeds: every message type encoded empty, realistic messages of the nodes' channels written
// with the project's own encoders, files written by its own writers (controllers, .pmd,
// calibrations, trajectories, boxes, octrees, logs) and the configs of config/. With --log,
// short windows of a recorded flight (every channel's first messages; per node, its channels
// for a second). With --reliability (the shared reliability reproducers, a folder given on the command line), the crafted inputs of the
// reliability issue: each payload as it is, and on its channel of every node target that
// subscribes to it. Files are written only when missing or different.
#include <aerie/control_cmd_t.hpp>
#include <aerie/flc_params_t.hpp>
#include <aerie/gt_box_t.hpp>
#include <aerie/gt_pose_t.hpp>
#include <aerie/imu_t.hpp>
#include <aerie/map_cmd_t.hpp>
#include <aerie/map_query_t.hpp>
#include <aerie/map_response_t.hpp>
#include <aerie/nav_state_t.hpp>
#include <aerie/pilot_cmd_t.hpp>
#include <aerie/pose_t.hpp>
#include <aerie/process_status_t.hpp>
#include <aerie/stereo_image_t.hpp>
#include <aerie/target_pose_t.hpp>
#include <aerie/track_cmd_t.hpp>
#include <aerie/track_t.hpp>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <iterator>
#include <map>
#include <opencv2/core.hpp>
#include <opencv2/imgproc.hpp>
#include <sstream>
#include <string>
#include <vector>

#include "air/track/eval/sequence.hpp"
#include "common/camera/calibration_io.hpp"
#include "common/flc/flc_io.hpp"
#include "common/image/image_message.hpp"
#include "common/logio/event_log.hpp"
#include "common/sim/flight/flight_sim.hpp"
#include "common/sim/flight/node/flightsim_node.hpp"
#include "common/sim/simulation.hpp"
#include "fuzz/fuzz_support.hpp"
#include "fuzz_catalogue.hpp"
#include "ground/map/octomap_message.hpp"
#include "procman/pmd_config.hpp"
#include "procman/sheriff.hpp"
#include "tools/eval/trajectory.hpp"

namespace {

namespace fs = std::filesystem;
using namespace aerie;
using Bytes = std::vector<uint8_t>;

fs::path g_fuzz_dir;
int g_written = 0;

void put(const std::string& kind, const std::string& target, const std::string& name, const Bytes& bytes) {
  const fs::path path = g_fuzz_dir / kind / target / name;
  fs::create_directories(path.parent_path());
  std::ifstream old(path, std::ios::binary);
  if (old && Bytes{std::istreambuf_iterator<char>(old), std::istreambuf_iterator<char>()} == bytes) return;
  std::ofstream(path, std::ios::binary).write(reinterpret_cast<const char*>(bytes.data()),
                                              static_cast<std::streamsize>(bytes.size()));
  ++g_written;
}
void seed(const std::string& target, const std::string& name, const Bytes& bytes) { put("corpus", target, name, bytes); }
void seed(const std::string& target, const std::string& name, const std::string& text) {
  seed(target, name, Bytes(text.begin(), text.end()));
}
void regression(const std::string& target, const std::string& name, const Bytes& bytes) {
  put("regressions", target, name, bytes);
}

Bytes read_file(const fs::path& p) {
  std::ifstream in(p, std::ios::binary);
  if (!in) throw std::runtime_error("cannot read " + p.string());
  return {std::istreambuf_iterator<char>(in), std::istreambuf_iterator<char>()};
}
// Runs a writer that takes a path and returns what it wrote.
template <typename Write>
Bytes written_by(Write&& write) {
  const fs::path p = fs::temp_directory_path() / "aerie-fuzz-make-corpus.tmp";
  write(p.string());
  Bytes b = read_file(p);
  fs::remove(p);
  return b;
}

template <typename Msg>
Bytes encode(const Msg& m) {
  Bytes b(static_cast<size_t>(m.getEncodedSize()));
  m.encode(b.data(), 0, static_cast<int>(b.size()));
  return b;
}

// --- messages of the nodes' channels --------------------------------------------------------

struct Message {
  std::string channel;
  Bytes payload;
};

constexpr int64_t kT0 = 1'000'000'000;  // µs

void wxyz_about(double axis_x, double axis_y, double axis_z, double angle_rad, double q[4]) {
  q[0] = std::cos(angle_rad / 2);
  q[1] = axis_x * std::sin(angle_rad / 2);
  q[2] = axis_y * std::sin(angle_rad / 2);
  q[3] = axis_z * std::sin(angle_rad / 2);
}

std::vector<Message> pose_messages() {
  std::vector<Message> out;
  for (int k = 0; k < 10; ++k) {
    const int64_t t = kT0 + k * 33'333;
    aerie::pose_t p{};  // VO: heading about -y (y down)
    p.utime = t;
    p.seq = k;
    p.status = k == 0 ? aerie::pose_t::INITIALISING : aerie::pose_t::OK;
    p.position[2] = 0.05 * k;
    wxyz_about(0, -1, 0, -0.1 * k, p.orientation);
    p.features_3d = 120;
    p.inliers = 90;
    p.keyframe = k % 5 == 0;
    out.push_back({"VO_POSE", encode(p)});

    aerie::nav_state_t n{};
    n.utime = t;
    n.seq = k;
    n.status = aerie::nav_state_t::OK;
    n.reason = "ok";
    n.position[0] = 0.05 * k;
    wxyz_about(0, 0, 1, 0.1 * k, n.orientation);
    n.time_since_vo_s = 0.03;
    out.push_back({"NAV_STATE", encode(n)});

    aerie::gt_pose_t g{};
    g.utime = t;
    g.seq = k;
    g.frame_id = "world";
    g.position[1] = 0.05 * k;
    g.position[2] = 1.5;
    wxyz_about(0, 0, 1, -0.1 * k, g.orientation);
    out.push_back({"GT_POSE", encode(g)});
  }
  return out;
}

std::vector<Message> controller_messages() {
  aerie::flc_params_t gains{};
  gains.utime = kT0;
  gains.controller_id = "gains";
  gains.names = {"Kp", "Kd", "Ki", "e.NB"};
  gains.values = {2.0, 0.01, -0.01, -0.8};
  gains.nparams = 4;
  aerie::flc_params_t fll{};
  fll.utime = kT0 + 1;
  fll.seq = 1;
  fll.controller_id = "initial";
  fll.fll = flc::to_fll(flc::thesis_initial());
  return {{"FLC_PARAMS", encode(gains)}, {"FLC_PARAMS", encode(fll)}};
}

std::vector<Message> imu_messages(int n) {
  std::vector<Message> out;
  for (int k = 0; k < n; ++k) {
    aerie::imu_t m{};
    m.utime = kT0 + k * 5'000;
    m.seq = k;
    m.angular_velocity[2] = k > n / 2 ? 0.05 : 0.0;
    m.linear_acceleration[2] = 9.81;
    m.orientation[0] = 1;
    out.push_back({"IMU", encode(m)});
  }
  return out;
}

std::vector<Message> pilot_messages() {
  std::vector<Message> out;
  for (int8_t c : {aerie::pilot_cmd_t::START, aerie::pilot_cmd_t::LAND, aerie::pilot_cmd_t::ABORT,
                   aerie::pilot_cmd_t::RESUME}) {
    aerie::pilot_cmd_t m{};
    m.utime = kT0;
    m.command = c;
    m.source = "operator";
    out.push_back({"PILOT_CMD", encode(m)});
  }
  for (int k = 0; k < 5; ++k) {
    aerie::track_t t{};
    t.utime = kT0 + k * 50'000;
    t.seq = k;
    t.tracker = "dcf";
    t.camera = "CAM_DOWN";
    t.status = aerie::track_t::TRACKING;
    t.x = 160 + k;
    t.y = 120;
    t.scale = 1;
    t.width = 40;
    t.height = 40;
    t.confidence = 0.9f;
    aerie::track_level_t level{};
    level.evaluated = 3;
    level.npoints = 3;
    level.u = {150, 160, 170};
    level.v = {110, 120, 130};
    level.score = {0.1f, 0.9f, 0.2f};
    t.levels = {level};
    t.nlevels = 1;
    out.push_back({"TRACK", encode(t)});

    aerie::target_pose_t p{};
    p.utime = t.utime;
    p.seq = k;
    p.target = "helipad";
    p.position[0] = 0.4 - 0.05 * k;
    p.position[1] = 0.1;
    p.position[2] = 2.0 - 0.1 * k;
    p.yaw = 0.1;
    p.confidence = 0.8f;
    p.source = aerie::target_pose_t::SOURCE_FIT;
    out.push_back({"TARGET_POSE", encode(p)});
  }
  return out;
}

aerie::spherical_depth_t small_depth(int64_t utime) {
  aerie::spherical_depth_t d{};
  d.utime = utime;
  d.has_pose = true;
  d.orientation[0] = 1;
  d.polar_min_rad = static_cast<float>(M_PI / 4);
  d.polar_step_rad = static_cast<float>(M_PI / 32);
  d.n_polar = 16;
  d.azimuth_min_rad = static_cast<float>(-M_PI / 4);
  d.azimuth_step_rad = static_cast<float>(M_PI / 32);
  d.n_azimuth = 16;
  d.range_scale_m = 0.01f;
  d.max_range_m = 5;
  d.focal_px = 163;
  d.baseline_m = 0.12f;
  for (int b = 100; b < 140; b += 4) {
    d.bin.push_back(b);
    d.range.push_back(static_cast<int16_t>(150 + b));
  }
  d.nbins = d.nrange = static_cast<int32_t>(d.bin.size());
  return d;
}

octomap::OcTree small_tree() {
  octomap::OcTree tree(0.1);
  for (int i = 0; i < 20; ++i) tree.updateNode(octomap::point3d(0.1f * i, 0.5f, 0.2f), i % 3 != 0);
  return tree;
}

std::vector<Message> map_messages() {
  std::vector<Message> out;
  for (int k = 0; k < 3; ++k) {
    aerie::pose_t p{};
    p.utime = kT0 + k * 100'000;
    p.seq = k;
    p.orientation[0] = 1;
    out.push_back({"VO_POSE", encode(p)});
    out.push_back({"VO_DEPTH", encode(small_depth(p.utime))});
  }
  for (int8_t kind : {aerie::map_query_t::OCCUPANCY, aerie::map_query_t::NEAREST_OBSTACLE, aerie::map_query_t::RAY}) {
    aerie::map_query_t q{};
    q.utime = kT0 + 300'000;
    q.kind = kind;
    q.point[0] = 0.5;
    q.direction[0] = 1;
    q.max_range = 3;
    q.reply_channel = kind == aerie::map_query_t::RAY ? "MAP_RESPONSE_PILOT" : "MAP_RESPONSE";
    out.push_back({"MAP_QUERY", encode(q)});
  }
  for (int8_t command : {aerie::map_cmd_t::SAVE, aerie::map_cmd_t::LOAD, aerie::map_cmd_t::PUBLISH_FULL,
                         aerie::map_cmd_t::CLEAR}) {
    aerie::map_cmd_t c{};
    c.utime = kT0 + 400'000;
    c.command = command;
    c.path = command == aerie::map_cmd_t::LOAD ? "room.ot" : "room.bt";
    out.push_back({"MAP_CMD", encode(c)});
  }
  aerie::octomap_t m{};
  m.utime = kT0;
  map::encode_octree(small_tree(), true, m);
  out.push_back({"MAP_OCTOMAP", encode(m)});
  return out;
}

std::vector<Message> image_messages() {
  cv::Mat gray(12, 16, CV_8UC1), color(12, 16, CV_8UC3);
  cv::randu(gray, 0, 255);
  cv::randu(color, 0, 255);
  std::vector<Message> out;
  for (const auto enc : {image::Encoding::Raw, image::Encoding::Png, image::Encoding::Jpeg}) {
    aerie::image_t m = image::to_message(enc == image::Encoding::Jpeg ? color : gray, kT0, 1, enc);
    image::set_metadata(m, "seq", "1");
    out.push_back({"CAM_LEFT", encode(m)});
  }
  aerie::stereo_image_t s{};
  s.utime = kT0;
  s.left = image::to_message(gray, kT0, 1);
  s.right = image::to_message(gray, kT0, 1);
  s.fx = s.fy = 163;
  s.cx = 8;
  s.cy = 6;
  s.baseline_m = 0.12;
  out.push_back({"CAM_STEREO", encode(s)});
  return out;
}

procman::PmdConfig demo_pmd() { return procman::load_pmd(fuzz::source_path("config/demo.pmd")); }

std::vector<Message> procman_messages() {
  procman::Sheriff sheriff("sheriff", false, 3.0, 1);
  const procman::PmdConfig config = demo_pmd();
  sheriff.load(config);
  for (const std::string& host : config.hosts()) {  // orders go only to deputies heard from
    bot_procman::info2_t hello{};
    hello.utime = kT0;
    hello.host = host;
    sheriff.on_info(hello, 0);
  }
  sheriff.start(sheriff.select(procman::TargetKind::Everything, ""));
  std::vector<Message> out;
  for (const bot_procman::orders2_t& o : sheriff.orders(kT0)) {
    out.push_back({"PMD_ORDERS2", encode(o)});
    bot_procman::info2_t info{};
    info.utime = kT0 + 100'000;
    info.host = o.host;
    info.cpu_load = 0.3f;
    for (const auto& sc : o.cmds) {
      bot_procman::deputy_cmd2_t c{};
      c.cmd = sc.cmd;
      c.sheriff_id = sc.sheriff_id;
      c.actual_runid = sc.desired_runid;
      c.pid = 4000 + sc.sheriff_id % 1000;
      info.cmds.push_back(c);
    }
    info.ncmds = static_cast<int32_t>(info.cmds.size());
    out.push_back({"PMD_INFO2", encode(info)});
  }
  return out;
}

std::vector<Message> all_messages() {
  std::vector<Message> all;
  for (auto part : {pose_messages(), controller_messages(), imu_messages(20), pilot_messages(), map_messages(),
                    image_messages(), procman_messages()})
    all.insert(all.end(), part.begin(), part.end());
  return all;
}

// --- node targets ---------------------------------------------------------------------------

struct NodeTarget {
  const char* name;
  const std::vector<std::string>* channels;
};
const NodeTarget kNodes[] = {{"node_control", &fuzz::kControlChannels}, {"node_nav", &fuzz::kNavChannels},
                             {"node_pilot", &fuzz::kPilotChannels},     {"node_map", &fuzz::kMapChannels},
                             {"procman_messages", &fuzz::kProcmanChannels},
                             {"node_track", &fuzz::kTrackChannels},     {"node_vo", &fuzz::kVoChannels},
                             {"node_flightsim", &fuzz::kFlightSimChannels}, {"node_link", &fuzz::kLinkChannels}};

const NodeTarget& node_named(const std::string& name) {
  for (const NodeTarget& n : kNodes)
    if (name == n.name) return n;
  throw std::logic_error("no node target " + name);
}

int channel_index(const NodeTarget& node, const std::string& channel) {
  const auto& ch = *node.channels;
  const auto it = std::find(ch.begin(), ch.end(), channel);
  return it == ch.end() ? -1 : static_cast<int>(it - ch.begin());
}

// The messages on the node's channels as one input (records of fuzz_support.hpp).
Bytes records(const NodeTarget& node, const std::vector<Message>& messages) {
  Bytes out;
  for (const Message& m : messages)
    if (const int i = channel_index(node, m.channel); i >= 0) fuzz::append_record(out, static_cast<uint8_t>(i), m.payload);
  return out;
}

// --- the track, VO, flight simulator and link targets' own sequences -----------------------
// Kept out of all_messages(): lcm_messages and the other node targets keep their seeds. Images
// are small (the targets' costs grow with them): 64 x 48 for the down camera, 96 x 72 for the
// stereo pairs (aerie-vo's feature margins and buckets, config/vo.yaml, need at least 80 x 64).

constexpr int kSeedWidth = 64, kSeedHeight = 48;
constexpr int kStereoWidth = 96, kStereoHeight = 72;

// The down camera of aerie-flightsim (its rig at 64 x 48) looking at the room's helipad from
// 1.1 m, drifting and descending (the pad about 30 px wide, large enough for aerie-track to fit
// its corners): frames as aerie-flightsim publishes them (intrinsics in the metadata) and their
// GT_TRACK boxes.
struct DownFrames {
  std::vector<Message> images, boxes;
  std::vector<cv::Rect2d> box;
};

DownFrames down_frames(int n) {
  const sim::World world = sim::World::room(sim::WorldConfig{});
  sim::RigConfig rig = sim::FlightSimConfig::down_rig();
  rig.width = kSeedWidth;
  rig.height = kSeedHeight;
  const sim::StereoRenderer renderer(world, rig);
  const sim::Intrinsics K = renderer.intrinsics();
  const Eigen::Matrix3d R_wc = (Eigen::Matrix3d() << 1, 0, 0, 0, -1, 0, 0, 0, -1).finished();  // optical axis down
  DownFrames out;
  for (int k = 0; k < n; ++k) {
    const Eigen::Vector3d eye = world.helipad().center + Eigen::Vector3d(0.03 * k, 0.02 * k, 1.1 - 0.02 * k);
    const sim::StereoFrame f = renderer.render_mono(geometry::SE3(Eigen::Quaterniond(R_wc), eye), kT0 + k * 50'000, k);
    out.images.push_back({"CAM_DOWN", encode(sim::image_message(f.left, f.utime, f.seq, "down", K))});
    out.boxes.push_back({"GT_TRACK", encode(sim::gt_box_message(f, f.utime, f.seq, "CAM_DOWN"))});
    out.box.push_back(f.target_box);
  }
  return out;
}

Message track_command(int8_t command, const std::string& tracker = "", const cv::Rect2d& box = {},
                      const std::vector<std::pair<std::string, std::string>>& params = {}) {
  aerie::track_cmd_t c{};
  c.utime = kT0;
  c.command = command;
  c.tracker = tracker;
  c.x = box.x;
  c.y = box.y;
  c.width = box.width;
  c.height = box.height;
  for (const auto& [name, value] : params) {
    c.param_names.push_back(name);
    c.param_values.push_back(value);
  }
  c.nparams = static_cast<int32_t>(params.size());
  return {"TRACK_CMD", encode(c)};
}

// Rectified pairs of the room seen by the VO rig (the simulator's 376 x 240 rig at 96 x 72)
// flying its survey loop.
std::vector<Message> stereo_pairs(int n, image::Encoding encoding = image::Encoding::Raw) {
  const sim::World world = sim::World::room(sim::WorldConfig{});
  sim::RigConfig rig;
  rig.width = kStereoWidth;
  rig.height = kStereoHeight;
  sim::StereoSimulation simulation(world, rig, sim::Trajectory::survey_loops(world, 1, 1.0), 20.0, kT0);
  const sim::Intrinsics K = simulation.intrinsics();
  std::vector<Message> out;
  sim::StereoFrame f;
  for (int k = 0; k < n && simulation.next(f); ++k) {
    aerie::stereo_image_t s{};
    s.utime = f.utime;
    s.seq = f.seq;
    s.left = image::to_message(f.left, f.utime, f.seq, encoding);
    s.right = image::to_message(f.right, f.utime, f.seq, encoding);
    s.fx = K.fx;
    s.fy = K.fy;
    s.cx = K.cx;
    s.cy = K.cy;
    s.baseline_m = K.baseline;
    out.push_back({"CAM_STEREO", encode(s)});
  }
  return out;
}

// CTRL_CMD answering aerie-flightsim's frame k (utime k x 50 ms from 0, its start time).
Message control_command(int k, int8_t mode, float vx = 0, float vy = 0, float vz = 0, float yaw_rate = 0) {
  aerie::control_cmd_t c{};
  c.utime = int64_t{k} * 50'000;
  c.seq = k;
  c.mode = mode;
  c.controller_id = "initial";
  c.velocity_body[0] = vx;
  c.velocity_body[1] = vy;
  c.velocity_body[2] = vz;
  c.yaw_rate_deg_s = yaw_rate;
  return {"CTRL_CMD", encode(c)};
}

void track_seeds() {
  const NodeTarget& node = node_named("node_track");
  const DownFrames d = down_frames(6);
  using C = aerie::track_cmd_t;
  // The demo: initialised on the simulator's box of the same frame (init_from_gt 0), then STOP.
  std::vector<Message> gt;
  for (size_t k = 0; k + 1 < d.images.size(); ++k) {
    gt.push_back(d.boxes[k]);
    gt.push_back(d.images[k]);
  }
  gt.push_back(track_command(C::STOP));
  gt.push_back(d.images.back());
  seed(node.name, "gt_init_track_stop.bin", records(node, gt));
  // An operator: INIT on the pad's box (with an override), RESET, SET_TRACKER, STOP.
  const std::vector<Message> op = {d.images[0],
                                   track_command(C::INIT, "", d.box[0], {{"search_radius", "8"}}),
                                   d.images[1],
                                   d.images[2],
                                   track_command(C::RESET),
                                   d.images[3],
                                   track_command(C::SET_TRACKER, "ct", {}, {{"features", "50"}}),
                                   d.images[4],
                                   track_command(C::STOP),
                                   d.images[5]};
  seed(node.name, "operator_init_reset_set_stop.bin", records(node, op));
  seed(node.name, "CAM_DOWN_64x48.bin", records(node, {d.images[0]}));
  seed(node.name, "GT_TRACK_pad.bin", records(node, {d.boxes[0]}));
  seed(node.name, "TRACK_CMD_init.bin", records(node, {track_command(C::INIT, "dcf", d.box[0])}));
  seed(node.name, "TRACK_CMD_stop.bin", records(node, {track_command(C::STOP)}));
}

void vo_seeds() {
  const NodeTarget& node = node_named("node_vo");
  seed(node.name, "pairs_96x72.bin", records(node, stereo_pairs(3)));
  const std::vector<Message> jpeg = stereo_pairs(4, image::Encoding::Jpeg);
  seed(node.name, "pairs_96x72_jpeg.bin", records(node, jpeg));
  seed(node.name, "pair_96x72_png.bin", records(node, stereo_pairs(1, image::Encoding::Png)));
  // A duplicate, then an older pair.
  seed(node.name, "pairs_duplicate_older.bin", records(node, {jpeg[0], jpeg[1], jpeg[1], jpeg[0]}));
}

void flightsim_seeds() {
  const NodeTarget& node = node_named("node_flightsim");
  using C = aerie::control_cmd_t;
  // Take off, fly forward turning, hover, land (touchdown about frame 85, then disarmed): one
  // answer per frame (100 frames, 5 s, the target's kMaxFrames).
  std::vector<Message> flight;
  int k = 0;
  for (; k < 25; ++k) flight.push_back(control_command(k, C::TAKEOFF));
  for (; k < 35; ++k) flight.push_back(control_command(k, C::ACTIVE, 0.5f, 0.1f, 0, 15));
  for (; k < 40; ++k) flight.push_back(control_command(k, C::HOVER));
  for (; k < 45; ++k) flight.push_back(control_command(k, C::FALLBACK_HOVER));
  for (; k < 100; ++k) flight.push_back(control_command(k, C::LAND));
  seed(node.name, "takeoff_fly_hover_land.bin", records(node, flight));
  for (int8_t mode : {C::HOVER, C::ACTIVE, C::FALLBACK_HOVER, C::TAKEOFF, C::LAND})
    seed(node.name, "CTRL_CMD_mode_" + std::to_string(mode) + ".bin",
         records(node, {control_command(0, mode, 0.2f, 0, 0.1f, 5)}));
  // Refused: beyond the vehicle's limits, not finite; then an answer from the past (no answer).
  seed(node.name, "CTRL_CMD_refused.bin",
       records(node, {control_command(0, C::TAKEOFF), control_command(1, C::ACTIVE, 40, 0, 0, 0),
                      control_command(2, C::ACTIVE, NAN, 0, 0, 0), control_command(0, C::HOVER)}));
}

void link_seeds() {
  const NodeTarget& node = node_named("node_link");
  const DownFrames d = down_frames(3);
  aerie::process_status_t st{};
  st.utime = kT0;
  st.node = "VO";
  st.host = "air";
  st.pid = 4242;
  st.message = "OK";
  st.counter_names = {"frames", "keyframes"};
  st.counter_values = {120, 12};
  st.ncounters = 2;
  st.timing_names = {"total"};
  st.timing_ms = {9.5};
  st.ntimings = 1;
  aerie::map_response_t r{};
  r.utime = kT0;
  r.kind = aerie::map_query_t::RAY;
  r.occupancy = aerie::map_response_t::OCCUPIED;
  r.voxel_size = 0.1;
  r.distance = 1.5;
  r.hit[0] = 1.5;
  using C = aerie::track_cmd_t;
  const std::vector<Message> pairs = stereo_pairs(1, image::Encoding::Jpeg);
  const std::vector<Message> mixed = {d.images[0],  d.boxes[0], pairs[0], {"STATUS_VO", encode(st)},
                                      control_command(1, aerie::control_cmd_t::ACTIVE, 0.3f),
                                      track_command(C::INIT, "", d.box[0]), d.images[1], d.boxes[1],
                                      {"MAP_RESPONSE", encode(r)}, d.images[2], track_command(C::STOP)};
  seed(node.name, "downlink_uplink.bin", records(node, mixed));
  seed(node.name, "CAM_DOWN_64x48.bin", records(node, {d.images[0]}));
  seed(node.name, "CAM_STEREO_96x72_jpeg.bin", records(node, pairs));
  seed(node.name, "STATUS_VO.bin", records(node, {{"STATUS_VO", encode(st)}}));
  seed(node.name, "MAP_RESPONSE.bin", records(node, {{"MAP_RESPONSE", encode(r)}}));
  seed(node.name, "TRACK_CMD_init.bin", records(node, {track_command(C::INIT, "", d.box[0])}));
  seed(node.name, "CTRL_CMD.bin", records(node, {control_command(1, aerie::control_cmd_t::ACTIVE, 0.3f)}));
  // Frames in a row, each re-encoded and queued for the transmitter.
  std::vector<Message> burst;
  for (int i = 0; i < 4; ++i) burst.push_back(d.images[static_cast<size_t>(i % 3)]);
  seed(node.name, "CAM_DOWN_burst.bin", records(node, burst));
}

void message_seeds() {
  []<typename... Msg>(fuzz::TypeList<Msg...>) {
    (seed("lcm_messages", std::string(Msg::getTypeName()) + "_empty.bin", encode(Msg{})), ...);
  }(fuzz::Catalogue{});
  std::map<std::string, int> count;
  const std::vector<Message> all = all_messages();
  for (const Message& m : all) seed("lcm_messages", m.channel + "_" + std::to_string(count[m.channel]++) + ".bin", m.payload);

  for (const NodeTarget& node : kNodes) {
    const Bytes everything = records(node, all);
    if (!everything.empty()) seed(node.name, "sequence.bin", everything);
    count.clear();
    for (const Message& m : all)
      if (channel_index(node, m.channel) >= 0)
        seed(node.name, m.channel + "_" + std::to_string(count[m.channel]++) + ".bin", records(node, {m}));
  }
  // aerie-control's nav and gt nodes take controllers on channels of their own.
  seed("node_control", "FLC_PARAMS_NAV.bin", records(kNodes[0], {{"FLC_PARAMS_NAV", controller_messages()[0].payload}}));
  seed("node_control", "FLC_PARAMS_GT.bin", records(kNodes[0], {{"FLC_PARAMS_GT", controller_messages()[1].payload}}));
  // aerie-nav's static alignment needs a second of IMU before VO is applied.
  std::vector<Message> align = imu_messages(220);
  for (const Message& p : pose_messages())
    if (p.channel == "VO_POSE") align.push_back(p);
  seed("node_nav", "alignment_then_vo.bin", records(kNodes[1], align));
}

// --- files ----------------------------------------------------------------------------------

void copy_configs() {
  for (const std::string dir : {"config", "config/sim"})
    for (const auto& e : fs::directory_iterator(fuzz::source_path(dir))) {
      const std::string ext = e.path().extension().string();
      if (ext == ".yaml") seed("config", (dir == "config" ? "" : "sim_") + e.path().filename().string(), read_file(e.path()));
      if (ext == ".pmd") seed("pmd", e.path().filename().string(), read_file(e.path()));
    }
  for (const auto& e : fs::directory_iterator(fuzz::source_path("config/flc"))) {
    seed("flc", e.path().filename().string(), read_file(e.path()));
    seed("flc", e.path().stem().string() + ".fll", flc::to_fll(flc::load_yaml(e.path().string())));
  }
}

void pmd_seeds() {
  seed("pmd", "every_construct.pmd", R"(# every construct of the format
cmd "top" { exec = "aerie-sim --help"; host = "ground"; }
group "air" {
  cmd "vo" { exec = "aerie-vo -c ${AERIE_CONFIG:-config}/vo.yaml"; host = "air"; auto_respawn = "true";
             stop_signal = 15; stop_time_allowed = 2.5; }
  group "vision" { cmd "track" { exec = "aerie-track --camera 'CAM DOWN' \"quoted\" $HOME"; host = "air"; } }
}
script "start_all" {
  start group "air" wait "running";
  wait ms 500;
  start cmd "top";
  wait cmd "top" status "running";
  restart cmd "vo" wait "running";
  run_script "stop_all";
}
script "stop_all" { stop everything wait "stopped"; }
)");
  seed("pmd", "written_demo.pmd", procman::to_pmd(demo_pmd()));
}

void calibration_seeds() {
  seed("calibration", "kitti_labelled_calib.txt",
       "P0: 700 0 600 0 0 700 180 0 0 0 1 0\nP1: 700 0 600 -350 0 700 180 0 0 0 1 0\n"
       "P2: 700 0 600 45 0 700 180 0 0 0 1 0\nP3: 700 0 600 -340 0 700 180 0 0 0 1 0\n");
  seed("calibration", "kitti_unlabelled_calib.txt",
       "700 0 600 0 0 700 180 0 0 0 1 0\n700 0 600 -350 0 700 180 0 0 0 1 0\n");
  seed("calibration", "euroc_sensor.yaml", R"(# General sensor definitions.
sensor_type: camera
comment: VI-Sensor cam0 (MT9M034)

# Sensor extrinsics wrt. the body-frame.
T_BS:
  cols: 4
  rows: 4
  data: [0.0148655429818, -0.999880929698, 0.00414029679422, -0.0216401454975,
         0.999557249008, 0.0149672133247, 0.025715529948, -0.064676986768,
        -0.0257744366974, 0.00375618835797, 0.999660727178, 0.00981073058949,
         0.0, 0.0, 0.0, 1.0]

# Camera specific definitions.
rate_hz: 20
resolution: [752, 480]
camera_model: pinhole
intrinsics: [458.654, 457.296, 367.215, 248.375] #fu, fv, cu, cv
distortion_model: radial-tangential
distortion_coefficients: [-0.28340811, 0.07395907, 0.00019359, 1.76187114e-05]
)");
  camera::StereoCalibration c;
  c.left = {752, 480, 458.654, 457.296, 367.215, 248.375, camera::Distortion::RadTan,
            {-0.28340811, 0.07395907, 0.00019359, 1.76187114e-05}};
  c.right = c.left;
  c.right.distortion = camera::Distortion::Equidistant;
  c.T_right_left = geometry::SE3(Eigen::Quaterniond::Identity(), Eigen::Vector3d(-0.11, 0.001, 0.0005));
  seed("calibration", "aerie_stereo.yaml", written_by([&](const std::string& p) { camera::write_opencv_stereo(c, p); }));
}

void dataset_seeds() {
  eval::Trajectory traj;
  for (int k = 0; k < 5; ++k)
    traj.push_back(1403715273.262143 + 0.05 * k,
                   geometry::SE3(Eigen::Quaterniond(Eigen::AngleAxisd(0.1 * k, Eigen::Vector3d::UnitZ())),
                                 Eigen::Vector3d(0.1 * k, 0.02 * k, 1.0)));
  seed("datasets", "trajectory.tum", written_by([&](const std::string& p) { eval::write_tum(traj, p); }));
  seed("datasets", "poses.kitti", written_by([&](const std::string& p) { eval::write_kitti_poses(traj, p); }));
  seed("datasets", "times.txt", "# seconds\n0.000000e+00\n1.036240e-01\n\n2.072480e-01\n1403715273.262143\n");
  seed("datasets", "euroc_groundtruth.csv",
       "#timestamp, p_RS_R_x [m], p_RS_R_y [m], p_RS_R_z [m], q_RS_w [], q_RS_x [], q_RS_y [], q_RS_z [], "
       "v_RS_R_x [m s^-1], v_RS_R_y [m s^-1], v_RS_R_z [m s^-1], b_w_RS_S_x [rad s^-1], b_w_RS_S_y [rad s^-1], "
       "b_w_RS_S_z [rad s^-1], b_a_RS_S_x [m s^-2], b_a_RS_S_y [m s^-2], b_a_RS_S_z [m s^-2]\n"
       "1403715274302142976,0.878612,2.142470,0.947262,0.060514,-0.828459,-0.058956,-0.553641,0.009474,"
       "-0.014009,-0.002145,-0.002229,0.020700,0.076350,-0.012492,0.547666,0.069894\n"
       "1403715274307143168,0.878658,2.142403,0.947253,0.060578,-0.828433,-0.058976,-0.553666,0.008926,"
       "-0.013368,-0.001767,-0.002229,0.020700,0.076350,-0.012492,0.547666,0.069894\n");
  seed("datasets", "groundtruth.txt", written_by([&](const std::string& p) {
         track::eval::write_boxes(p, {{10, 20, 30, 40}, {11.5, 21, 30, 41}, {NAN, NAN, NAN, NAN}, {0, 0, 0, 0}});
       }));
  seed("datasets", "groundtruth_tabs.txt", "10\t20\t30\t40\n12 22 30 40\n");
}

void octomap_seeds(const std::vector<Message>& messages) {
  const octomap::OcTree tree = small_tree();
  std::ostringstream bt, ot;
  tree.writeBinaryConst(bt);
  tree.write(ot);
  seed("octomap", "small.bt", bt.str());
  seed("octomap", "small.ot", ot.str());
  for (const Message& m : messages)
    if (m.channel == "MAP_OCTOMAP") seed("octomap", "MAP_OCTOMAP_small.bin", m.payload);
}

void event_log_seeds(const std::vector<Message>& messages) {
  seed("event_log", "messages.lcm", written_by([&](const std::string& p) {
         logio::Writer w(p);
         int64_t t = kT0;
         for (const Message& m : messages)
           if (m.payload.size() < 4096) w.write(t += 1000, m.channel, m.payload.data(), m.payload.size());
         w.write(t + 1, "LCM_SELF_TEST", "lcm self test", 13);
       }));
  seed("event_log", "empty.lcm", Bytes{});
}

// --- a recorded flight ----------------------------------------------------------------------

// Per channel, the first messages of at most 16 KB (lcm_messages, octomap); per node target,
// its channels' messages over one second from `from_s` into the flight (small messages only).
void log_seeds(const std::string& path) {
  std::map<std::string, int> per_channel;
  std::map<std::string, std::vector<Message>> window;  // node -> messages
  const fs::path excerpt = fs::temp_directory_path() / "aerie-fuzz-flight-excerpt.lcm";
  logio::Writer small_events(excerpt.string());  // event_log: the first 200 events under 4 KB
  logio::Reader reader(path);
  logio::Event ev;
  int64_t start = -1;
  while (reader.next(ev)) {
    if (start < 0) start = ev.utime;
    const double t = static_cast<double>(ev.utime - start) * 1e-6;
    if (ev.data.size() < 4096 && small_events.events_written() < 200) small_events.write(ev, true);
    if (ev.data.size() <= 16384 && per_channel[ev.channel]++ < 2) {
      seed("lcm_messages", "flight_" + ev.channel + "_" + std::to_string(per_channel[ev.channel]) + ".bin", ev.data);
      if (ev.channel == "MAP_OCTOMAP") seed("octomap", "flight_MAP_OCTOMAP.bin", ev.data);
    }
    for (const NodeTarget& node : kNodes) {
      const bool map_depth = std::string(node.name) == "node_map" && ev.channel == "VO_DEPTH";
      if (channel_index(node, ev.channel) < 0 || t < 8.0 || t > 9.0 || (ev.data.size() > 4096 && !map_depth)) continue;
      auto& w = window[node.name];
      if (map_depth && std::count_if(w.begin(), w.end(), [](const Message& m) { return m.channel == "VO_DEPTH"; }) >= 2)
        continue;
      w.push_back({ev.channel, ev.data});
    }
    if (t > 9.0 && ev.channel == "PMD_INFO2") break;
  }
  for (const NodeTarget& node : kNodes)
    if (!window[node.name].empty()) seed(node.name, "flight_8s.bin", records(node, window[node.name]));
  small_events.close();
  seed("event_log", "flight_excerpt.lcm", read_file(excerpt));
  fs::remove(excerpt);
}

// --- the reliability issue's reproducers ----------------------------------------------------

// Which channel of a node target each reproducer goes to, by the start of its file name
// (the reliability README beside those reproducers).
struct Route {
  const char* prefix;
  const char* target;
  const char* channel;
};
const Route kRoutes[] = {
    {"flc_params_", "node_control", "FLC_PARAMS"}, {"gt_pose_", "node_control", "GT_POSE"},
    {"vo_pose_", "node_control", "VO_POSE"},       {"vo_pose_", "node_nav", "VO_POSE"},
    {"vo_pose_", "node_map", "VO_POSE"},           {"vo_depth_", "node_map", "VO_DEPTH"},
    {"map_query_", "node_map", "MAP_QUERY"},       {"map_cmd_", "node_map", "MAP_CMD"},
    {"track_npoints", "node_pilot", "TRACK"},      {"orders2_", "procman_messages", "PMD_ORDERS2"},
    {"info2_", "procman_messages", "PMD_INFO2"},   {"gt_track_", "node_track", "GT_TRACK"},
    {"track_cmd_", "node_track", "TRACK_CMD"},     {"image_", "node_track", "CAM_DOWN"},
    {"stereo_left_", "node_vo", "CAM_STEREO"},     {"image_", "node_link", "CAM_DOWN"},
    {"stereo_left_", "node_link", "CAM_STEREO"},   {"track_cmd_", "node_link", "TRACK_CMD"},
};

void reliability_regressions(const fs::path& dir) {
  for (const auto& e : fs::directory_iterator(dir)) {
    const std::string name = e.path().filename().string(), ext = e.path().extension().string();
    const Bytes bytes = read_file(e.path());
    if (ext == ".bin") {
      regression("lcm_messages", name, bytes);
      for (const Route& r : kRoutes)
        if (name.starts_with(r.prefix))
          for (const NodeTarget& node : kNodes)
            if (std::string(node.name) == r.target) regression(r.target, name, records(node, {{r.channel, bytes}}));
    } else if (ext == ".fll") {
      regression("flc", name, bytes);
    } else if (ext == ".bt") {
      regression("octomap", name, bytes);
    } else if (ext == ".pmd" && bytes.size() < 512 * 1024) {
      regression("pmd", name, bytes);
    } else if (ext == ".lcm") {  // the events up to the hostile one, without the large images
      regression("event_log", name, written_by([&](const std::string& p) {
                   logio::Writer w(p);
                   logio::Reader r(e.path().string());
                   logio::Event ev;
                   while (r.next(ev))
                     if (ev.data.size() < 4096 || ev.channel == "TRACK_CMD") w.write(ev);
                 }));
    }
  }
  // The 2 MB chain of 50,000 run_script calls is too large to keep: the same refusal, 1,000 deep.
  std::string chain;
  for (int i = 0; i < 1000; ++i) chain += "script \"s" + std::to_string(i) + "\" { run_script \"s" + std::to_string(i + 1) + "\"; }\n";
  chain += "script \"s1000\" { wait ms 1; }\n";
  regression("pmd", "sheriff_run_script_chain_1000.pmd", Bytes(chain.begin(), chain.end()));
}

}  // namespace

int main(int argc, char** argv) {
  if (argc < 2 || std::string(argv[1]) == "--help") {
    std::printf("usage: %s FUZZ_DIR [--log FLIGHT.lcm] [--reliability REPRO_DIR]\n"
                "Writes the seed corpora FUZZ_DIR/corpus/<target>/ and regression inputs FUZZ_DIR/regressions/<target>/.\n",
                argv[0]);
    return argc < 2 ? 2 : 0;
  }
  g_fuzz_dir = argv[1];
  std::string log, reliability;
  for (int i = 2; i + 1 < argc; i += 2) {
    const std::string opt = argv[i];
    if (opt == "--log") log = argv[i + 1];
    else if (opt == "--reliability") reliability = argv[i + 1];
    else {
      std::fprintf(stderr, "unknown option %s\n", opt.c_str());
      return 2;
    }
  }
  const std::vector<Message> messages = all_messages();
  message_seeds();
  track_seeds();
  vo_seeds();
  flightsim_seeds();
  link_seeds();
  copy_configs();
  pmd_seeds();
  calibration_seeds();
  dataset_seeds();
  octomap_seeds(messages);
  event_log_seeds(messages);
  if (!log.empty()) log_seeds(log);
  if (!reliability.empty()) reliability_regressions(reliability);
  std::printf("%d files written under %s\n", g_written, g_fuzz_dir.c_str());
  return 0;
}
