#pragma once
// The link's hop in a split deployment, from two logs: the air side's and the ground side's
// (each side's lcm-logger, or aerie-linkstudy --logs). A message is matched across the logs by
// its channel and its source utime (every Aerie message carries it first; a JPEG re-encoded
// image keeps it), so
//   hop latency = log time on the receiving side - log time on the sending side,
// and the sending side of a channel is the one that logs its messages first (when the times
// tie, as over a zero-delay simulated link: the side with more of them, else the hint). A message the
// sender logged and the receiver never did was lost on the way (or cut by the logs' ends).
// Both logs must be stamped by synchronised clocks (one host, or PTP/NTP across hosts).
#include <cstdint>
#include <map>
#include <string>
#include <utility>
#include <vector>

#include "tools/latency/stats.hpp"

namespace aerie::latency {

struct LinkHop {
  std::string channel;
  std::string direction;   // "air->ground" or "ground->air"
  Summary latency_ms;      // over the messages logged on both sides
  int64_t sent = 0;        // messages in the sending side's log
  int64_t delivered = 0;   // of those, also in the receiving side's log
};

class LinkJoin {
 public:
  enum class Log { kAir, kGround };
  // One log event (its channel, the log's time and the payload). Events without a utime are ignored.
  void add(Log log, const std::string& channel, int64_t log_utime, const uint8_t* data, size_t size);
  // Which way `channel` crosses, for when the logs cannot tell (equal times and counts).
  void hint(const std::string& channel, bool air_to_ground) { hints_[channel] = air_to_ground; }
  // The channels logged on both sides, by name.
  std::vector<LinkHop> hops() const;

 private:
  std::map<std::string, bool> hints_;
  // (channel) -> source utime -> first log time on each side (-1: not logged there)
  std::map<std::string, std::map<int64_t, std::pair<int64_t, int64_t>>> seen_;
};

std::string format_link_table(const std::vector<LinkHop>& hops);

}  // namespace aerie::latency
