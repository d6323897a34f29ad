#include "common/util/message_clock.hpp"

#include <algorithm>
#include <cmath>
#include <sstream>
#include <stdexcept>

namespace aerie::util {

namespace {

// (a - b) in seconds, exact enough for a message and free of int64 overflow.
double seconds_between(int64_t a, int64_t b) {
  return static_cast<double>(static_cast<long double>(a) - static_cast<long double>(b)) * 1e-6;
}

std::string jump_words(int64_t to, int64_t from) {
  std::ostringstream s;
  const double d = seconds_between(to, from);
  s << (d >= 0 ? "forwards " : "backwards ") << std::abs(d) << " s";
  return s.str();
}

}  // namespace

void MessageClockConfig::validate() const {
  constexpr int64_t kHour = int64_t{3600} * 1000000;
  if (!(max_jump_us > 0 && max_jump_us <= kHour))
    throw std::invalid_argument("message_time: max_jump_s must be in (0, 3600] s");
  if (!(resync_messages >= 1 && resync_messages <= 1000))
    throw std::invalid_argument("message_time: resync_messages must be in [1, 1000]");
  if (!(stale_timeout_us > 0 && stale_timeout_us <= kHour))
    throw std::invalid_argument("message_time: stale_timeout_s must be in (0, 3600] s");
}

MessageClockConfig MessageClockConfig::from_config(const Config& section, MessageClockConfig c) {
  section.check_keys({"max_jump_s", "resync_messages", "stale_timeout_s"});
  // get_in() refuses outside the closed range; 1 µs stands for the open lower bound.
  const auto us = [&](const char* key, int64_t fallback) {
    return static_cast<int64_t>(std::llround(section.get_in(key, static_cast<double>(fallback) * 1e-6, 1e-6, 3600.0) * 1e6));
  };
  c.max_jump_us = us("max_jump_s", c.max_jump_us);
  c.stale_timeout_us = us("stale_timeout_s", c.stale_timeout_us);
  c.resync_messages = section.get_in("resync_messages", c.resync_messages, 1, 1000);
  c.validate();
  return c;
}

MessageClockConfig MessageClockConfig::from_config(const Config& section) {
  return from_config(section, MessageClockConfig{});
}

MessageClock::MessageClock(std::string source, MessageClockConfig config)
    : source_(std::move(source)), cfg_((config.validate(), config)) {}

bool within(int64_t a, int64_t b, int64_t limit) {
  const uint64_t d = a >= b ? static_cast<uint64_t>(a) - static_cast<uint64_t>(b)
                            : static_cast<uint64_t>(b) - static_cast<uint64_t>(a);
  return d <= static_cast<uint64_t>(limit);
}

MessageClock::Result MessageClock::observe(int64_t utime, int64_t now_us) {
  if (!synced_ || within(utime, newest_, cfg_.max_jump_us)) {
    // The first message sets the time base; a message near the newest continues it, and
    // ends any confirmation of another time base (that one was an outlier).
    newest_ = synced_ ? std::max(newest_, utime) : utime;
    synced_ = true;
    candidate_count_ = 0;
    last_accept_now_ = now_us;
    return {};
  }
  // A jump: a new time base is confirmed by consistent messages there, one at a time.
  if (candidate_count_ > 0 && within(utime, candidate_, cfg_.max_jump_us)) {
    candidate_ = std::max(candidate_, utime);
    ++candidate_count_;
  } else {
    candidate_ = utime;
    candidate_count_ = 1;
  }
  if (candidate_count_ >= cfg_.resync_messages) {
    Result r{Verdict::kResynced, source_ + " re-synchronised: time moved " + jump_words(candidate_, newest_) +
                                     " (restart or outage), " + std::to_string(candidate_count_) +
                                     " consistent message(s) at the new time"};
    newest_ = candidate_;
    candidate_count_ = 0;
    last_accept_now_ = now_us;
    ++resyncs_;
    return r;
  }
  ++held_;
  std::ostringstream m;
  m << source_ << " utime " << utime << " jumps " << jump_words(utime, newest_) << " from the newest (bound "
    << seconds_between(cfg_.max_jump_us, 0) << " s): held, " << candidate_count_ << " of " << cfg_.resync_messages
    << " consistent messages to re-synchronise";
  return {Verdict::kHeld, m.str()};
}

bool MessageClock::stale(int64_t now_us) const {
  return synced_ && seconds_between(now_us, last_accept_now_) > seconds_between(cfg_.stale_timeout_us, 0);
}

std::optional<std::string> MessageClock::stale_change(int64_t now_us) {
  const bool s = stale(now_us);
  if (s == stale_reported_) return std::nullopt;
  stale_reported_ = s;
  if (!s) return std::string();
  std::ostringstream m;
  m << source_ << " stale: no message for " << seconds_between(now_us, last_accept_now_) << " s (timeout "
    << seconds_between(cfg_.stale_timeout_us, 0) << " s)";
  return m.str();
}

}  // namespace aerie::util
