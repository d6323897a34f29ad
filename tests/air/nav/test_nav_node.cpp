// aerie-nav's node over memq://: one NAV_STATE per IMU sample, INITIALISING until the static
// alignment, VO poses applied, bad inputs refused and counted, an outage reported; a restarted
// node resuming from its state file; and config/nav.yaml: it documents the defaults, unknown
// keys and bad values are refused.
#include <aerie/imu_t.hpp>
#include <aerie/nav_state_t.hpp>
#include <aerie/pose_t.hpp>
#include <gtest/gtest.h>

#include <cmath>
#include <filesystem>
#include <fstream>
#include <vector>

#include "air/nav/nav_config.hpp"
#include "air/nav/node/nav_node.hpp"
#include "air/nav/state_file.hpp"
#include "tests/support/test_support.hpp"

using namespace aerie;

namespace {

aerie::imu_t still_imu(int64_t utime) {
  aerie::imu_t m{};
  m.utime = utime;
  m.seq = utime / 5000;
  m.angular_velocity[0] = 0.003;  // a gyro bias
  m.angular_velocity[1] = -0.002;
  m.angular_velocity[2] = 0.001;
  m.linear_acceleration[2] = 9.81;
  m.orientation[0] = 1.0;
  return m;
}

}  // namespace

TEST(NavNode, PublishesStateAppliesVoAndCountsBadInputs) {
  bus::Bus bus("memq://");
  nav::NavConfig cfg = nav::load_nav_config(util::Config::load(AERIE_SOURCE_DIR "/config/nav.yaml"));
  nav::NavNode node(bus, cfg);
  std::vector<aerie::nav_state_t> states;
  bus.subscribe<aerie::nav_state_t>("NAV_STATE", [&](const aerie::nav_state_t& m, const bus::ReceiveInfo&) { states.push_back(m); });
  auto drain = [&] {
    while (bus.handle(0) > 0) {
    }
  };
  int64_t t = 1'000'000;
  for (int k = 0; k < 150; ++k) {  // 0.75 s: still aligning
    bus.publish("IMU", still_imu(t += 5000));
    drain();
  }
  ASSERT_EQ(states.size(), 150u);
  EXPECT_EQ(states.back().status, aerie::nav_state_t::INITIALISING);
  EXPECT_NE(states.back().reason.find("static alignment"), std::string::npos) << states.back().reason;
  for (int k = 0; k < 60; ++k) {  // past the 1 s window
    bus.publish("IMU", still_imu(t += 5000));
    drain();
  }
  ASSERT_EQ(states.size(), 210u);
  const aerie::nav_state_t& s = states.back();
  EXPECT_EQ(s.status, aerie::nav_state_t::OK);
  EXPECT_EQ(s.utime, t);
  EXPECT_NEAR(s.gyro_bias[0], 0.003, 1e-12);
  EXPECT_NEAR(s.gyro_bias[1], -0.002, 1e-12);
  EXPECT_NEAR(s.orientation[0], 1.0, 1e-9);  // level, yaw 0
  EXPECT_GT(s.attitude_covariance[0], 0.0);
  EXPECT_EQ(s.attitude_covariance[0], s.covariance_diagonal[6]);

  // VO: the first pose anchors the VO frame, the next ones are applied.
  aerie::pose_t vo{};
  vo.orientation[0] = 1.0;
  for (int i = 0; i < 36; i += 7) vo.covariance[i] = 1e-4;
  for (int k = 0; k < 5; ++k) {
    vo.utime = t - 2500;  // between two IMU samples, behind the newest one
    vo.seq = k;
    vo.status = k == 0 ? aerie::pose_t::INITIALISING : aerie::pose_t::OK;
    bus.publish("VO_POSE", vo);
    for (int j = 0; j < 10; ++j) bus.publish("IMU", still_imu(t += 5000));
    drain();
  }
  EXPECT_EQ(node.filter().counters().vo_anchors, 1);
  EXPECT_EQ(states.back().vo_applied, 4);
  EXPECT_EQ(states.back().status, aerie::nav_state_t::OK);
  EXPECT_LT(std::abs(states.back().position[2]), 1e-3);

  // Bad inputs: refused, counted, no NAV_STATE for a refused IMU sample.
  const size_t before = states.size();
  aerie::imu_t bad = still_imu(t + 5000);
  bad.linear_acceleration[0] = std::nan("");
  bus.publish("IMU", bad);
  bus.publish("IMU", still_imu(t - 100000));  // back in time
  vo.utime = t;
  vo.orientation[0] = 2.0;  // not a unit quaternion
  bus.publish("VO_POSE", vo);
  vo.orientation[0] = 1.0;
  vo.status = aerie::pose_t::LOST;
  bus.publish("VO_POSE", vo);
  drain();
  EXPECT_EQ(states.size(), before);
  EXPECT_EQ(node.counter("imu_refused"), 2);
  EXPECT_EQ(node.filter().counters().imu_non_finite, 1);
  EXPECT_EQ(node.filter().counters().imu_time_not_increasing, 1);
  EXPECT_EQ(node.counter("vo_refused"), 1);
  EXPECT_EQ(node.counter("vo_not_tracking"), 1);

  // No VO for 0.4 s: IMU_ONLY, reported as a warning in the status.
  for (int k = 0; k < 80; ++k) bus.publish("IMU", still_imu(t += 5000));
  drain();
  EXPECT_EQ(states.back().status, aerie::nav_state_t::IMU_ONLY);
  EXPECT_GT(states.back().time_since_vo_s, 0.25);
  bus::StatusReporter status(bus, "nav");
  node.report(status);
  EXPECT_EQ(status.counter("imu_refused"), 2);
  EXPECT_EQ(status.counter("vo_applied"), 4);
  EXPECT_EQ(status.counter("imu_non_finite"), 1);
  for (size_t i = 1; i < states.size(); ++i) ASSERT_EQ(states[i].seq, states[i - 1].seq + 1);
}

