#pragma once
// The lock-step landing both door tests fly (test_door_landing, test_door_attacks): the tracker
// on the ground, the down camera's images crossing down, its results (and `up_channels`) up,
// and every message of both buses recorded.
#include <aerie/track_t.hpp>

#include <string>
#include <vector>

#include "tests/support/lockstep_bytes.hpp"
#include "loop/landing.hpp"
#include "tools/link/sim_link.hpp"

namespace aerie::door_test {

inline loop::landing::RunConfig landing_split(uint64_t seed, const std::string& up_channels = "TRACK|TARGET_POSE") {
  loop::landing::RunConfig rc = loop::landing::load_landing_run(
      util::Config::parse("tracker: amcmr-ct\nmax_time_s: 60\n", "split_landing.hpp"), seed, AERIE_SOURCE_DIR);
  link::Split split;
  split.nodes = {{"track", link::Side::kGround}};  // images down, the tracker's results up
  split.down.channels = "CAM_DOWN|GT_TRACK";
  split.down.delay_ms = 20;
  split.down.jitter_ms = 3;
  split.down.seed = 3;
  split.up.channels = up_channels;
  split.up.name = "ground->air";
  split.up.delay_ms = 20;
  split.up.seed = 4;
  rc.split = split;
  return rc;
}

struct Message {
  link::Side side;
  std::string channel;
  std::vector<uint8_t> bytes;
  bool operator==(const Message&) const = default;
};

// Every message on both buses; TRACK with its processing time (wall clock) zeroed.
inline std::vector<Message> record(loop::landing::RunConfig rc, loop::landing::RunResult& result) {
  std::vector<Message> out;
  rc.on_message = [&](link::Side side, const std::string& channel, const uint8_t* data, size_t size, int64_t) {
    out.push_back(Message{side, channel, test::comparable_bytes(channel, data, size)});
  };
  result = loop::landing::fly(rc);
  return out;
}

}  // namespace aerie::door_test
