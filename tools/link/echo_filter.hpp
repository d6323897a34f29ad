#pragma once
// What a relay published on a network comes back to its own subscriptions there (multicast
// loopback): remember it briefly (5 s) and drop the echo. Shared by the emulator and the door.
#include <cstddef>
#include <cstdint>
#include <deque>
#include <functional>
#include <string>
#include <string_view>
#include <unordered_set>
#include <utility>

namespace aerie::link {

class EchoFilter {
 public:
  static uint64_t key(const std::string& channel, const uint8_t* data, size_t size) {
    const uint64_t h1 = std::hash<std::string_view>{}(std::string_view(reinterpret_cast<const char*>(data), size));
    return h1 ^ (std::hash<std::string>{}(channel) * 0x9E3779B97F4A7C15ULL);
  }
  void sent(uint64_t k, int64_t now_us) {
    keys_.insert(k);
    order_.emplace_back(now_us, k);
    while (!order_.empty() && now_us - order_.front().first > 5'000'000) {
      if (auto it = keys_.find(order_.front().second); it != keys_.end()) keys_.erase(it);
      order_.pop_front();
    }
  }
  bool is_echo(uint64_t k) {
    const auto it = keys_.find(k);
    if (it == keys_.end()) return false;
    keys_.erase(it);
    return true;
  }

 private:
  std::unordered_multiset<uint64_t> keys_;
  std::deque<std::pair<int64_t, uint64_t>> order_;
};

}  // namespace aerie::link
