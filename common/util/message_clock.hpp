#pragma once
// The one message-time policy of every node (docs/architecture.md, "Message time"), without LCM.
//
// One MessageClock per input source (a process whose messages share one time base, e.g. the
// camera frames behind VO_POSE and VO_DEPTH). It keeps the newest accepted message time and:
//   * accepts a message within `max_jump_us` of the newest (either way: small reordering is the
//     node's business);
//   * holds (refuses) a message that jumps forwards or backwards by more than that: one outlier
//     (utime = INT64_MAX) never moves the clock;
//   * re-synchronises to a new time base after `resync_messages` consistent messages there (a
//     source that restarted, or came back after an outage): the one that completes the count is
//     accepted with Verdict::kResynced, and the node forgets what it kept of the old time base;
//   * reports the source stale when no message was accepted for longer than `stale_timeout_us`,
//     measured on the node's own clock (`now_us`: wall clock live, the simulation clock in
//     lock-step), from the first message on.
#include <cstdint>
#include <functional>
#include <optional>
#include <string>

#include "common/util/config.hpp"

namespace aerie::util {

// |a - b| <= limit (limit >= 0) for message times, without int64 overflow on hostile stamps.
bool within(int64_t a, int64_t b, int64_t limit);

// A node's own clock in microseconds: util::wall_utime live; a test or a lock-step driver
// passes its own.
using NodeClock = std::function<int64_t()>;

struct MessageClockConfig {
  int64_t max_jump_us = 10'000'000;     // message_time.max_jump_s: (0, 3600] s
  int resync_messages = 3;              // message_time.resync_messages: [1, 1000]
  int64_t stale_timeout_us = 2'000'000;  // message_time.stale_timeout_s: (0, 3600] s
  void validate() const;                // throws std::invalid_argument

  // Reads the keys of a `message_time:` section (missing keys keep the defaults given),
  // refusing unknown keys and values outside their ranges, naming file, key and line.
  static MessageClockConfig from_config(const Config& section, MessageClockConfig defaults);
  static MessageClockConfig from_config(const Config& section);
};

class MessageClock {
 public:
  enum class Verdict { kAccepted, kResynced, kHeld };
  struct Result {
    Verdict verdict = Verdict::kAccepted;
    std::string reason;  // for kHeld and kResynced: what happened, in words
    bool accepted() const { return verdict != Verdict::kHeld; }
  };

  explicit MessageClock(std::string source, MessageClockConfig config = {});

  // A message stamped `utime` (message time) arrived at node time `now_us`.
  Result observe(int64_t utime, int64_t now_us);

  // True from the first message on when none was accepted for longer than the timeout.
  bool stale(int64_t now_us) const;
  // Once per change: "<source> stale: no message for 25.0 s (timeout 2 s)" when it goes stale,
  // "" when it is live again; nullopt otherwise.
  std::optional<std::string> stale_change(int64_t now_us);

  bool synced() const { return synced_; }
  int64_t newest() const { return newest_; }  // newest accepted message time (valid when synced)
  int64_t held() const { return held_; }        // messages held as jumps so far
  int64_t resyncs() const { return resyncs_; }
  const std::string& source() const { return source_; }
  const MessageClockConfig& config() const { return cfg_; }

 private:
  std::string source_;
  MessageClockConfig cfg_;
  bool synced_ = false, stale_reported_ = false;
  int64_t newest_ = 0, last_accept_now_ = 0;
  int64_t candidate_ = 0;  // newest time of the time base being confirmed
  int candidate_count_ = 0;
  int64_t held_ = 0, resyncs_ = 0;
};

}  // namespace aerie::util