TEST(NavNode, PublishRateLimitsNavState) {
  bus::Bus bus("memq://");
  nav::NavConfig cfg;
  cfg.publish_rate_hz = 50.0;  // every 4th sample at 200 Hz
  cfg.eskf.static_window_s = 0.1;
  nav::NavNode node(bus, cfg);
  int n = 0;
  bus.subscribe<aerie::nav_state_t>("NAV_STATE", [&](const aerie::nav_state_t&, const bus::ReceiveInfo&) { ++n; });
  int64_t t = 0;
  for (int k = 0; k < 400; ++k) bus.publish("IMU", still_imu(t += 5000));
  while (bus.handle(0) > 0) {
  }
  EXPECT_NEAR(n, 400 / 4 + 20, 21);  // about 100 after the alignment (+ the INITIALISING ones)
  EXPECT_LT(n, 150);
}

TEST(NavNode, OneBogusImuStampIsHeldAndTheFilterGoesOn) {
  // A corrupt or hostile IMU message stamped in the far future (fault campaign: it froze the
  // filter, which then refused every real sample as "not after the previous one").
  bus::Bus bus("memq://");
  nav::NavNode node(bus, nav::load_nav_config(util::Config::load(AERIE_SOURCE_DIR "/config/nav.yaml")));
  std::vector<aerie::nav_state_t> states;
  bus.subscribe<aerie::nav_state_t>("NAV_STATE", [&](const aerie::nav_state_t& m, const bus::ReceiveInfo&) { states.push_back(m); });
  int64_t t = 1'000'000;
  for (int k = 0; k < 250; ++k) bus.publish("IMU", still_imu(t += 5000));
  bus.publish("IMU", still_imu(t + (int64_t{1} << 50)));
  for (int k = 0; k < 20; ++k) bus.publish("IMU", still_imu(t += 5000));
  // Bit 20 flipped: 1.05 s ahead (a burst campaign's copy; within the VO's 1 s bound it moved
  // the filter's clock and lost the VO). The IMU's own bound, imu.max_jump_s, holds it.
  bus.publish("IMU", still_imu(t + (int64_t{1} << 20) - 130000));
  for (int k = 0; k < 20; ++k) bus.publish("IMU", still_imu(t += 5000));
  while (bus.handle(0) > 0) {
  }
  EXPECT_EQ(node.counter("imu_time_held"), 2);
  EXPECT_EQ(node.counter("imu_refused"), 0);
  ASSERT_EQ(states.size(), 290u);  // every real sample answered
  EXPECT_EQ(states.back().utime, t);
}

