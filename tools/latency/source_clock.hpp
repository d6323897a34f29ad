#pragma once
// Latency on the source's own clock (used by aerie-latency and aerie-viewer).
//
// A message's utime is its source frame's time. Live, that is the wall clock and
//   latency = receive time - utime.
// Recorded data (a dataset, a log stamped by another host) carry stamps of another clock,
// e.g. EuRoC's 2015 nanoseconds: receive - utime is then years, not a latency. The rule:
//  * a message is on the receiver's clock when |receive - utime| <= kOtherClockUs (1 h);
//  * otherwise its latency is measured from its frame's first arrival: receive time minus
//    the receive time of the first message seen with the same utime (normally the camera
//    frame), both on the receiver's clock. The first arrival itself is the reference and
//    has no latency of its own.
// Node heartbeats (process_status_t) give receive and publish on the node's wall clock;
// with a source on another clock their input and age are taken from the frame's arrival.
#include <cstdint>
#include <deque>
#include <optional>
#include <string>
#include <unordered_map>

namespace aerie::latency {

inline constexpr int64_t kOtherClockUs = 3'600'000'000;  // 1 h

inline bool on_receive_clock(int64_t utime, int64_t receive_utime) {
  const int64_t d = receive_utime - utime;
  return d <= kOtherClockUs && d >= -kOtherClockUs;
}

// The first receive time of each frame (utime), for the newest `capacity` frames.
class FrameArrivals {
 public:
  struct Arrival {
    int64_t receive_utime;
    std::string channel;
  };
  explicit FrameArrivals(size_t capacity = 8192) : capacity_(capacity) {}
  // Records (utime, receive) unless the frame was seen; returns its first arrival.
  const Arrival& note(int64_t utime, int64_t receive_utime, const std::string& channel);
  const Arrival* find(int64_t utime) const;

 private:
  size_t capacity_;
  std::unordered_map<int64_t, Arrival> first_;
  std::deque<int64_t> order_;
};

struct Measured {
  double ms = 0;
  bool source_clock = false;  // stamped by another clock: measured from the frame's first arrival
  std::string reference;      // with source_clock: the channel of that first arrival
};
// The rule above for one message (records its arrival). nullopt for a first arrival on
// another clock: the reference, not a latency.
std::optional<Measured> measure(FrameArrivals& arrivals, const std::string& channel, int64_t utime,
                                int64_t receive_utime);

}  // namespace aerie::latency
