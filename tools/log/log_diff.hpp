#pragma once
// `aerie-log diff A B [--channels C1,C2,...]`: two logs compared channel by channel (e.g. the
// output of a replay against a reference run). Messages are paired by their order within the
// channel — the i-th message of a channel in A with the i-th in B, whatever their times — and
// compared byte for byte (payload only: the logger's receive times are not compared); where the
// payload is a catalogue type, the pair's numeric fields are compared too (message_fields.hpp)
// for the largest absolute difference and the field that has it.
// With PairBy::Seq or PairBy::Utime the messages are paired by their own frame number (the `seq`
// field, or image_t's metadata "seq") or `utime` instead (the k-th message with a key in A with
// the k-th with that key in B), so that a frame missing from one log is counted as missing, not
// as a shift of every pair after it; a channel whose type has no such field is paired by order,
// and messages without the key (undecodable) are paired by order among themselves.
#include <cstdint>
#include <ostream>
#include <string>
#include <vector>

namespace aerie::logtools {

enum class PairBy { Order, Seq, Utime };
// "order", "seq", "utime"; throws std::invalid_argument naming the value otherwise.
PairBy pair_by_from_string(const std::string& name);
const char* to_string(PairBy p);

struct ChannelDiff {
  std::string channel;
  std::string type;           // as info names it; "A-type | B-type" when the logs disagree
  int64_t count_a = 0, count_b = 0;
  int64_t identical = 0;      // pairs equal byte for byte (of min(count_a, count_b) pairs)
  double max_abs = 0;         // largest numeric field difference over the pairs
  std::string field;          // its field path ("position[0]"); "" when no numeric field differs
  int64_t at = -1;            // the pair where it is: its message index within the channel, or its key
  std::string at_what = "message";  // what `at` counts: "message", "seq", "utime"
  std::string note;           // the first difference no number shows: "message 3: levels: 2 vs 3 elements"
  PairBy paired_by = PairBy::Order;  // Order also when the channel's type has no key field
  int64_t matched = 0;        // pairs compared
  int64_t missing_a = 0;      // messages of B with no counterpart in A
  int64_t missing_b = 0;      // messages of A with no counterpart in B
  int64_t differing() const { return matched - identical; }

  bool same() const { return count_a == count_b && identical == count_a && missing_a == 0 && missing_b == 0; }
};

struct LogDiff {
  std::string path_a, path_b;
  PairBy pair_by = PairBy::Order;
  std::vector<ChannelDiff> channels;  // sorted by name

  bool same() const;  // every compared channel: same counts, every pair identical
};

// `channels` empty: the union of the channels of both logs. Throws std::runtime_error naming the
// file when a log cannot be opened or is damaged (truncated, bad sync word ...) and
// std::invalid_argument when a requested channel is in neither log.
LogDiff diff_logs(const std::string& path_a, const std::string& path_b, const std::vector<std::string>& channels = {},
                  PairBy pair_by = PairBy::Order);

// PairBy::Order: the table of counts and identical pairs; by key: the frames matched, missing in
// A, missing in B, identical and differing per channel.
void print_diff(const LogDiff& d, std::ostream& out);

}  // namespace aerie::logtools
