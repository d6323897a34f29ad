#include "tools/log/log_diff.hpp"

#include <algorithm>
#include <cstdio>
#include <deque>
#include <map>
#include <set>
#include <stdexcept>

#include "common/logio/event_log.hpp"
#include "tools/log/message_fields.hpp"
#include "tools/log/type_registry.hpp"

namespace aerie::logtools {
namespace {

// A diff of part of a log would look like a difference: a damaged log is refused.
void refuse_damage(const logio::Reader& r) {
  if (r.damaged()) throw std::runtime_error(r.damage().front().message + " (aerie-log info shows what precedes it)");
}

std::string payload_type(const std::vector<uint8_t>& data, const std::string& channel) {
  const int64_t fp = fingerprint_of(data.data(), data.size());
  return type_name(find_type(fp), fp, channel);
}

struct ChannelScan {
  int64_t count = 0;
  std::string type;  // of the first message
};

// First pass over one log: messages and type per channel; refuses a damaged log.
std::map<std::string, ChannelScan> scan(const std::string& path) {
  logio::Reader reader(path);
  std::map<std::string, ChannelScan> channels;
  logio::Event ev;
  while (reader.next(ev)) {
    auto& c = channels[ev.channel];
    if (c.count++ == 0) c.type = payload_type(ev.data, ev.channel);
  }
  refuse_damage(reader);
  return channels;
}

// One log read in step with the other: the next event and its time since the log's first event.
class Stream {
 public:
  explicit Stream(const std::string& path) : reader_(path) {
    advance();
    t0_ = ev_.utime;
  }
  bool more() const { return more_; }
  int64_t time() const { return ev_.utime - t0_; }
  logio::Event& event() { return ev_; }
  void advance() {
    more_ = reader_.next(ev_);
    if (!more_) refuse_damage(reader_);
  }

