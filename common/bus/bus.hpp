#pragma once
// Typed publish/subscribe over LCM 1.3, whose C++ API has no lambda subscribe.
// A subscription decodes the message itself, bounded (wire.hpp), so a corrupt or hostile
// payload is counted and logged instead of reaching the handler; a handler that throws is counted too.
// Gaps in `seq` are counted as drops (LCM drops silently when a queue is full).
#include <lcm/lcm-cpp.hpp>

#include <atomic>
#include <concepts>
#include <cstdint>
#include <functional>
#include <map>
#include <memory>
#include <optional>
#include <stdexcept>
#include <string>
#include <vector>

#include "common/bus/wire.hpp"

#if defined(__SANITIZE_THREAD__)
#define AERIE_TSAN 1
#elif defined(__has_feature)
#if __has_feature(thread_sanitizer)
#define AERIE_TSAN 1
#endif
#endif
#if AERIE_TSAN
#include <mutex>
#endif

namespace aerie::bus {

class Bus;

struct ChannelCounters {
  std::atomic<int64_t> received{0};
  std::atomic<int64_t> malformed{0};        // failed to decode
  std::atomic<int64_t> handler_errors{0};   // handler threw
  std::atomic<int64_t> sequence_gaps{0};    // messages missing according to seq
};

struct ReceiveInfo {
  std::string channel;
  int64_t recv_utime = 0;  // wall clock at reception (LCM's)
  size_t bytes = 0;
};

class Subscription {
 public:
  virtual ~Subscription() = default;
  const std::string& channel() const { return channel_; }
  const ChannelCounters& counters() const { return counters_; }
  const std::string& last_error() const { return last_error_; }

 protected:
  friend class Bus;
  void on_raw(const lcm::ReceiveBuffer* rbuf, const std::string& channel);
  virtual void dispatch(const lcm::ReceiveBuffer* rbuf, const std::string& channel) = 0;
  // Sequence gaps are counted per channel: a pattern subscription (STATUS_.*) hears several
  // publishers, each with its own seq. At most kSeqChannels channels are followed.
  void note_seq(const std::string& channel, int64_t seq);
  static constexpr size_t kSeqChannels = 256;

  std::string channel_;
  ChannelCounters counters_;
  std::string last_error_;
  std::map<std::string, int64_t> last_seq_;  // per channel heard
  lcm::Subscription* handle_ = nullptr;
  Bus* bus_ = nullptr;
};

template <typename Msg>
concept HasSeq = requires(Msg m) {
  { m.seq } -> std::convertible_to<int64_t>;
};

template <typename Msg>
class TypedSubscription final : public Subscription {
 public:
  using Handler = std::function<void(const Msg&, const ReceiveInfo&)>;
  explicit TypedSubscription(Handler h) : handler_(std::move(h)) {}

 private:
  void dispatch(const lcm::ReceiveBuffer* rbuf, const std::string& channel) override {
    const Msg msg = decode_bounded<Msg>(rbuf->data, rbuf->data_size);  // throws std::invalid_argument
    if constexpr (HasSeq<Msg>) note_seq(channel, msg.seq);
    handler_(msg, ReceiveInfo{channel, rbuf->recv_utime, rbuf->data_size});
  }
  Handler handler_;
};

// Undecoded messages (any type), e.g. for relays, loggers and latency measurement.
class RawSubscription final : public Subscription {
 public:
  using Handler = std::function<void(const uint8_t* data, size_t size, const ReceiveInfo&)>;
  explicit RawSubscription(Handler h) : handler_(std::move(h)) {}

 private:
  void dispatch(const lcm::ReceiveBuffer* rbuf, const std::string& channel) override {
    handler_(static_cast<const uint8_t*>(rbuf->data), rbuf->data_size,
             ReceiveInfo{channel, rbuf->recv_utime, rbuf->data_size});
  }
  Handler handler_;
};

// The utime of an Aerie message without decoding it: every Aerie type starts with
// `int64_t utime` right after the 8-byte fingerprint (big-endian). nullopt when too short.
std::optional<int64_t> peek_utime(const uint8_t* data, size_t size);

class Bus {
 public:
  // url "" = LCM_DEFAULT_URL or LCM's default. Throws std::runtime_error if LCM cannot start.
  explicit Bus(const std::string& url = "");
  Bus(const Bus&) = delete;
  Bus& operator=(const Bus&) = delete;
  ~Bus();

  template <typename Msg>
  void publish(const std::string& channel, const Msg& msg) {
    HandOff hand_off(*this);
    if (lcm_.publish(channel, &msg) != 0) ++publish_errors_;
  }
  // Encoded bytes as they are (relays, log replay, fault injection): the receiver decodes them.
  void publish_raw(const std::string& channel, const void* data, size_t size);

  // queue_capacity: messages LCM keeps for this subscription before dropping the newest.
  template <typename Msg>
  Subscription& subscribe(const std::string& channel, typename TypedSubscription<Msg>::Handler handler,
                          int queue_capacity = 30) {
    auto sub = std::make_unique<TypedSubscription<Msg>>(std::move(handler));
    return attach(std::move(sub), channel, queue_capacity);
  }

  // channel_regex is an LCM channel regular expression (e.g. "CAM_.*").
  Subscription& subscribe_raw(const std::string& channel_regex, RawSubscription::Handler handler,
                              int queue_capacity = 30) {
    return attach(std::make_unique<RawSubscription>(std::move(handler)), channel_regex, queue_capacity);
  }

  // Removes a subscription made on this bus (its handler is never called again, its
  // queued messages are dropped). Not from inside a handler. Throws if it is not ours.
  void unsubscribe(const Subscription& sub);

  // Handles messages for up to timeout_ms; returns how many were handled (0 on timeout).
  int handle(int timeout_ms);
  int fileno() { return lcm_.getFileno(); }
  const std::string& url() const { return url_; }
  const std::vector<std::unique_ptr<Subscription>>& subscriptions() const { return subs_; }
  int64_t publish_errors() const { return publish_errors_; }

 private:
  friend class Subscription;
  Subscription& attach(std::unique_ptr<Subscription> sub, const std::string& channel, int queue_capacity);

  // ThreadSanitizer cannot see the GLib mutex (a raw futex) with which liblcm's memq://
  // hands a published buffer to the thread that handles it, and reports our decoder's read
  // as a race with the publisher's copy. In TSan builds a pthread mutex of the bus, held
  // around every publish and taken at the start of every dispatch, shows it that edge; it
  // orders nothing LCM does not already order. Compiled out otherwise.
#if AERIE_TSAN
  struct HandOff {
    explicit HandOff(Bus& bus) : lock(bus.hand_off_) {}
    std::lock_guard<std::mutex> lock;
  };
  std::mutex hand_off_;
#else
  struct HandOff {
    explicit HandOff(Bus&) {}
  };
#endif

  std::string url_;
  lcm::LCM lcm_;
  std::vector<std::unique_ptr<Subscription>> subs_;
  std::atomic<int64_t> publish_errors_{0};
};

}  // namespace aerie::bus
