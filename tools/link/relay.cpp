#include "tools/link/relay.hpp"

#include "tools/link/reencode.hpp"

namespace aerie::link {

ChannelMatcher::ChannelMatcher(const std::string& regex)
    : re_(regex.empty() ? std::regex("$^") : std::regex(regex, std::regex::extended)) {}

bool ChannelMatcher::operator()(const std::string& channel) {
  const auto it = cache_.find(channel);
  if (it != cache_.end()) return it->second;
  const bool match = std::regex_match(channel, re_);
  // Bounded: names come from the network (a sender cycling names must not grow it).
  if (cache_.size() < kMaxCached) cache_[channel] = match;
  return match;
}

Relay::Relay(DirectionConfig config) : model_(config), jpeg_(config.jpeg_channels) {}

void Relay::take(const std::string& channel, const uint8_t* data, size_t size, int64_t recv_wall_utime,
                 int64_t now_us) {
  Packet p;
  p.channel = channel;
  p.data.assign(data, data + size);
  p.recv_wall_utime = recv_wall_utime;
  if (jpeg_(channel)) {
    if (auto smaller = reencode_jpeg(p.data, model_.config().jpeg_quality)) {
      p.data = std::move(*smaller);
      ++model_.counters().reencoded;
    }
  }
  model_.offer(std::move(p), now_us);
}

}  // namespace aerie::link
