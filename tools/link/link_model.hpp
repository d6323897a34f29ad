#pragma once
// One direction of the emulated air-ground radio link, in user space (kernel netem
// is not available, and a relay is what users run on a real radio too).
//
// A packet that arrives waits in a bounded FIFO queue for the transmitter; the
// transmitter sends one packet at a time at the bandwidth cap (serialisation time =
// wire bytes * 8 / rate); a sent packet is lost or not (independent Bernoulli, or
// the bursty two-state Gilbert-Elliott channel), and a kept packet is delivered
// after the propagation delay plus jitter. Without `reorder`, deliveries keep the
// arrival order (a packet is never delivered before the one sent before it).
//
// Time is given by the caller (microseconds, monotonic), so the model is exactly
// reproducible: for a given seed, which packets are lost and the delays drawn
// depend only on the order of the packets.
#include <cstdint>
#include <deque>
#include <random>
#include <string>
#include <vector>

namespace aerie::link {

enum class JitterDistribution { Normal, Uniform, Exponential };
enum class QueuePolicy { DropOldest, DropNewest };
enum class LossModel { Bernoulli, GilbertElliott };

// Gilbert-Elliott channel: a Markov chain between a Good and a Bad state, moved
// once per packet; a packet is lost with loss_good in Good and loss_bad in Bad.
struct GilbertElliott {
  double p_good_to_bad = 0.0;
  double p_bad_to_good = 1.0;
  double loss_good = 0.0;
  double loss_bad = 1.0;
  // Stationary loss rate: (r * loss_good + p * loss_bad) / (p + r).
  double mean_loss() const;
};

struct DirectionConfig {
  std::string name = "air->ground";
  std::string channels = ".*";     // LCM channel regex of what this direction relays
  double delay_ms = 0.0;           // propagation delay
  double jitter_ms = 0.0;          // standard deviation of the delay's random part
  JitterDistribution jitter = JitterDistribution::Normal;
  bool reorder = false;            // let jitter reorder packets
  LossModel loss_model = LossModel::Bernoulli;
  double loss = 0.0;               // Bernoulli loss probability
  GilbertElliott gilbert_elliott;
  double bandwidth_bps = 0.0;      // 0 = unlimited
  int64_t queue_bytes = 4 << 20;   // waiting room in front of the transmitter
  QueuePolicy queue_policy = QueuePolicy::DropOldest;
  std::string jpeg_channels;       // channel regex of images to re-encode ("" = none)
  int jpeg_quality = 50;
  uint64_t seed = 1;

  // Throws std::invalid_argument naming the field when a value is out of range.
  void validate() const;
};

struct Packet {
  std::string channel;
  std::vector<uint8_t> data;
  int64_t arrival_us = 0;          // monotonic time it was received
  int64_t recv_wall_utime = 0;     // wall clock of reception (for the achieved delay)
  int64_t release_us = 0;          // set by the model: when it is delivered
  uint64_t serial = 0;             // set by the model: arrival order in this direction
};

// What the packet costs on the air: payload and channel name plus LCM (8 bytes,
// 20 per fragment for fragmented messages) and UDP/IPv4 (28 bytes per datagram).
int64_t wire_bytes(const std::string& channel, size_t payload_size);

struct DirectionCounters {
  int64_t received = 0;
  int64_t delivered = 0;
  int64_t bytes_delivered = 0;     // wire bytes
  int64_t dropped_loss = 0;
  int64_t dropped_queue = 0;
  int64_t dropped_other = 0;       // e.g. a single packet larger than the whole queue
  int64_t dropped_outage = 0;      // sent or in flight while the link was down (faults)
  int64_t reencoded = 0;
};

class LinkDirection {
 public:
  explicit LinkDirection(DirectionConfig config);

  void offer(Packet packet, int64_t now_us);
  // Packets whose delivery time has come, in delivery order.
  std::vector<Packet> due(int64_t now_us);
  // When something next happens (a transmission ends or a delivery is due); -1 = idle.
  int64_t next_event_us() const;

  // Faults (tools/faults): while down, what is in flight and what is sent is lost; impair()
  // sets the delay and a Bernoulli loss for what is sent from now on (throws on bad values),
  // restore() the configured ones.
  void set_down(bool down);
  bool down() const { return down_; }
  void impair(double delay_ms, double loss);
  void restore() { config_ = configured_; }

  int queue_depth() const { return static_cast<int>(waiting_.size()); }
  int64_t queue_bytes() const { return waiting_bytes_; }
  int in_flight() const { return static_cast<int>(in_flight_.size()); }
  const DirectionCounters& counters() const { return counters_; }
  DirectionCounters& counters() { return counters_; }
  const DirectionConfig& config() const { return config_; }

 private:
  void transmit(int64_t now_us);
  bool draw_loss();
  int64_t draw_delay_us();

  struct Later {
    bool operator()(const Packet& a, const Packet& b) const {
      return a.release_us != b.release_us ? a.release_us > b.release_us : a.serial > b.serial;
    }
  };

  DirectionConfig config_, configured_;
  std::mt19937_64 loss_rng_, delay_rng_;  // separate streams: losses never shift delays
  std::deque<Packet> waiting_;
  int64_t waiting_bytes_ = 0;
  int64_t transmitter_free_us_ = 0;
  std::vector<Packet> in_flight_;  // min-heap on (release_us, serial)
  int64_t last_release_us_ = 0;
  uint64_t next_serial_ = 0;
  bool bad_state_ = false;
  bool down_ = false;
  DirectionCounters counters_;
};

const char* to_string(JitterDistribution d);
JitterDistribution jitter_from_string(const std::string& s);   // normal, uniform, exponential
QueuePolicy queue_policy_from_string(const std::string& s);    // drop_oldest, drop_newest
LossModel loss_model_from_string(const std::string& s);        // bernoulli, gilbert_elliott

}  // namespace aerie::link
