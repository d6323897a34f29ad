#pragma once
// aerie-nav with a monocular source (nav.yaml source: mono): IMU (aerie.imu_t) and the mono VO's
// poses (aerie.pose_t with SCALE_ARBITRARY, mono.channel) in, NAV_STATE out, through the MSF filter
// (air/nav/msf.hpp) that also estimates the visual scale and the vision frame. NAV_STATE says
// SCALE_UNKNOWN while the filter is otherwise OK but the scale is not known yet; status shows the
// scale, its sigma and SCALE_OK/SCALE_UNKNOWN. No resume from a state file (stereo only).
#include <cstdint>
#include <map>
#include <optional>
#include <string>

#include "air/nav/msf.hpp"
#include "air/nav/nav_config.hpp"
#include "air/nav/node/nav_node.hpp"
#include "common/bus/bus.hpp"
#include "common/bus/status.hpp"
#include "common/util/message_clock.hpp"

namespace aerie::nav {

class MonoNavNode {
 public:
  // options.vo_channel is not used: the mono channel is config.mono_channel.
  MonoNavNode(bus::Bus& bus, NavConfig config, NavNodeOptions options = {});
  void report(bus::StatusReporter& status) const;
  const MonoEskf& filter() const { return filter_; }
  int64_t counter(const std::string& name) const;

 private:
  void publish();

  bus::Bus& bus_;
  NavConfig cfg_;
  NavNodeOptions opt_;
  MonoEskf filter_;
  util::MessageClock imu_time_, vo_time_;
  std::map<std::string, int64_t> counters_;
  RefusalLog log_;
  int8_t last_status_ = 0;  // nav_state_t status last published
  int64_t seq_ = 0;
  int64_t last_publish_utime_ = INT64_MIN;
  bool new_map_ = true;  // the next OK pose starts a map (after INITIALISING / a resync)
};

}  // namespace aerie::nav
