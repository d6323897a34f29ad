#pragma once
// aerie-nav as a class: IMU (aerie.imu_t) and VO_POSE (aerie.pose_t) in, NAV_STATE
// (aerie.nav_state_t) out, one per accepted IMU sample or at publish_rate_hz (message time).
// With resume.state_file, the filter's snapshot is kept on disk and a restarted node resumes
// from it in the same world frame.
// Bad messages are refused by the filter or here with a reason, counted and logged; the
// filter never sees a malformed one.
#include <cstdint>
#include <map>
#include <optional>
#include <string>

#include "air/nav/eskf.hpp"
#include "air/nav/nav_config.hpp"
#include "common/bus/bus.hpp"
#include "common/bus/channels.hpp"
#include "common/bus/status.hpp"
#include "common/util/message_clock.hpp"

namespace aerie {
class nav_state_t;
}

namespace aerie::nav {

// The state fields of NAV_STATE from the nominal state and the 15x15 covariance with the attitude
// error in the world frame (shared by the stereo and the mono node).
void fill_nav_state(aerie::nav_state_t& m, const NominalState& x, const Mat15& P_world_attitude, double time_since_vo_s);
int8_t nav_status_to_message(NavStatus s);

// The nodes' refusals: the last one, and a log that shows the 1st, 10th, 100th, ... per channel,
// so that a stream of them (VO poses before the alignment, a broken IMU) does not flood it.
struct RefusalLog {
  std::map<std::string, int64_t> per_channel;
  std::string last_error;
  void refused(const std::string& what, const std::string& why);
};
// The nodes' message-time policy (NavConfig::message_time): nullopt for a held stamp (counted in
// counters[held], logged); else the verdict (kResynced: the source restarted or came back).
std::optional<util::MessageClock::Verdict> admit_message_time(util::MessageClock& clock, const std::string& channel,
                                                              int64_t utime, std::map<std::string, int64_t>& counters,
                                                              const std::string& held, RefusalLog& log);

struct NavNodeOptions {
  std::string imu_channel = channels::kImu;
  std::string vo_channel = channels::kVoPose;
  std::string state_channel = channels::kNavState;
};

class NavNode {
 public:
  NavNode(bus::Bus& bus, NavConfig config, NavNodeOptions options = {});
  void report(bus::StatusReporter& status) const;
  const Eskf& filter() const { return eskf_; }
  int64_t counter(const std::string& name) const;

 private:
  void publish();
  // resume.state_file: true when the filter started from the snapshot read at construction
  // (at `first`, the first IMU sample); the snapshot is used or dropped at the first sample.
  bool resume_at(const ImuSample& first);
  void keep_snapshot();
  void refused(const std::string& what, const std::string& why);
  // The message-time policy (NavConfig::message_time): nullopt, counted and logged, for a held
  // stamp; else the verdict (kResynced: the source restarted or came back after an outage).
  std::optional<util::MessageClock::Verdict> admit(util::MessageClock& clock, const std::string& channel, int64_t utime);

  bus::Bus& bus_;
  NavConfig cfg_;
  NavNodeOptions opt_;
  Eskf eskf_;
  util::MessageClock imu_time_, vo_time_;
  std::map<std::string, int64_t> counters_;
  RefusalLog log_;
  NavStatus last_status_ = NavStatus::Initialising;
  int64_t seq_ = 0;
  int64_t last_publish_utime_ = INT64_MIN;
  std::optional<Snapshot> resume_from_;  // read from resume.state_file at construction
  int64_t last_snapshot_utime_ = INT64_MIN;
};

}  // namespace aerie::nav
