#pragma once
// Typed publish/subscribe over LCM 1.3, whose C++ API has no lambda subscribe.
// A subscription decodes the message itself, bounded (wire.hpp), so a corrupt or hostile
// payload is counted and logged instead of reaching the handler; a handler that throws is counted too.
// Gaps in `seq` are counted as drops (LCM drops silently when a queue is full).
// A queued subscription (subscribe_queued) takes every message off LCM at once into a bounded
// queue of its own that counts what it discards (queue_overflows), so its sequence gaps are
// upstream losses only (docs/stereo.md, "Keeping up on a small board").
#include <lcm/lcm-cpp.hpp>

#include <atomic>
#include <algorithm>
#include <concepts>
#include <cstdint>
#include <deque>
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
  std::atomic<int64_t> queue_overflows{0};  // queued subscription: discarded because its queue was full
};

// Which message a full queue of a queued subscription discards.
enum class Overflow {
  kDropOldest,  // keep the latest (a camera: work on the newest frame)
  kDropNewest,  // keep the first ones (as LCM's own queue)
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
  // Queued subscriptions: capacity of the own queue (0 = none, LCM's queue only) and messages waiting in it.
  size_t queue_capacity() const { return queue_capacity_; }
  virtual size_t queued() const { return 0; }

 protected:
  friend class Bus;
  void on_raw(const lcm::ReceiveBuffer* rbuf, const std::string& channel);
  virtual void dispatch(const lcm::ReceiveBuffer* rbuf, const std::string& channel) = 0;
  // Queued subscriptions: hands the oldest waiting message to the handler (false: none waits).
  bool deliver_one();
  virtual bool deliver_next() { return false; }
  // Runs f, counting (and logging) a malformed message or a handler that threw.
  void guarded(const std::string& channel, const std::function<void()>& f);
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
  size_t queue_capacity_ = 0;
};

template <typename Msg>
concept HasSeq = requires(Msg m) {
  { m.seq } -> std::convertible_to<int64_t>;
};

template <typename Msg>
class TypedSubscription final : public Subscription {
 public:
  using Handler = std::function<void(const Msg&, const ReceiveInfo&)>;
  explicit TypedSubscription(Handler h, size_t queue_capacity = 0, Overflow overflow = Overflow::kDropOldest)
      : handler_(std::move(h)), overflow_(overflow) {
    queue_capacity_ = queue_capacity;
  }
  size_t queued() const override { return queue_.size(); }

 private:
  void dispatch(const lcm::ReceiveBuffer* rbuf, const std::string& channel) override {
    Msg msg = decode_bounded<Msg>(rbuf->data, rbuf->data_size);  // throws std::invalid_argument
    // Before the own queue: a gap is a message that never reached this subscription.
    if constexpr (HasSeq<Msg>) note_seq(channel, msg.seq);
    ReceiveInfo info{channel, rbuf->recv_utime, rbuf->data_size};
    if (queue_capacity_ == 0) return handler_(msg, info);
    if (queue_.size() >= queue_capacity_) {
      ++counters_.queue_overflows;
      if (overflow_ == Overflow::kDropNewest) return;
      queue_.pop_front();
    }
    queue_.emplace_back(std::move(msg), std::move(info));
  }
  bool deliver_next() override {
    if (queue_.empty()) return false;
    auto [msg, info] = std::move(queue_.front());
    queue_.pop_front();
    handler_(msg, info);
    return true;
  }
  Handler handler_;
  Overflow overflow_;
  std::deque<std::pair<Msg, ReceiveInfo>> queue_;
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

  // A subscription with a bounded queue of its own: handle() first takes every message LCM
  // holds (decoded and queued, `overflow` deciding what a full queue discards, each one
  // counted in queue_overflows), then hands queued messages to the handler, oldest first,
  // one per handle() call, between LCM's. LCM's queue behind it holds kLcmSpill messages
  // (it only fills while one handler runs for longer than kLcmSpill messages take to come;
  // what it drops then shows as sequence gaps). capacity >= 1.
  static constexpr int kLcmSpill = 100;
  template <typename Msg>
  Subscription& subscribe_queued(const std::string& channel, typename TypedSubscription<Msg>::Handler handler,
                                 size_t capacity, Overflow overflow = Overflow::kDropOldest) {
    if (capacity < 1) throw std::invalid_argument("subscribe_queued: " + channel + ": queue capacity must be >= 1");
    auto sub = std::make_unique<TypedSubscription<Msg>>(std::move(handler), capacity, overflow);
    const int lcm_capacity = static_cast<int>(std::max<size_t>(capacity, kLcmSpill));
    return attach(std::move(sub), channel, lcm_capacity);
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
  // With queued subscriptions, one call takes everything LCM holds and then hands one queued
  // message on (waiting only when none is queued); the count includes both.
  int handle(int timeout_ms);
  int fileno() { return lcm_.getFileno(); }
  const std::string& url() const { return url_; }
  const std::vector<std::unique_ptr<Subscription>>& subscriptions() const { return subs_; }
  int64_t publish_errors() const { return publish_errors_; }

 private:
  friend class Subscription;
  Subscription& attach(std::unique_ptr<Subscription> sub, const std::string& channel, int queue_capacity);
  int handle_lcm(int timeout_ms);

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
  size_t next_queued_ = 0;  // the queued subscription handle() served last
  std::atomic<int64_t> publish_errors_{0};
};

}  // namespace aerie::bus
