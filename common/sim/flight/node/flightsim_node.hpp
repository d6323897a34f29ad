#pragma once
// aerie-flightsim as a class: publishes what the simulated vehicle senses (IMU, CAM_DOWN,
// optionally CAM_STEREO) and the ground truth (GT_POSE, GT_TRACK, SIM_STATE), and moves
// the vehicle by CTRL_CMD alone.
//
// Lock-step protocol (tests and benches): frame k's messages are published in the order
// IMU samples of (t_{k-1}, t_k], GT_POSE, GT_TRACK, SIM_STATE, images; then the node waits
// until every answer channel (default: CTRL_CMD) has carried a message whose utime is
// >= t_k — the consumers' answer to frame k — and only then steps the physics to k+1.
// A missing answer is waited for `answer_timeout_s` of wall time, then counted
// (lockstep_timeouts) and the simulation goes on. Commands act at the simulation time
// they are answered at (plus the vehicle's latency), so results do not depend on how
// fast the consumers run. Real-time mode publishes frame k at wall time t_k / speed and
// applies commands as they come.
#include <aerie/control_cmd_t.hpp>
#include <aerie/gt_box_t.hpp>
#include <aerie/image_t.hpp>

#include <cstdint>
#include <map>
#include <string>
#include <vector>

#include "common/bus/bus.hpp"
#include "common/bus/status.hpp"
#include "common/sim/flight/flight_sim.hpp"

namespace aerie::sim {

struct FlightSimNodeOptions {
  std::vector<std::string> answer_channels{"CTRL_CMD"};
  double answer_timeout_s = 5.0;  // wall time per frame before a missing answer is counted
  std::string command_channel = "CTRL_CMD";  // "": none (the vehicle is commanded through its autopilot)
  std::string imu_channel = "IMU";
  std::string down_channel = "CAM_DOWN";
  std::string stereo_channel = "CAM_STEREO";
  std::string gt_pose_channel = "GT_POSE";    // forward left camera (as aerie-capture --source sim)
  std::string gt_track_channel = "GT_TRACK";  // the pad's box in CAM_DOWN
  std::string state_channel = "SIM_STATE";
};

// The messages aerie-flightsim publishes for its down camera (also what the fuzz seeds of
// aerie-track are made of): the image with its camera's name and intrinsics in the metadata
// (aerie-track reads them: no calibration to mismatch), and the pad's box in it.
aerie::image_t image_message(const cv::Mat& img, int64_t utime, int64_t seq, const std::string& camera,
                             const Intrinsics& K);
aerie::gt_box_t gt_box_message(const StereoFrame& down, int64_t utime, int64_t seq, const std::string& camera);

class FlightSimNode {
 public:
  FlightSimNode(bus::Bus& bus, FlightSim& sim, FlightSimNodeOptions options);

  // Steps the simulator to the next frame and publishes it.
  const FlightFrame& publish_next();
  // Lock-step: handles messages until every answer channel has answered the last
  // published frame; false (and counted) on timeout.
  bool wait_answers();
  // Copies counters and health into the status reporter.
  void report(bus::StatusReporter& status) const;

  const FlightFrame& last() const { return frame_; }
  int64_t lockstep_timeouts() const { return timeouts_; }
  int64_t commands_received() const { return commands_; }
  // Faults (tools/faults): while stalled, frames publish no images (IMU and truth go on).
  void stall_cameras(bool stalled) { cameras_stalled_ = stalled; }
  int64_t stalled_frames() const { return stalled_frames_; }

 private:
  void on_command(const aerie::control_cmd_t& cmd);

  bus::Bus& bus_;
  FlightSim& sim_;
  FlightSimNodeOptions opt_;
  FlightFrame frame_;
  std::map<std::string, int64_t> answered_;  // newest utime per answer channel
  int64_t timeouts_ = 0, commands_ = 0, imu_seq_ = 0, stalled_frames_ = 0;
  bool cameras_stalled_ = false;
};

}  // namespace aerie::sim