 private:
  logio::Reader reader_;
  logio::Event ev_;
  bool more_ = false;
  int64_t t0_ = 0;
};

// The messages of one channel paired by order. A message waits (in memory) until its
// counterpart in the other log is read; the logs are read in step by time so that few wait.
struct Pairing {
  ChannelDiff* diff = nullptr;
  int64_t pairs = 0;  // min(count_a, count_b): messages beyond have no counterpart and are only counted
  int64_t seen[2] = {0, 0};
  std::deque<std::vector<uint8_t>> waiting[2];
};

void compare_pair(ChannelDiff& d, int64_t i, const std::vector<uint8_t>& a, const std::vector<uint8_t>& b) {
  if (a == b) {
    ++d.identical;
    return;
  }
  const FieldDifference f = compare_fields(a.data(), a.size(), b.data(), b.size());
  if (f.max_abs > d.max_abs) {
    d.max_abs = f.max_abs;
    d.field = f.field;
    d.at = i;
  }
  if (!d.note.empty()) return;
  std::string what;
  if (!f.comparable) {
    const std::string ta = payload_type(a, d.channel), tb = payload_type(b, d.channel);
    if (ta != tb) {
      what = "A has " + ta + ", B has " + tb;
    } else if (find_type(fingerprint_of(a.data(), a.size()))) {
      what = "the bytes differ; a payload does not decode as " + ta;
    } else {
      what = "the bytes differ (no catalogue type to compare by field)";
    }
  } else if (!f.shape.empty()) {
    what = f.shape;
  } else if (!f.text.empty()) {
    what = f.text + ": the strings differ";
  } else if (f.field.empty()) {
    what = "the bytes differ but every value is equal (0 and -0, or NaNs)";
  }
  if (!what.empty()) d.note = "message " + std::to_string(i) + ": " + what;
}

void take(Pairing& p, int side, std::vector<uint8_t>&& data) {
  const int64_t i = p.seen[side]++;
  if (i >= p.pairs) return;
  auto& theirs = p.waiting[1 - side];
  if (theirs.empty()) {
    p.waiting[side].push_back(std::move(data));
    return;
  }
  compare_pair(*p.diff, i, side == 0 ? data : theirs.front(), side == 0 ? theirs.front() : data);
  theirs.pop_front();
}

}  // namespace

bool LogDiff::same() const {
  return std::all_of(channels.begin(), channels.end(), [](const ChannelDiff& c) { return c.same(); });
}

LogDiff diff_logs(const std::string& path_a, const std::string& path_b, const std::vector<std::string>& channels) {
  const auto scan_a = scan(path_a), scan_b = scan(path_b);
  std::set<std::string> names(channels.begin(), channels.end());
  if (names.empty()) {
    for (const auto& [name, c] : scan_a) names.insert(name);
    for (const auto& [name, c] : scan_b) names.insert(name);
  }
  LogDiff out{path_a, path_b, {}};
  std::string missing;
  for (const auto& name : names) {
    const auto a = scan_a.find(name), b = scan_b.find(name);
    if (a == scan_a.end() && b == scan_b.end()) {
      missing += (missing.empty() ? "" : ", ") + name;
      continue;
    }
    ChannelDiff d;
    d.channel = name;
    d.count_a = a == scan_a.end() ? 0 : a->second.count;
    d.count_b = b == scan_b.end() ? 0 : b->second.count;
    const std::string ta = d.count_a ? a->second.type : "", tb = d.count_b ? b->second.type : "";
    d.type = ta.empty() || tb.empty() || ta == tb ? (ta.empty() ? tb : ta) : ta + " | " + tb;
    out.channels.push_back(std::move(d));
  }
  if (!missing.empty()) {
    std::set<std::string> all;
    for (const auto* s : {&scan_a, &scan_b})
      for (const auto& [name, c] : *s) all.insert(name);
    std::string list;
    for (const auto& n : all) list += (list.empty() ? "" : ", ") + n;
    throw std::invalid_argument("diff: no channel " + missing + " in " + path_a + " or " + path_b +
                                " (channels: " + (list.empty() ? "none" : list) + ")");
  }

  std::map<std::string, Pairing> pairing;
  for (auto& d : out.channels) {
    auto& p = pairing[d.channel];
    p.diff = &d;
    p.pairs = std::min(d.count_a, d.count_b);
  }
  Stream streams[2] = {Stream(path_a), Stream(path_b)};
  while (streams[0].more() || streams[1].more()) {
    const int side = !streams[1].more() || (streams[0].more() && streams[0].time() <= streams[1].time()) ? 0 : 1;
    logio::Event& ev = streams[side].event();
    if (const auto it = pairing.find(ev.channel); it != pairing.end()) take(it->second, side, std::move(ev.data));
    streams[side].advance();
  }
  return out;
}

void print_diff(const LogDiff& d, std::ostream& out) {
  out << "A: " << d.path_a << "\nB: " << d.path_b << "\n";
  char line[512];
  std::snprintf(line, sizeof line, "\n%-18s %-24s %8s %8s %10s  %s\n", "channel", "type", "count A", "count B",
                "identical", "largest difference (field, value, message)");
  out << line;
  std::vector<std::string> differing;
  for (const auto& c : d.channels) {
    std::string largest = "-";
    if (!c.field.empty()) {
      char v[64];
      std::snprintf(v, sizeof v, "%.6g", c.max_abs);
      largest = c.field + " " + v + " (message " + std::to_string(c.at) + ")";
    }
    std::snprintf(line, sizeof line, "%-18s %-24s %8lld %8lld %10lld  %s\n", c.channel.c_str(), c.type.c_str(),
                  static_cast<long long>(c.count_a), static_cast<long long>(c.count_b),
                  static_cast<long long>(c.identical), largest.c_str());
    out << line;
    if (!c.same()) differing.push_back(c.channel);
  }
  for (const auto& c : d.channels)
    if (!c.note.empty()) out << "note: " << c.channel << ": " << c.note << "\n";
  if (differing.empty()) {
    out << "\nsame: every message of the " << d.channels.size() << " channel(s) compared is identical\n";
    return;
  }
  out << "\ndifferent: " << differing.size() << " of " << d.channels.size() << " channel(s):";
  for (size_t i = 0; i < differing.size(); ++i) out << (i ? ", " : " ") << differing[i];
  out << "\n";
}

}  // namespace aerie::logtools
