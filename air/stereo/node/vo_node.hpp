#pragma once
// aerie-vo's LCM side: CAM_STEREO in; VO_POSE, VO_DEPTH and STATUS_VO out. The odometry
// itself is air/stereo/vo; this class checks the input, converts messages and reports.
#include <aerie/stereo_image_t.hpp>

#include <memory>
#include <optional>
#include <string>

#include "air/stereo/vo/vo.hpp"
#include "common/bus/bus.hpp"
#include "common/bus/input_clock.hpp"
#include "common/bus/status.hpp"
#include "common/spherical/spherical_depth.hpp"
#include "common/util/config.hpp"
#include "common/util/time.hpp"

namespace aerie::stereo {

struct VoNodeConfig {
  VoParams vo;
  std::string input = "CAM_STEREO";
  std::string pose = "VO_POSE";
  std::string depth = "VO_DEPTH";  // "" = no VO_DEPTH
  int64_t max_pair_skew_us = 1000;
  double spherical_resolution_deg = 0.5;
  double spherical_max_range_m = 20.0;
  // Pairs waiting for the odometry in the node's own input queue (bus::subscribe_queued): when
  // it is full the oldest waiting pair is dropped (the odometry works on the newest) and counted
  // as <input>.queue_overflows, apart from <input>.sequence_gaps (pairs that never arrived).
  int queue = 4;
  // message_time.*: the camera's time (docs/architecture.md "Message time"): jumps are held,
  // a restart / outage re-synchronises (and restarts the odometry from the last pose), no pair
  // for stale_timeout_s is reported as "<input> stale".
  util::MessageClockConfig message_time;
};
// config/vo.yaml: the VO keys and the "node" section.
VoNodeConfig load_vo_node_config(const util::Config& cfg);

class VoNode {
 public:
  // `now` is the node's clock for staleness (wall clock live; tests pass theirs).
  VoNode(bus::Bus& bus, bus::StatusReporter& status, const VoNodeConfig& cfg, util::NodeClock now = util::wall_utime);
  ~VoNode();

  // Handles one stereo pair (also called by the subscription). Never throws: refused pairs
  // are logged and counted.
  void on_stereo(const aerie::stereo_image_t& msg, int64_t receive_utime);

  // Reports the camera stale when no pair came for message_time.stale_timeout_s, and pairs
  // dropped from the input queue since the last pair was published.
  void tick();

  int64_t processed() const { return processed_; }
  // Pairs dropped here because the input queue was full, and pairs missing upstream (seq gaps).
  int64_t queue_overflows() const { return input_.counters().queue_overflows; }
  int64_t upstream_gaps() const { return input_.counters().sequence_gaps; }
  int64_t refused() const { return refused_; }
  const std::optional<VoResult>& last() const { return last_; }

 private:
  // Throws std::invalid_argument with the reason when the pair cannot be used.
  void check(const aerie::stereo_image_t& msg) const;
  void publish(const VoResult& r, int64_t seq, int64_t receive_utime);
  // status_.ok(state), naming the input's losses; WARN for a while after a pair was dropped here.
  void report(const std::string& state);

  bus::Bus& bus_;
  bus::StatusReporter& status_;
  VoNodeConfig cfg_;
  util::NodeClock now_;
  bus::InputClock camera_clock_;
  bus::Subscription& input_;
  int64_t reported_overflows_ = 0, last_overflow_us_ = 0;
  std::unique_ptr<StereoOdometry> vo_;
  std::unique_ptr<spherical::SphericalEncoder> encoder_;
  int64_t last_utime_ = -1;
  int older_run_ = 0;      // pairs older than last_utime_ in a row, each newer than the one before
  int64_t older_last_ = 0;
  std::optional<StereoCamera> pending_camera_;  // another camera than vo_'s, seen camera_run_ pairs in a row
  int camera_run_ = 0;
  int64_t processed_ = 0, refused_ = 0, seq_ = 0;
  std::optional<VoResult> last_;
};

}  // namespace aerie::stereo