TEST(NavConfig, FileDocumentsTheDefaultsAndIsStrict) {
  const nav::NavConfig file = nav::load_nav_config(util::Config::load(AERIE_SOURCE_DIR "/config/nav.yaml"));
  const nav::NavConfig defaults = nav::load_nav_config(util::Config());
  const nav::EskfParams& a = file.eskf;
  const nav::EskfParams& b = defaults.eskf;
  EXPECT_EQ(file.publish_rate_hz, defaults.publish_rate_hz);
  EXPECT_EQ(file.imu_max_jump_us, defaults.imu_max_jump_us);
  EXPECT_EQ(a.gyro_noise_density, b.gyro_noise_density);
  EXPECT_EQ(a.accel_random_walk, b.accel_random_walk);
  EXPECT_EQ(a.max_imu_dt_s, b.max_imu_dt_s);
  EXPECT_EQ(a.static_window_s, b.static_window_s);
  EXPECT_EQ(a.static_max_accel_std_m_s2, b.static_max_accel_std_m_s2);
  EXPECT_NEAR(a.init_yaw_sigma_rad, b.init_yaw_sigma_rad, 1e-4);
  EXPECT_NEAR(a.vo_rotation_sigma_rad, b.vo_rotation_sigma_rad, 1e-4);
  EXPECT_EQ(a.gate_chi2, b.gate_chi2);
  EXPECT_EQ(a.lost_after_s, b.lost_after_s);
  EXPECT_EQ(a.buffer_s, b.buffer_s);
  EXPECT_LT((a.T_body_cam.matrix() - b.T_body_cam.matrix()).cwiseAbs().maxCoeff(), 1e-12);
  EXPECT_LT((b.T_body_cam.matrix() - nav::sim_forward_rig_T_body_cam().matrix()).cwiseAbs().maxCoeff(), 1e-12);

  auto refused = [](const std::string& yaml, const std::string& needle) {
    try {
      nav::load_nav_config(util::Config::parse(yaml, "nav-test.yaml"));
    } catch (const std::exception& e) {
      EXPECT_NE(std::string(e.what()).find(needle), std::string::npos) << e.what();
      return true;
    }
    return false;
  };
  EXPECT_TRUE(refused("imu: {max_dt: 0.1}\n", "unknown key 'max_dt'"));
  EXPECT_TRUE(refused("gate: 3\n", "unknown key 'gate'"));
  EXPECT_TRUE(refused("vo: {frame: world}\n", "vo.frame"));
  EXPECT_TRUE(refused("outage: {imu_only_after_s: 3, lost_after_s: 2}\n", "lost_after_s"));
  EXPECT_TRUE(refused("imu: {gyro_noise_density: -1}\n", "imu.gyro_noise_density"));
  EXPECT_TRUE(refused("imu: {max_jump_s: 0}\n", "max_jump_s"));
  EXPECT_TRUE(refused("camera: {T_body_cam: [1, 0, 0]}\n", "16 numbers"));
  EXPECT_TRUE(refused("camera: {T_body_cam: [2,0,0,0, 0,1,0,0, 0,0,1,0, 0,0,0,1]}\n", "not a rotation"));
  EXPECT_TRUE(refused("resume: {max_age: 1}\n", "unknown key 'max_age'"));
  EXPECT_TRUE(refused("resume: {write_period_s: 0}\n", "write_period_s"));
  EXPECT_TRUE(refused("resume: {gap_accel_sigma_m_s2: .nan}\n", "gap_accel_sigma_m_s2"));
  EXPECT_EQ(file.resume.state_file, "");
  EXPECT_EQ(file.resume.max_age_s, defaults.resume.max_age_s);
  EXPECT_NEAR(file.resume.gap.rate_sigma_rad_s, defaults.resume.gap.rate_sigma_rad_s, 1e-12);
  EXPECT_FALSE(refused("vo: {frame: fixed, noise: config}\npublish_rate_hz: 50\n", ""));
}

