#include "tools/log/log_info.hpp"

#include <algorithm>
#include <cstdint>
#include <cstdio>
#include <ctime>
#include <functional>
#include <map>
#include <optional>

#include "tools/log/type_registry.hpp"

namespace aerie::logtools {
namespace {

// Sums and differences of values read from the log (seq, frames_skipped, event numbers,
// utimes) saturate instead of overflowing: a crafted log gives large counts, not undefined
// behaviour (fuzzing, docs/fuzz.md).
int64_t sat_add(int64_t a, int64_t b) {
  int64_t r;
  return __builtin_add_overflow(a, b, &r) ? (b > 0 ? INT64_MAX : INT64_MIN) : r;
}
int64_t sat_sub(int64_t a, int64_t b) {
  int64_t r;
  return __builtin_sub_overflow(a, b, &r) ? (b < 0 ? INT64_MAX : INT64_MIN) : r;
}

std::string format_time(int64_t utime) {
  const std::time_t t = static_cast<std::time_t>(utime / 1'000'000);
  std::tm tm{};
  gmtime_r(&t, &tm);
  char buf[64];
  std::strftime(buf, sizeof buf, "%Y-%m-%d %H:%M:%S", &tm);
  char frac[16];
  std::snprintf(frac, sizeof frac, ".%03d UTC", static_cast<int>((utime / 1000) % 1000));
  return std::string(buf) + frac;
}

std::string json_escape(const std::string& s) {
  std::string o;
  for (const char c : s) {
    if (c == '"' || c == '\\') o += '\\';
    if (static_cast<unsigned char>(c) < 0x20) {
      char buf[8];
      std::snprintf(buf, sizeof buf, "\\u%04x", c);
      o += buf;
    } else {
      o += c;
    }
  }
  return o;
}

// Result types whose seq is that of the camera frame they answer, from a producer that answers
// only some frames by design: aerie-vo publishes VO_POSE for the stereo pairs it processes (pairs
// that arrive while its queue is full, or that it refuses, get none) and VO_DEPTH for one pair in
// `depth_every`. Their seq gaps are frames without a result; every other seq counts messages.
bool seq_follows_frames(const std::string& type) { return type == "aerie.pose_t" || type == "aerie.spherical_depth_t"; }

struct Accumulator {
  ChannelSummary s;
  std::vector<std::string> types;
  std::optional<int64_t> last_seq;
  int64_t undecodable_since_seq = 0;  // corrupt messages since the last good seq
  std::optional<int64_t> last_frames_skipped;
};

template <typename Count>
int64_t sum(const std::vector<ChannelSummary>& channels, Count count) {
  int64_t n = 0;
  for (const auto& c : channels) n = sat_add(n, count(c));
  return n;
}

// "GT_POSE 1, VO_POSE 4" for the channels where count(c) > 0, or "none".
template <typename Count>
std::string per_channel(const std::vector<ChannelSummary>& channels, Count count) {
  std::string list;
  for (const auto& c : channels)
    if (const int64_t n = count(c); n > 0) list += (list.empty() ? "" : ", ") + c.channel + " " + std::to_string(n);
  return list.empty() ? "none" : list;
}

}  // namespace

int64_t LogSummary::dropped() const { return sum(channels, std::mem_fn(&ChannelSummary::seq_gaps)); }
int64_t LogSummary::logger_lost() const { return sum(channels, std::mem_fn(&ChannelSummary::logger_lost)); }
int64_t LogSummary::producer_skipped() const { return sum(channels, std::mem_fn(&ChannelSummary::producer_skipped)); }

LogSummary summarize(const std::string& path, bool resync) {
  logio::Reader reader(path, {.resync = resync});
  LogSummary out;
  out.path = path;
  out.file_size = reader.file_size();
  std::map<std::string, Accumulator> acc;
  logio::Event ev;
  std::optional<int64_t> last_event_number;
  while (reader.next(ev)) {
    if (out.events == 0) out.first_utime = ev.utime;
    out.last_utime = std::max(out.last_utime, ev.utime);
    ++out.events;
    if (last_event_number && ev.event_number > sat_add(*last_event_number, 1))
      out.event_number_gaps = sat_add(out.event_number_gaps, sat_sub(sat_sub(ev.event_number, *last_event_number), 1));
    last_event_number = ev.event_number;

    auto& a = acc[ev.channel];
    auto& c = a.s;
    if (c.count == 0) {
      c.channel = ev.channel;
      c.first_utime = ev.utime;
    } else {
      c.max_gap_s = std::max(c.max_gap_s, static_cast<double>(sat_sub(ev.utime, c.last_utime)) * 1e-6);
    }
    c.last_utime = ev.utime;
    ++c.count;
    c.bytes += ev.data.size();

    const int64_t fp = fingerprint_of(ev.data.data(), ev.data.size());
    const TypeInfo* type = find_type(fp);
    const std::string name = type_name(type, fp, ev.channel);
    if (std::find(a.types.begin(), a.types.end(), name) == a.types.end()) a.types.push_back(name);
    if (!type) continue;
    Stamp st;
    try {
      st = type->decode(ev.data.data(), ev.data.size());
    } catch (const std::exception& e) {  // a decoder that throws: the payload is corrupt, the log goes on
      st = Stamp{};
      out.notes.push_back(path + ": event " + std::to_string(ev.event_number) + " on " + ev.channel + " (" +
                          name + "): " + e.what());
    }
    if (!st.decoded) {
      ++c.undecodable;
      ++a.undecodable_since_seq;
      continue;
    }
    if (st.frames_skipped) {  // cumulative: count what it grew by during the log (from 0 after a restart)
      if (a.last_frames_skipped)
        c.frames_skipped = sat_add(c.frames_skipped, *st.frames_skipped >= *a.last_frames_skipped
                                                         ? sat_sub(*st.frames_skipped, *a.last_frames_skipped)
                                                         : *st.frames_skipped);
      a.last_frames_skipped = st.frames_skipped;
    }
    if (!st.seq) continue;
    c.has_seq = true;
    c.seq_follows_frames = seq_follows_frames(type->name);
    if (a.last_seq) {
      // A missing seq is a dropped message unless a corrupt message took its place.
      const int64_t missing = sat_sub(sat_sub(*st.seq, *a.last_seq), 1);
      if (missing > 0) c.seq_gaps = sat_add(c.seq_gaps, std::max<int64_t>(0, sat_sub(missing, a.undecodable_since_seq)));
      if (*st.seq <= *a.last_seq) ++c.seq_restarts;
    }
    a.last_seq = st.seq;
    a.undecodable_since_seq = 0;
  }
  out.damage = reader.damage();
  out.duration_s = out.events ? static_cast<double>(sat_sub(out.last_utime, out.first_utime)) * 1e-6 : 0.0;
  for (auto& [name, a] : acc) {
    auto& c = a.s;
    c.type = a.types.size() == 1 ? a.types[0] : "mixed:";
    if (a.types.size() > 1)
      for (const auto& t : a.types) c.type += " " + t;
    if (c.count > 1 && c.last_utime > c.first_utime)
      c.rate_hz = static_cast<double>(c.count - 1) / (static_cast<double>(sat_sub(c.last_utime, c.first_utime)) * 1e-6);
    out.channels.push_back(std::move(c));
  }
  return out;
}

void print_summary(const LogSummary& s, std::ostream& out) {
  char line[512];
  std::snprintf(line, sizeof line, "log:      %s\nsize:     %.1f MB, %lld events\n", s.path.c_str(),
                s.file_size / 1e6, static_cast<long long>(s.events));
  out << line;
  if (s.events) {
    out << "start:    " << format_time(s.first_utime) << "\n";
    std::snprintf(line, sizeof line, "duration: %.3f s\n", s.duration_s);
    out << line;
  }
  std::snprintf(line, sizeof line, "\n%-18s %-24s %8s %9s %10s %8s %8s %11s %9s\n", "channel", "type", "count",
                "rate Hz", "max gap s", "lost", "skipped", "MB", "corrupt");
  out << line;
  for (const auto& c : s.channels) {
    const std::string lost = c.has_seq ? std::to_string(c.logger_lost()) : "-";
    const std::string skipped = c.has_seq || c.frames_skipped ? std::to_string(c.producer_skipped()) : "-";
    std::snprintf(line, sizeof line, "%-18s %-24s %8lld %9.2f %10.3f %8s %8s %11.2f %9lld\n", c.channel.c_str(),
                  c.type.c_str(), static_cast<long long>(c.count), c.rate_hz, c.max_gap_s, lost.c_str(),
                  skipped.c_str(), c.bytes / 1e6, static_cast<long long>(c.undecodable));
    out << line;
  }
  // A sequence gap is a message the logger lost or a frame its producer skipped by design.
  const int64_t lost = s.logger_lost(), skipped = s.producer_skipped();
  out << "\ndropped messages (sequence gaps): " << s.dropped();
  if (s.dropped() != lost) out << ", of which logger lost " << lost << ", skipped by producers " << s.dropped() - lost;
  out << "\nlogger lost: " << lost;
  if (lost)
    out << " (published, never recorded: " << per_channel(s.channels, std::mem_fn(&ChannelSummary::logger_lost)) << ")";
  out << "\nskipped by producers (by design, per channel): "
      << per_channel(s.channels, std::mem_fn(&ChannelSummary::producer_skipped))
      << (skipped ? " (camera frames without a result)\n" : "\n");
  if (s.event_number_gaps)
    out << "events missing from the log's numbering: " << s.event_number_gaps << " (taken out after recording)\n";
  for (const auto& c : s.channels)
    if (c.seq_restarts) out << "note: " << c.channel << ": sequence restarted " << c.seq_restarts << " time(s)\n";
  for (const auto& n : s.notes) out << "note: " << n << "\n";
  if (s.events == 0 && s.damage.empty()) {
    out << "empty:    the log holds no events\n";
  } else if (s.damage.empty()) {
    out << "damage:   none\n";
  } else {
    for (const auto& d : s.damage) out << "DAMAGE:   " << d.message << "\n";
  }
}

void print_summary_json(const LogSummary& s, std::ostream& out) {
  out << "{\n  \"path\": \"" << json_escape(s.path) << "\",\n  \"file_size\": " << s.file_size
      << ",\n  \"events\": " << s.events << ",\n  \"first_utime\": " << s.first_utime
      << ",\n  \"last_utime\": " << s.last_utime << ",\n  \"duration_s\": " << s.duration_s
      << ",\n  \"dropped\": " << s.dropped() << ",\n  \"logger_lost\": " << s.logger_lost()
      << ",\n  \"producer_skipped\": " << s.producer_skipped() << ",\n  \"event_number_gaps\": " << s.event_number_gaps
      << ",\n  \"channels\": [";
  for (size_t i = 0; i < s.channels.size(); ++i) {
    const auto& c = s.channels[i];
    out << (i ? "," : "") << "\n    {\"channel\": \"" << json_escape(c.channel) << "\", \"type\": \""
        << json_escape(c.type) << "\", \"count\": " << c.count << ", \"bytes\": " << c.bytes
        << ", \"first_utime\": " << c.first_utime << ", \"last_utime\": " << c.last_utime
        << ", \"rate_hz\": " << c.rate_hz << ", \"max_gap_s\": " << c.max_gap_s
        << ", \"has_seq\": " << (c.has_seq ? "true" : "false") << ", \"seq_gaps\": " << c.seq_gaps
        << ", \"seq_follows_frames\": " << (c.seq_follows_frames ? "true" : "false")
        << ", \"logger_lost\": " << c.logger_lost() << ", \"producer_skipped\": " << c.producer_skipped()
        << ", \"seq_restarts\": " << c.seq_restarts << ", \"undecodable\": " << c.undecodable << "}";
  }
  out << "\n  ],\n  \"damage\": [";
  for (size_t i = 0; i < s.damage.size(); ++i) {
    const auto& d = s.damage[i];
    out << (i ? "," : "") << "\n    {\"kind\": \"" << logio::to_string(d.kind) << "\", \"offset\": " << d.offset
        << ", \"event_number\": " << d.event_number << ", \"message\": \"" << json_escape(d.message) << "\"}";
  }
  out << "\n  ]\n}\n";
}

}  // namespace aerie::logtools
