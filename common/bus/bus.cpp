#include "common/bus/bus.hpp"

#include <spdlog/spdlog.h>

#include <algorithm>
#include <cerrno>
#include <cstdlib>
#include <limits>
#include <sys/select.h>

namespace aerie::bus {

void Subscription::on_raw(const lcm::ReceiveBuffer* rbuf, const std::string& channel) {
#if AERIE_TSAN
  { std::lock_guard<std::mutex> hand_off(bus_->hand_off_); }  // after the publish that queued rbuf (bus.hpp)
#endif
  ++counters_.received;
  guarded(channel, [&] { dispatch(rbuf, channel); });
}

bool Subscription::deliver_one() {
  bool delivered = false;
  guarded(channel_, [&] { delivered = deliver_next(); });
  return delivered;
}

void Subscription::guarded(const std::string& channel, const std::function<void()>& f) {
  try {
    f();
  } catch (const std::invalid_argument& e) {
    ++counters_.malformed;
    last_error_ = channel + ": " + e.what();
    spdlog::warn("dropped message on {}: {}", channel, e.what());
  } catch (const std::exception& e) {
    ++counters_.handler_errors;
    last_error_ = channel + ": " + e.what();
    spdlog::error("handler for {} failed: {}", channel, e.what());
  }
}

void Subscription::note_seq(const std::string& channel, int64_t seq) {
  auto last = last_seq_.find(channel);
  if (last == last_seq_.end()) {
    if (last_seq_.size() < kSeqChannels) last_seq_.emplace(channel, seq);
    return;
  }
  // A seq at or below the last one is a restarted publisher or a replayed log: resynchronise.
  if (last->second >= 0 && seq > last->second && seq - last->second > 1) counters_.sequence_gaps += seq - last->second - 1;
  last->second = seq;
}

std::optional<int64_t> peek_utime(const uint8_t* data, size_t size) {
  if (size < 16) return std::nullopt;
  uint64_t v = 0;
  for (int i = 8; i < 16; ++i) v = (v << 8) | data[i];
  return static_cast<int64_t>(v);
}

namespace {
std::string resolve_url(const std::string& url) {
  if (!url.empty()) return url;
  const char* env = std::getenv("LCM_DEFAULT_URL");
  return env ? env : "";
}
}  // namespace

Bus::Bus(const std::string& url) : url_(resolve_url(url)), lcm_(url_) {
  if (!lcm_.good())
    throw std::runtime_error("cannot start LCM on '" + (url_.empty() ? std::string("default URL") : url_) +
                             "' (multicast route missing? try: ip route add 224.0.0.0/4 dev lo)");
}

Bus::~Bus() {
  for (auto& s : subs_)
    if (s->handle_) lcm_.unsubscribe(s->handle_);
}

Subscription& Bus::attach(std::unique_ptr<Subscription> sub, const std::string& channel, int queue_capacity) {
  sub->channel_ = channel;
  sub->bus_ = this;
  // LCM matches "^" + regex + "$": grouped, alternatives ("A|B") match whole names only.
  sub->handle_ = lcm_.subscribe("(" + channel + ")", &Subscription::on_raw, sub.get());
  if (!sub->handle_) throw std::runtime_error("cannot subscribe to " + channel);
  sub->handle_->setQueueCapacity(queue_capacity);
  subs_.push_back(std::move(sub));
  return *subs_.back();
}

void Bus::unsubscribe(const Subscription& sub) {
  const auto it = std::find_if(subs_.begin(), subs_.end(), [&](const auto& s) { return s.get() == &sub; });
  if (it == subs_.end()) throw std::invalid_argument("unsubscribe: " + sub.channel() + " is not a subscription of this bus");
  if ((*it)->handle_) lcm_.unsubscribe((*it)->handle_);
  subs_.erase(it);
}

void Bus::publish_raw(const std::string& channel, const void* data, size_t size) {
  HandOff hand_off(*this);
  if (size > std::numeric_limits<unsigned>::max() || lcm_.publish(channel, data, static_cast<unsigned>(size)) != 0)
    ++publish_errors_;
}

int Bus::handle_lcm(int timeout_ms) {
  const int r = lcm_.handleTimeout(timeout_ms);
  if (r < 0 && errno != EINTR) throw std::runtime_error("LCM handle failed on " + url_);
  return r < 0 ? 0 : r;
}

int Bus::handle(int timeout_ms) {
  const bool any_queued = std::any_of(subs_.begin(), subs_.end(), [](const auto& s) { return s->queue_capacity() > 0; });
  if (!any_queued) return handle_lcm(timeout_ms);
  const auto waiting = [&] {
    return std::any_of(subs_.begin(), subs_.end(), [](const auto& s) { return s->queued() > 0; });
  };
  // Everything LCM holds now (each message is handled or queued at once), waiting for one
  // message only when nothing is queued. Bounded: a publisher faster than the decoder must
  // not keep the queued handlers from running.
  int handled = handle_lcm(waiting() ? 0 : timeout_ms);
  for (int i = 0, n = handled; n > 0 && i < 10 * kLcmSpill; ++i) handled += n = handle_lcm(0);
  // One queued message, taking the subscriptions in turn.
  for (size_t k = 0; k < subs_.size(); ++k) {
    next_queued_ = (next_queued_ + 1) % subs_.size();
    if (subs_[next_queued_]->deliver_one()) return handled + 1;
  }
  return handled;
}

}  // namespace aerie::bus
