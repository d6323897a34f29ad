#pragma once
// `aerie-log info`: what is in an LCM log — per channel the message type (named by
// fingerprint), count, rate, largest time gap and messages missing by sequence
// number (dropped somewhere between publisher and logger), plus any damage.
#include <cstdint>
#include <ostream>
#include <string>
#include <vector>

#include "common/logio/event_log.hpp"

namespace aerie::logtools {

struct ChannelSummary {
  std::string channel;
  std::string type;         // "aerie.image_t", "unknown (fingerprint 0x...)" or "mixed: a, b"
  int64_t count = 0;
  uint64_t bytes = 0;
  int64_t first_utime = 0;  // logger receive time of the first/last message
  int64_t last_utime = 0;
  double rate_hz = 0;       // (count - 1) / (last - first)
  double max_gap_s = 0;     // largest interval between consecutive messages
  bool has_seq = false;     // the type carries a sequence number
  int64_t seq_gaps = 0;     // messages missing according to seq: dropped
  int64_t seq_restarts = 0; // seq went backwards or repeated (publisher restarted)
  int64_t undecodable = 0;  // payloads that did not decode as their type
};

struct LogSummary {
  std::string path;
  uint64_t file_size = 0;
  int64_t events = 0;
  int64_t first_utime = 0, last_utime = 0;
  double duration_s = 0;
  int64_t event_number_gaps = 0;  // events missing by the logger's own numbering
  std::vector<ChannelSummary> channels;  // sorted by name
  std::vector<logio::Damage> damage;
  std::vector<std::string> notes;  // payloads whose decoder threw: file, event number, channel, why

  int64_t dropped() const;  // sum of seq_gaps
};

// Throws std::runtime_error if the file cannot be opened; damage is reported, not thrown.
LogSummary summarize(const std::string& path, bool resync = false);
void print_summary(const LogSummary& s, std::ostream& out);
void print_summary_json(const LogSummary& s, std::ostream& out);

}  // namespace aerie::logtools
