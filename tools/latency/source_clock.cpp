#include "tools/latency/source_clock.hpp"

namespace aerie::latency {

const FrameArrivals::Arrival& FrameArrivals::note(int64_t utime, int64_t receive_utime, const std::string& channel) {
  auto [it, fresh] = first_.try_emplace(utime, Arrival{receive_utime, channel});
  if (fresh) {
    order_.push_back(utime);
    if (order_.size() > capacity_) {
      first_.erase(order_.front());
      order_.pop_front();
    }
  }
  return first_.at(utime);  // the eviction above never removes the newest
}

const FrameArrivals::Arrival* FrameArrivals::find(int64_t utime) const {
  const auto it = first_.find(utime);
  return it == first_.end() ? nullptr : &it->second;
}

std::optional<Measured> measure(FrameArrivals& arrivals, const std::string& channel, int64_t utime,
                                int64_t receive_utime) {
  const FrameArrivals::Arrival& first = arrivals.note(utime, receive_utime, channel);
  if (on_receive_clock(utime, receive_utime))
    return Measured{static_cast<double>(receive_utime - utime) * 1e-3, false, ""};
  if (first.receive_utime == receive_utime && first.channel == channel) return std::nullopt;  // the reference
  return Measured{static_cast<double>(receive_utime - first.receive_utime) * 1e-3, true, first.channel};
}

}  // namespace aerie::latency
