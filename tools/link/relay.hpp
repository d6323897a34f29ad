#pragma once
// One direction of the link as a relay, shared by aerie-link (live, monotonic wall time)
// and SimLink (lock-step, simulation time): a message taken from the sending network is
// re-encoded as JPEG when its channel says so, offered to the link model, and handed back
// by due() when the model delivers it. Time is the caller's.
#include <cstdint>
#include <regex>
#include <string>
#include <unordered_map>
#include <vector>

#include "tools/link/link_model.hpp"

namespace aerie::link {

// LCM channel regexes match whole names (LCM anchors them with ^...$); "" matches nothing.
class ChannelMatcher {
 public:
  explicit ChannelMatcher(const std::string& regex);
  bool operator()(const std::string& channel);

 private:
  static constexpr size_t kMaxCached = 4096;
  std::regex re_;
  std::unordered_map<std::string, bool> cache_;
};

class Relay {
 public:
  explicit Relay(DirectionConfig config);

  // A message received at now_us on the sending network (recv_wall_utime: the wall clock
  // of its reception, kept for the achieved delay).
  void take(const std::string& channel, const uint8_t* data, size_t size, int64_t recv_wall_utime, int64_t now_us);
  std::vector<Packet> due(int64_t now_us) { return model_.due(now_us); }

  LinkDirection& model() { return model_; }
  const LinkDirection& model() const { return model_; }

 private:
  LinkDirection model_;
  ChannelMatcher jpeg_;
};

}  // namespace aerie::link
