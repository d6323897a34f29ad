#pragma once
// End-to-end latency from a log (aerie-latency). Every Aerie message carries the
// utime of the camera frame it derives from as its first field, so for each event
//   latency = log receive time - message utime
// per channel; and nodes that record, in their STATUS_<NODE> heartbeat
// (aerie.process_status_t), the source utime of their last input and the wall-clock
// times they received it and published their result give the per-hop split:
//   input = receive - source,  processing = publish - receive,  age = publish - source.
// Times are those of the hosts' clocks: across hosts they must be synchronised.
// Messages stamped by another clock (recorded datasets) follow source_clock.hpp: their
// latency is measured from the frame's first arrival in the log.
#include <cstdint>
#include <map>
#include <optional>
#include <regex>
#include <string>
#include <vector>

#include "tools/latency/source_clock.hpp"
#include "tools/latency/stats.hpp"

namespace aerie::latency {

struct ChannelLatency {
  std::string channel;
  std::string type;               // message type name, "" when unknown
  Summary latency_ms;
  int64_t messages = 0;           // events on the channel
  int64_t unstamped = 0;          // unknown type or too short: no utime
  int64_t other_clock = 0;        // stamped by another clock (|receive - utime| > 1 h: dataset time)
  int64_t references = 0;         // of those, first arrivals of their frame: the reference, no latency
  std::string reference;          // the channel the others are measured from ("" when none is)
  int64_t negative = 0;           // received before its utime: the hosts' clocks disagree
};

struct HopLatency {
  std::string node;               // STATUS_<NODE> without the prefix
  Summary input_ms;               // receive - source
  Summary processing_ms;          // publish - receive
  Summary age_ms;                 // publish - source
  bool source_clock = false;      // the source on another clock: input and age from the frame's arrival
};

class LatencyAnalysis {
 public:
  struct Options {
    std::string channels = ".*";  // regex (whole channel names) of the channels reported
    bool unknown_types = false;   // also read utime from payloads of unknown types
  };
  LatencyAnalysis() : LatencyAnalysis(Options{}) {}
  explicit LatencyAnalysis(Options options);

  // One log event: its channel, the logger's receive time and the payload.
  void add(const std::string& channel, int64_t log_utime, const uint8_t* data, size_t size);

  std::vector<ChannelLatency> channels() const;  // sorted by channel name
  std::vector<HopLatency> hops() const;          // sorted by node name
  int64_t events() const { return events_; }

 private:
  struct Acc {
    std::string type;
    std::vector<double> ms;
    int64_t messages = 0, unstamped = 0, other_clock = 0, references = 0, negative = 0;
    std::string reference;
  };
  struct HopAcc {
    std::vector<double> input, processing, age;
    int64_t last_source = -1, last_receive = -1, last_publish = -1;
    bool source_clock = false;
  };
  Options options_;
  std::regex channel_re_;
  std::map<std::string, bool> matches_;
  std::map<std::string, Acc> channels_;
  std::map<std::string, HopAcc> hops_;
  FrameArrivals arrivals_;
  int64_t events_ = 0;
};

// Text table, CSV and JSON of the results.
std::string format_table(const std::vector<ChannelLatency>& channels, const std::vector<HopLatency>& hops);
std::string to_csv(const std::vector<ChannelLatency>& channels, const std::vector<HopLatency>& hops);
std::string to_json(const std::vector<ChannelLatency>& channels, const std::vector<HopLatency>& hops);

}  // namespace aerie::latency
