#include "tools/log/log_info.hpp"

#include <algorithm>
#include <cstdio>
#include <ctime>
#include <map>
#include <optional>

#include "tools/log/type_registry.hpp"

namespace aerie::logtools {
namespace {

std::string hex64(int64_t v) {
  char buf[32];
  std::snprintf(buf, sizeof buf, "0x%016llx", static_cast<unsigned long long>(v));
  return buf;
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

struct Accumulator {
  ChannelSummary s;
  std::vector<std::string> types;
  std::optional<int64_t> last_seq;
  int64_t undecodable_since_seq = 0;  // corrupt messages since the last good seq
};

}  // namespace

int64_t LogSummary::dropped() const {
  int64_t n = 0;
  for (const auto& c : channels) n += c.seq_gaps;
  return n;
}

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
    if (last_event_number && ev.event_number > *last_event_number + 1)
      out.event_number_gaps += ev.event_number - *last_event_number - 1;
    last_event_number = ev.event_number;

    auto& a = acc[ev.channel];
    auto& c = a.s;
    if (c.count == 0) {
      c.channel = ev.channel;
      c.first_utime = ev.utime;
    } else {
      c.max_gap_s = std::max(c.max_gap_s, (ev.utime - c.last_utime) * 1e-6);
    }
    c.last_utime = ev.utime;
    ++c.count;
    c.bytes += ev.data.size();

    const int64_t fp = fingerprint_of(ev.data.data(), ev.data.size());
    const TypeInfo* type = find_type(fp);
    const std::string type_name = type ? type->name : "unknown (fingerprint " + hex64(fp) + ")";
    if (std::find(a.types.begin(), a.types.end(), type_name) == a.types.end()) a.types.push_back(type_name);
    if (!type) continue;
    Stamp st;
    try {
      st = type->decode(ev.data.data(), ev.data.size());
    } catch (const std::exception& e) {  // a decoder that throws: the payload is corrupt, the log goes on
      st = Stamp{};
      out.notes.push_back(path + ": event " + std::to_string(ev.event_number) + " on " + ev.channel + " (" +
                          type_name + "): " + e.what());
    }
    if (!st.decoded) {
      ++c.undecodable;
      ++a.undecodable_since_seq;
      continue;
    }
    if (!st.seq) continue;
    c.has_seq = true;
    if (a.last_seq) {
      // A missing seq is a dropped message unless a corrupt message took its place.
      const int64_t missing = *st.seq - *a.last_seq - 1;
      if (missing > 0) c.seq_gaps += std::max<int64_t>(0, missing - a.undecodable_since_seq);
      if (*st.seq <= *a.last_seq) ++c.seq_restarts;
    }
    a.last_seq = st.seq;
    a.undecodable_since_seq = 0;
  }
  out.damage = reader.damage();
  out.duration_s = out.events ? (out.last_utime - out.first_utime) * 1e-6 : 0.0;
  for (auto& [name, a] : acc) {
    auto& c = a.s;
    c.type = a.types.size() == 1 ? a.types[0] : "mixed:";
    if (a.types.size() > 1)
      for (const auto& t : a.types) c.type += " " + t;
    if (c.count > 1 && c.last_utime > c.first_utime)
      c.rate_hz = static_cast<double>(c.count - 1) / ((c.last_utime - c.first_utime) * 1e-6);
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
  std::snprintf(line, sizeof line, "\n%-18s %-24s %8s %9s %10s %8s %11s %9s\n", "channel", "type", "count", "rate Hz",
                "max gap s", "dropped", "MB", "corrupt");
  out << line;
  for (const auto& c : s.channels) {
    std::snprintf(line, sizeof line, "%-18s %-24s %8lld %9.2f %10.3f %8s %11.2f %9lld\n", c.channel.c_str(),
                  c.type.c_str(), static_cast<long long>(c.count), c.rate_hz, c.max_gap_s,
                  c.has_seq ? std::to_string(c.seq_gaps).c_str() : "-", c.bytes / 1e6,
                  static_cast<long long>(c.undecodable));
    out << line;
  }
  out << "\ndropped messages (sequence gaps): " << s.dropped();
  if (s.event_number_gaps) out << "; events missing from the logger's numbering: " << s.event_number_gaps;
  out << "\n";
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
      << ",\n  \"dropped\": " << s.dropped() << ",\n  \"event_number_gaps\": " << s.event_number_gaps
      << ",\n  \"channels\": [";
  for (size_t i = 0; i < s.channels.size(); ++i) {
    const auto& c = s.channels[i];
    out << (i ? "," : "") << "\n    {\"channel\": \"" << json_escape(c.channel) << "\", \"type\": \""
        << json_escape(c.type) << "\", \"count\": " << c.count << ", \"bytes\": " << c.bytes
        << ", \"first_utime\": " << c.first_utime << ", \"last_utime\": " << c.last_utime
        << ", \"rate_hz\": " << c.rate_hz << ", \"max_gap_s\": " << c.max_gap_s
        << ", \"has_seq\": " << (c.has_seq ? "true" : "false") << ", \"seq_gaps\": " << c.seq_gaps
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
