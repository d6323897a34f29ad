#pragma once
// `aerie-log info`: what is in an LCM log — per channel the message type (named by
// fingerprint), count, rate, largest time gap and messages missing by sequence number,
// split into what the logger lost (published, never recorded) and what producers skipped
// by design (frames a node did not answer), plus any damage.
#include <cstdint>
#include <ostream>
#include <string>
#include <vector>

#include "common/logio/event_log.hpp"

namespace aerie::logtools {

struct ChannelSummary {
  std::string channel;
  std::string type;         // "aerie.image_t", "lcm self-test (string)", "unknown (fingerprint 0x...)", "mixed: a b"
  int64_t count = 0;
  uint64_t bytes = 0;
  int64_t first_utime = 0;  // logger receive time of the first/last message
  int64_t last_utime = 0;
  double rate_hz = 0;       // (count - 1) / (last - first)
  double max_gap_s = 0;     // largest interval between consecutive messages
  bool has_seq = false;     // the type carries a sequence number
  // The seq is the source camera frame's, and the producer answers only some frames by
  // design (aerie-vo: VO_POSE, VO_DEPTH): a gap is a frame without a result, not a loss.
  bool seq_follows_frames = false;
  int64_t seq_gaps = 0;     // messages missing according to seq
  int64_t frames_skipped = 0;  // frames the producer reports it skipped during the log (track_t.frames_skipped)
  int64_t seq_restarts = 0; // seq went backwards or repeated (publisher restarted)
  int64_t undecodable = 0;  // payloads that did not decode as their type

  int64_t logger_lost() const { return seq_follows_frames ? 0 : seq_gaps; }  // published, not in the log
  int64_t producer_skipped() const {  // saturating: the counts come from the log
    int64_t r;
    return __builtin_add_overflow(seq_follows_frames ? seq_gaps : 0, frames_skipped, &r) ? INT64_MAX : r;
  }
};

struct LogSummary {
  std::string path;
  uint64_t file_size = 0;
  int64_t events = 0;
  int64_t first_utime = 0, last_utime = 0;
  double duration_s = 0;
  // Events missing from the log's numbering: taken out after recording (lcm-logger numbers
  // the events as it writes them, so what it fails to receive or write leaves no gap here).
  int64_t event_number_gaps = 0;
  std::vector<ChannelSummary> channels;  // sorted by name
  std::vector<logio::Damage> damage;
  std::vector<std::string> notes;  // payloads whose decoder threw: file, event number, channel, why

  int64_t dropped() const;           // sum of seq_gaps = logger_lost() + the skips among them
  int64_t logger_lost() const;       // sum of ChannelSummary::logger_lost()
  int64_t producer_skipped() const;  // sum of ChannelSummary::producer_skipped()
};

// Throws std::runtime_error if the file cannot be opened; damage is reported, not thrown.
LogSummary summarize(const std::string& path, bool resync = false);
void print_summary(const LogSummary& s, std::ostream& out);
void print_summary_json(const LogSummary& s, std::ostream& out);

}  // namespace aerie::logtools
