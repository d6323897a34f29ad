#pragma once
// config/nav.yaml -> NavConfig (every key documented there; unknown keys are rejected naming
// the file and the key; values are checked by EskfParams::validate()).
#include <string>

#include "air/nav/eskf.hpp"
#include "air/nav/msf.hpp"
#include "common/util/config.hpp"
#include "common/util/message_clock.hpp"

namespace aerie::nav {

struct NavConfig {
  EskfParams eskf;
  // source: stereo (VO_POSE, metric: the Eskf) or mono (mono.channel, arbitrary scale: the MonoEskf).
  enum class Source { Stereo, Mono } source = Source::Stereo;
  MonoParams mono;
  std::string mono_channel = "MONO_POSE";
  double publish_rate_hz = 0.0;  // NAV_STATE rate in message time; 0 = every accepted IMU sample
  // The node's message-time policy per source (the IMU; the VO's camera): a stamp more than
  // 1 s from the newest is held, so one bogus stamp never moves the filter's clock
  // (docs/architecture.md "Message time").
  util::MessageClockConfig message_time{1'000'000, 3, 2'000'000};
  // The IMU's own bound (imu.max_jump_s), tighter: it comes at 200 Hz, and a bit-flipped
  // stamp 0.9 s ahead, within the 1 s above, moved the filter's clock and lost the VO.
  int64_t imu_max_jump_us = 200'000;
  // Resuming after a restart in flight (resume.*; air/nav/state_file.hpp).
  struct Resume {
    std::string state_file;        // "" = none: a restarted aerie-nav aligns again (a new frame)
    double write_period_s = 0.1;   // message time between two snapshots written
    double max_age_s = 2.0;        // a snapshot older than this at the first IMU sample is not resumed from
    GapNoise gap;
  } resume;
};

NavConfig load_nav_config(const util::Config& cfg);
// The default camera.T_body_cam: the simulator's forward stereo rig with its defaults (left
// camera at +0.06 m along body y, optical axis along body x pitched 20 deg down; docs/sim.md).
geometry::SE3 sim_forward_rig_T_body_cam();
// A 4x4 row-major homogeneous transform (16 numbers, EuRoC's T_BS layout) as an SE3; throws
// naming `what` when it is not 16 finite numbers with an orthonormal rotation and last row 0 0 0 1.
geometry::SE3 se3_from_row_major(const std::vector<double>& m, const std::string& what);

}  // namespace aerie::nav