namespace {

// A VO pose in a VO frame that is not the world: the VO started 2 m east of the alignment point
// and turned 30 deg, so a new anchor would differ from the kept one.
aerie::pose_t vo_pose(int64_t utime, int8_t status) {
  aerie::pose_t m{};
  m.utime = utime;
  m.status = status;
  const Eigen::Quaterniond q(Eigen::AngleAxisd(0.5236, Eigen::Vector3d::UnitY()));
  m.orientation[0] = q.w();
  m.orientation[1] = q.x();
  m.orientation[2] = q.y();
  m.orientation[3] = q.z();
  m.position[0] = 2.0;
  return m;
}

}  // namespace

// One run of aerie-nav (a process: its own bus, gone with it).
struct NavProcess {
  bus::Bus bus{"memq://"};
  std::vector<aerie::nav_state_t> states;
  nav::NavNode node;
  explicit NavProcess(const nav::NavConfig& cfg) : node(bus, cfg) {
    bus.subscribe<aerie::nav_state_t>("NAV_STATE", [this](const aerie::nav_state_t& m, const bus::ReceiveInfo&) { states.push_back(m); });
  }
  void imu(int64_t utime) {
    bus.publish("IMU", still_imu(utime));
    drain();
  }
  void vo(int64_t utime, int8_t status) {
    bus.publish("VO_POSE", vo_pose(utime, status));
    drain();
  }
  void drain() {
    while (bus.handle(0) > 0) {
    }
  }
};

