#include "tools/latency/link_hops.hpp"

#include <cstdio>
#include <sstream>

#include "common/bus/bus.hpp"

namespace aerie::latency {

void LinkJoin::add(Log log, const std::string& channel, int64_t log_utime, const uint8_t* data, size_t size) {
  const auto u = bus::peek_utime(data, size);
  if (!u) return;
  auto [it, fresh] = seen_[channel].try_emplace(*u, -1, -1);
  int64_t& t = log == Log::kAir ? it->second.first : it->second.second;
  if (t < 0) t = log_utime;
}

std::vector<LinkHop> LinkJoin::hops() const {
  std::vector<LinkHop> out;
  for (const auto& [channel, by_utime] : seen_) {
    int64_t air_first = 0, ground_first = 0, both = 0, air = 0, ground = 0;
    for (const auto& [u, t] : by_utime) {
      air += t.first >= 0;
      ground += t.second >= 0;
      if (t.first < 0 || t.second < 0) continue;
      ++both;
      air_first += t.first < t.second;
      ground_first += t.second < t.first;
    }
    if (both == 0) continue;  // one side only: not a channel that crosses
    bool down = true;
    if (air_first != ground_first) {
      down = air_first > ground_first;
    } else if (air != ground) {
      down = air > ground;  // the receiver logs a subset
    } else if (const auto h = hints_.find(channel); h != hints_.end()) {
      down = h->second;
    }
    LinkHop h{channel, down ? "air->ground" : "ground->air", {}, down ? air : ground, 0};
    std::vector<double> ms;
    for (const auto& [u, t] : by_utime) {
      const int64_t from = down ? t.first : t.second, to = down ? t.second : t.first;
      if (from < 0 || to < 0) continue;
      ms.push_back(static_cast<double>(to - from) / 1000.0);
    }
    h.delivered = static_cast<int64_t>(ms.size());
    h.latency_ms = summarize(std::move(ms));
    out.push_back(std::move(h));
  }
  return out;
}

std::string format_link_table(const std::vector<LinkHop>& hops) {
  std::ostringstream os;
  char b[256];
  os << "The link's hop: receiving side's log time - sending side's, per channel (ms)\n";
  std::snprintf(b, sizeof b, "%-22s %-12s %8s %9s %9s %9s %9s %9s\n", "CHANNEL", "DIRECTION", "SENT", "DELIVERED",
                "MEDIAN", "P90", "P99", "MAX");
  os << b;
  for (const auto& h : hops) {
    const auto& s = h.latency_ms;
    std::snprintf(b, sizeof b, "%-22s %-12s %8lld %9lld %9.2f %9.2f %9.2f %9.2f\n", h.channel.c_str(),
                  h.direction.c_str(), static_cast<long long>(h.sent), static_cast<long long>(h.delivered), s.median,
                  s.p90, s.p99, s.max);
    os << b;
  }
  return os.str();
}

}  // namespace aerie::latency
