#include "common/bus/status.hpp"

#include <unistd.h>

#include <algorithm>
#include <cctype>

#include "common/util/time.hpp"

namespace aerie::bus {

StatusReporter::StatusReporter(Bus& bus, std::string node, double period_s)
    : bus_(bus), node_(std::move(node)), period_us_(static_cast<int64_t>(period_s * 1e6)) {
  std::string upper = node_;
  std::transform(upper.begin(), upper.end(), upper.begin(), [](unsigned char c) {
    return c == '-' ? '_' : static_cast<char>(std::toupper(c));
  });
  channel_ = std::string("STATUS_") + upper;
  char buf[256] = {0};
  gethostname(buf, sizeof(buf) - 1);
  host_ = buf;
}

void StatusReporter::time_ms(const std::string& stage, double ms) {
  auto& t = timings_[stage];
  t.first += ms;
  t.second += 1;
}

void StatusReporter::error(const std::string& message) {
  health_ = aerie::process_status_t::ERROR;
  message_ = message;
}
void StatusReporter::warn(const std::string& message) {
  if (health_ != aerie::process_status_t::ERROR) health_ = aerie::process_status_t::WARN;
  message_ = message;
}
void StatusReporter::ok(const std::string& message) {
  health_ = aerie::process_status_t::OK;
  message_ = message;
}

void StatusReporter::mark_hop(int64_t source_utime, int64_t receive_utime, int64_t publish_utime) {
  hop_source_ = source_utime;
  hop_receive_ = receive_utime;
  hop_publish_ = publish_utime;
}

int64_t StatusReporter::counter(const std::string& name) const {
  const auto it = counters_.find(name);
  return it == counters_.end() ? 0 : it->second;
}

void StatusReporter::tick() {
  if (util::wall_utime() - last_publish_ >= period_us_) publish_now();
}

void StatusReporter::publish_now() {
  aerie::process_status_t m;
  m.utime = util::wall_utime();
  m.seq = seq_++;
  m.node = node_;
  m.host = host_;
  m.pid = static_cast<int32_t>(getpid());
  m.health = health_;
  m.message = message_;
  auto add = [&](const std::string& name, int64_t v) {
    m.counter_names.push_back(name);
    m.counter_values.push_back(v);
  };
  for (const auto& [name, v] : counters_) add(name, v);
  for (const auto& sub : bus_.subscriptions()) {
    const auto& c = sub->counters();
    add(sub->channel() + ".received", c.received);
    add(sub->channel() + ".malformed", c.malformed);
    add(sub->channel() + ".handler_errors", c.handler_errors);
    add(sub->channel() + ".sequence_gaps", c.sequence_gaps);
    if (sub->queue_capacity() > 0) {  // a queue of its own (subscribe_queued): what it discarded, what waits
      add(sub->channel() + ".queue_overflows", c.queue_overflows);
      add(sub->channel() + ".queued", static_cast<int64_t>(sub->queued()));
    }
  }
  add("publish_errors", bus_.publish_errors());
  m.ncounters = static_cast<int32_t>(m.counter_names.size());
  for (const auto& [name, t] : timings_) {
    m.timing_names.push_back(name);
    m.timing_ms.push_back(t.second ? t.first / t.second : 0.0);
  }
  m.ntimings = static_cast<int32_t>(m.timing_names.size());
  timings_.clear();
  m.last_source_utime = hop_source_;
  m.last_receive_utime = hop_receive_;
  m.last_publish_utime = hop_publish_;
  bus_.publish(channel_, m);
  last_publish_ = m.utime;
}

}  // namespace aerie::bus
