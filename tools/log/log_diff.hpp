#pragma once
// `aerie-log diff A B [--channels C1,C2,...]`: two logs compared channel by channel (e.g. the
// output of a replay against a reference run). Messages are paired by their order within the
// channel — the i-th message of a channel in A with the i-th in B, whatever their times — and
// compared byte for byte (payload only: the logger's receive times are not compared); where the
// payload is a catalogue type, the pair's numeric fields are compared too (message_fields.hpp)
// for the largest absolute difference and the field that has it.
#include <cstdint>
#include <ostream>
#include <string>
#include <vector>

namespace aerie::logtools {

struct ChannelDiff {
  std::string channel;
  std::string type;           // as info names it; "A-type | B-type" when the logs disagree
  int64_t count_a = 0, count_b = 0;
  int64_t identical = 0;      // pairs equal byte for byte (of min(count_a, count_b) pairs)
  double max_abs = 0;         // largest numeric field difference over the pairs
  std::string field;          // its field path ("position[0]"); "" when no numeric field differs
  int64_t at = -1;            // the pair (message index within the channel) where it is
  std::string note;           // the first difference no number shows: "message 3: levels: 2 vs 3 elements"

  bool same() const { return count_a == count_b && identical == count_a; }
};

struct LogDiff {
  std::string path_a, path_b;
  std::vector<ChannelDiff> channels;  // sorted by name

  bool same() const;  // every compared channel: same counts, every pair identical
};

// `channels` empty: the union of the channels of both logs. Throws std::runtime_error naming the
// file when a log cannot be opened or is damaged (truncated, bad sync word ...) and
// std::invalid_argument when a requested channel is in neither log.
LogDiff diff_logs(const std::string& path_a, const std::string& path_b, const std::vector<std::string>& channels = {});

void print_diff(const LogDiff& d, std::ostream& out);

}  // namespace aerie::logtools