TEST(NavNode, ARestartedNodeResumesFromItsStateFileInTheSameFrame) {
  nav::NavConfig cfg = nav::load_nav_config(util::Config::load(AERIE_SOURCE_DIR "/config/nav.yaml"));
  cfg.resume.state_file = (test::scratch_dir("nav_state") / "nav.state").string();
  int64_t t = 1'000'000;
  geometry::SE3 anchor;
  {
    NavProcess first(cfg);
    for (int k = 0; k < 300; ++k) {  // aligned after 1 s, then VO every 50 ms
      first.imu(t += 5000);
      if (k >= 220 && k % 10 == 0) first.vo(t, k == 220 ? aerie::pose_t::INITIALISING : aerie::pose_t::OK);
    }
    ASSERT_EQ(first.node.filter().counters().vo_anchors, 1);
    ASSERT_GE(first.node.filter().counters().vo_applied, 7);
    anchor = *first.node.filter().T_world_vo();
    EXPECT_GE(first.node.counter("snapshots"), 4);  // every 0.1 s of message time once aligned
  }  // killed
  std::string why;
  const auto kept = nav::read_snapshot(cfg.resume.state_file, why);
  ASSERT_TRUE(kept) << why;
  EXPECT_GE(kept->x.utime, t - 100'000);  // written at most write_period_s before the end

  t += 300'000;  // down for 0.3 s
  NavProcess second(cfg);
  second.imu(t += 5000);
  ASSERT_EQ(second.states.size(), 1u);
  EXPECT_NE(second.states[0].status, aerie::nav_state_t::INITIALISING);  // no new alignment, no new frame
  EXPECT_EQ(second.node.filter().counters().resumed, 1);
  ASSERT_TRUE(second.node.filter().T_world_vo());
  EXPECT_LT((second.node.filter().T_world_vo()->matrix() - anchor.matrix()).cwiseAbs().maxCoeff(), 1e-12);
  for (int k = 0; k < 20; ++k) {  // the VO goes on in its frame: applied, not re-anchored
    second.imu(t += 5000);
    if (k % 10 == 0) second.vo(t, aerie::pose_t::OK);
  }
  EXPECT_EQ(second.node.filter().counters().vo_anchors, 0);
  EXPECT_EQ(second.node.filter().counters().vo_applied, 2);
  EXPECT_EQ(second.states.back().status, aerie::nav_state_t::OK);
  EXPECT_LT(std::hypot(second.states.back().position[0], second.states.back().position[1]), 0.05);  // where it aligned

  // A snapshot older than resume.max_age_s (another flight) is not resumed from: a new alignment.
  t += 10'000'000;
  NavProcess third(cfg);
  third.imu(t += 5000);
  EXPECT_EQ(third.states.back().status, aerie::nav_state_t::INITIALISING);
  EXPECT_EQ(third.node.filter().counters().resumed, 0);

  // A damaged file: not resumed from, the alignment starts the filter.
  std::ofstream(cfg.resume.state_file, std::ios::trunc) << "aerie-nav state 1\nutime 12\n";
  NavProcess fourth(cfg);
  fourth.imu(t += 5000);
  EXPECT_EQ(fourth.states.back().status, aerie::nav_state_t::INITIALISING);
}

TEST(NavStateFile, RoundTripsExactlyAndRefusesDamage) {
  const std::string path = (test::scratch_dir("state") / "nav.state").string();
  nav::Snapshot s;
  s.x.utime = 123456789;
  s.x.p = nav::Vec3(1.0 / 3.0, -2.5, 1e-9);
  s.x.v = nav::Vec3(0.1, 0.2, -0.3);
  s.x.q = Eigen::Quaterniond(Eigen::AngleAxisd(0.7, nav::Vec3(1, 2, 3).normalized()));
  s.x.bg = nav::Vec3(1e-3, -2e-3, 3e-4);
  s.x.ba = nav::Vec3(0.01, 0.02, -0.03);
  Eigen::Matrix<double, 15, 15> A = Eigen::Matrix<double, 15, 15>::Random();
  s.P = A * A.transpose() * 1e-3;
  s.last_update_utime = 123400000;
  std::string why;
  for (const bool anchored : {false, true}) {
    if (anchored) s.T_world_vo = geometry::SE3(Eigen::Quaterniond(Eigen::AngleAxisd(-1.2, nav::Vec3::UnitZ())), nav::Vec3(4, 5, 6));
    nav::write_snapshot(path, s);
    const auto r = nav::read_snapshot(path, why);
    ASSERT_TRUE(r) << why;
    EXPECT_EQ(r->x.utime, s.x.utime);
    EXPECT_EQ(r->last_update_utime, s.last_update_utime);
    EXPECT_EQ(r->x.p, s.x.p);  // 17 digits: exact
    EXPECT_EQ(r->x.v, s.x.v);
    EXPECT_EQ(r->x.q.coeffs(), s.x.q.coeffs());
    EXPECT_EQ(r->x.bg, s.x.bg);
    EXPECT_EQ(r->x.ba, s.x.ba);
    EXPECT_EQ(r->P, s.P);
    ASSERT_EQ(r->T_world_vo.has_value(), anchored);
    if (anchored) {
      EXPECT_LT((r->T_world_vo->matrix() - s.T_world_vo->matrix()).cwiseAbs().maxCoeff(), 1e-15);
    }
  }
  std::ifstream in(path);
  const std::string good((std::istreambuf_iterator<char>(in)), std::istreambuf_iterator<char>());
  auto refused = [&](const std::string& text, const std::string& needle) {
    std::ofstream(path, std::ios::trunc) << text;
    const auto r = nav::read_snapshot(path, why);
    EXPECT_FALSE(r) << text.substr(0, 60);
    EXPECT_NE(why.find(needle), std::string::npos) << why;
  };
  auto replaced = [&](const std::string& from, const std::string& to) {
    std::string t = good;
    t.replace(t.find(from), from.size(), to);
    return t;
  };
  refused(replaced("aerie-nav state 1", "aerie-nav state 2"), "not a state file of aerie-nav");
  refused(replaced("\nv ", "\nv nan "), "not a state file");
  refused(replaced("\nq ", "\nq 2 "), "not a state file");  // not a unit quaternion
  refused(replaced("\nP ", "\nP -1 "), "not a state file");  // a negative variance (and the rest shifted)
  refused(good.substr(0, good.size() / 2), "not a state file");  // truncated
  refused(good + "extra\n", "not a state file");
  refused("", "not a state file");
  std::filesystem::remove(path);
  EXPECT_FALSE(nav::read_snapshot(path, why));
  EXPECT_NE(why.find(path), std::string::npos) << why;
}
