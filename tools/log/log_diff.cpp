#include "tools/log/log_diff.hpp"

#include <algorithm>
#include <cstdio>
#include <deque>
#include <limits>
#include <map>
#include <optional>
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

// The message's own frame number or time (tools/log/type_registry: the `seq`/`utime` fields of
// lcmtypes/, image_t's metadata "seq"); nullopt for an unknown type, an undecodable payload or a
// type without that field. `known` (optional): the payload decoded as a catalogue type, or the
// type is unknown (either way the answer holds for the channel's type).
std::optional<int64_t> key_of(const std::vector<uint8_t>& data, PairBy by, bool* known = nullptr) {
  const TypeInfo* t = find_type(fingerprint_of(data.data(), data.size()));
  if (known) *known = t == nullptr;
  if (!t || by == PairBy::Order) return std::nullopt;
  const Stamp s = t->decode(data.data(), data.size());
  if (!s.decoded) return std::nullopt;
  if (known) *known = true;
  return by == PairBy::Seq ? s.seq : s.utime;
}

struct ChannelScan {
  int64_t count = 0;
  std::string type;  // of the first message
  bool key_checked = false, has_key = false;  // by the first message that decodes
};

// First pass over one log: messages and type per channel, and whether the channel's messages
// carry the pairing key; refuses a damaged log.
std::map<std::string, ChannelScan> scan(const std::string& path, PairBy by) {
  logio::Reader reader(path);
  std::map<std::string, ChannelScan> channels;
  logio::Event ev;
  while (reader.next(ev)) {
    auto& c = channels[ev.channel];
    if (c.count++ == 0) c.type = payload_type(ev.data, ev.channel);
    if (by != PairBy::Order && !c.key_checked) c.has_key = key_of(ev.data, by, &c.key_checked).has_value();
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

// The messages of one channel paired by order or by key. A message waits (in memory) until its
// counterpart in the other log is read; the logs are read in step by time so that few wait.
struct Pairing {
  ChannelDiff* diff = nullptr;
  PairBy by = PairBy::Order;  // Seq/Utime: the channel's messages carry the key
  // Pairs by order: min(count_a, count_b) for a channel paired by order (messages beyond have no
  // counterpart and are only counted); no limit for the unkeyed messages of a keyed channel.
  int64_t pairs = 0;
  int64_t seen[2] = {0, 0};
  std::deque<std::vector<uint8_t>> waiting[2];
  // By key: (key, occurrence of that key in its log) -> payload.
  std::map<std::pair<int64_t, int64_t>, std::vector<uint8_t>> keyed[2];
  std::map<int64_t, int64_t> occurrences[2];
};

void compare_pair(ChannelDiff& d, int64_t i, const char* what_i, const std::vector<uint8_t>& a,
                  const std::vector<uint8_t>& b) {
  ++d.matched;
  if (a == b) {
    ++d.identical;
    return;
  }
  const FieldDifference f = compare_fields(a.data(), a.size(), b.data(), b.size());
  if (f.max_abs > d.max_abs) {
    d.max_abs = f.max_abs;
    d.field = f.field;
    d.at = i;
    d.at_what = what_i;
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
  if (!what.empty()) d.note = std::string(what_i) + " " + std::to_string(i) + ": " + what;
}

void take(Pairing& p, int side, std::vector<uint8_t>&& data) {
  if (p.by != PairBy::Order) {
    if (const auto key = key_of(data, p.by)) {
      const std::pair<int64_t, int64_t> id{*key, p.occurrences[side][*key]++};
      auto& theirs = p.keyed[1 - side];
      const auto it = theirs.find(id);
      if (it == theirs.end()) {
        p.keyed[side].emplace(id, std::move(data));
        return;
      }
      compare_pair(*p.diff, *key, to_string(p.by), side == 0 ? data : it->second, side == 0 ? it->second : data);
      theirs.erase(it);
      return;
    }
  }
  const int64_t i = p.seen[side]++;
  if (i >= p.pairs) return;
  auto& theirs = p.waiting[1 - side];
  if (theirs.empty()) {
    p.waiting[side].push_back(std::move(data));
    return;
  }
  compare_pair(*p.diff, i, p.by == PairBy::Order ? "message" : "unkeyed message", side == 0 ? data : theirs.front(),
               side == 0 ? theirs.front() : data);
  theirs.pop_front();
}

}  // namespace

PairBy pair_by_from_string(const std::string& name) {
  if (name == "order") return PairBy::Order;
  if (name == "seq") return PairBy::Seq;
  if (name == "utime") return PairBy::Utime;
  throw std::invalid_argument("--pair '" + name + "': expected order, seq or utime");
}

const char* to_string(PairBy p) {
  switch (p) {
    case PairBy::Order: return "order";
    case PairBy::Seq: return "seq";
    case PairBy::Utime: return "utime";
  }
  return "?";
}

bool LogDiff::same() const {
  return std::all_of(channels.begin(), channels.end(), [](const ChannelDiff& c) { return c.same(); });
}

LogDiff diff_logs(const std::string& path_a, const std::string& path_b, const std::vector<std::string>& channels,
                  PairBy pair_by) {
  const auto scan_a = scan(path_a, pair_by), scan_b = scan(path_b, pair_by);
  std::set<std::string> names(channels.begin(), channels.end());
  if (names.empty()) {
    for (const auto& [name, c] : scan_a) names.insert(name);
    for (const auto& [name, c] : scan_b) names.insert(name);
  }
  LogDiff out{path_a, path_b, pair_by, {}};
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
    const bool keyed = pair_by != PairBy::Order && (a == scan_a.end() || a->second.has_key) &&
                       (b == scan_b.end() || b->second.has_key);
    d.paired_by = keyed ? pair_by : PairBy::Order;
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
    p.by = d.paired_by;
    p.pairs = p.by == PairBy::Order ? std::min(d.count_a, d.count_b) : std::numeric_limits<int64_t>::max();
  }
  Stream streams[2] = {Stream(path_a), Stream(path_b)};
  while (streams[0].more() || streams[1].more()) {
    const int side = !streams[1].more() || (streams[0].more() && streams[0].time() <= streams[1].time()) ? 0 : 1;
    logio::Event& ev = streams[side].event();
    if (const auto it = pairing.find(ev.channel); it != pairing.end()) take(it->second, side, std::move(ev.data));
    streams[side].advance();
  }
  for (auto& d : out.channels) {
    d.missing_b = d.count_a - d.matched;
    d.missing_a = d.count_b - d.matched;
  }
  return out;
}

void print_diff(const LogDiff& d, std::ostream& out) {
  out << "A: " << d.path_a << "\nB: " << d.path_b << "\n";
  const bool by_key = d.pair_by != PairBy::Order;
  char line[640];
  if (by_key)
    std::snprintf(line, sizeof line, "\n%-18s %-24s %-6s %8s %8s %8s %9s %9s %9s %9s  %s\n", "channel", "type",
                  "paired", "count A", "count B", "matched", "missing A", "missing B", "identical", "differing",
                  "largest difference (field, value, frame)");
  else
    std::snprintf(line, sizeof line, "\n%-18s %-24s %8s %8s %10s  %s\n", "channel", "type", "count A", "count B",
                  "identical", "largest difference (field, value, message)");
  out << line;
  std::vector<std::string> differing;
  for (const auto& c : d.channels) {
    std::string largest = "-";
    if (!c.field.empty()) {
      char v[64];
      std::snprintf(v, sizeof v, "%.6g", c.max_abs);
      largest = c.field + " " + v + " (" + c.at_what + " " + std::to_string(c.at) + ")";
    }
    if (by_key)
      std::snprintf(line, sizeof line, "%-18s %-24s %-6s %8lld %8lld %8lld %9lld %9lld %9lld %9lld  %s\n",
                    c.channel.c_str(), c.type.c_str(), to_string(c.paired_by), static_cast<long long>(c.count_a),
                    static_cast<long long>(c.count_b), static_cast<long long>(c.matched),
                    static_cast<long long>(c.missing_a), static_cast<long long>(c.missing_b),
                    static_cast<long long>(c.identical), static_cast<long long>(c.differing()), largest.c_str());
    else
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
