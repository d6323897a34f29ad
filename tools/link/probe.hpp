#pragma once
// Measures a link end to end: publishes numbered, time-stamped messages on one LCM
// network and records what arrives on another (delay = LCM receive time minus the
// utime stamped at publication). Used by the link tests and benchmarks; works
// against a real radio too.
#include <cstdint>
#include <string>
#include <vector>

#include "common/bus/bus.hpp"

namespace aerie::link {

struct ProbeSample {
  int64_t seq = 0;
  int64_t sent_utime = 0;
  int64_t recv_utime = 0;
  size_t payload_bytes = 0;   // LCM payload
  std::string pixel_format;   // of the aerie.image_t that arrived
};

class Probe {
 public:
  // Messages are aerie.image_t (GRAY8, `payload` pixels wide, 1 high) on `channel`.
  Probe(bus::Bus& source, bus::Bus& sink, std::string channel);

  // Publishes n messages at rate_hz (0 = as fast as possible) while receiving, then
  // keeps receiving for drain_ms.
  void run(int n, double rate_hz, size_t payload, int drain_ms);
  // Receives (and keeps what arrives) for ms milliseconds.
  void pump(int ms);

  int64_t sent() const { return sent_; }
  const std::vector<ProbeSample>& received() const { return received_; }
  std::vector<double> delays_ms() const;
  std::vector<int64_t> lost() const;   // sequence numbers sent and never received
  int64_t duplicates() const { return duplicates_; }

 private:
  bus::Bus& source_;
  bus::Bus& sink_;
  std::string channel_;
  int64_t sent_ = 0;
  int64_t duplicates_ = 0;
  std::vector<ProbeSample> received_;
  std::vector<bool> seen_;
};

}  // namespace aerie::link
