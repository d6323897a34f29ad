#include "tools/latency/latency.hpp"

#include <aerie/process_status_t.hpp>

#include <cmath>
#include <cstdio>
#include <sstream>

#include "common/bus/bus.hpp"
#include "common/bus/wire.hpp"
#include "tools/log/type_registry.hpp"

namespace aerie::latency {
namespace {

std::string json_string(const std::string& s) {
  std::string out = "\"";
  for (char c : s) {
    if (c == '"' || c == '\\') out += '\\';
    out += c;
  }
  return out + "\"";
}

std::string json_summary(const Summary& s) {
  char b[256];
  std::snprintf(b, sizeof b,
                "{\"count\": %lld, \"min\": %.3f, \"mean\": %.3f, \"median\": %.3f, \"p90\": %.3f, \"p99\": %.3f, "
                "\"max\": %.3f}",
                static_cast<long long>(s.count), s.min, s.mean, s.median, s.p90, s.p99, s.max);
  return b;
}

std::string csv_row(const std::string& kind, const std::string& name, const std::string& type, const Summary& s,
                    int64_t unstamped = 0, int64_t other_clock = 0, int64_t negative = 0) {
  char b[512];
  std::snprintf(b, sizeof b, "%s,%s,%s,%lld,%.3f,%.3f,%.3f,%.3f,%.3f,%.3f,%lld,%lld,%lld\n", kind.c_str(), name.c_str(),
                type.c_str(), static_cast<long long>(s.count), s.min, s.mean, s.median, s.p90, s.p99, s.max,
                static_cast<long long>(unstamped), static_cast<long long>(other_clock),
                static_cast<long long>(negative));
  return b;
}

}  // namespace

LatencyAnalysis::LatencyAnalysis(Options options)
    : options_(std::move(options)), channel_re_(options_.channels, std::regex::extended) {}

void LatencyAnalysis::add(const std::string& channel, int64_t log_utime, const uint8_t* data, size_t size) {
  ++events_;
  const int64_t fp = logtools::fingerprint_of(data, size);
  // Per hop, from the nodes' heartbeats (whatever the channel filter).
  if (channel.rfind("STATUS_", 0) == 0 && fp == aerie::process_status_t::getHash()) {
    aerie::process_status_t st;
    if (bus::decode_bounded(data, size, st) && st.last_source_utime > 0 && st.last_receive_utime > 0 &&
        st.last_publish_utime > 0) {
      HopAcc& h = hops_[st.node.empty() ? channel.substr(7) : st.node];
      // A heartbeat of an idle node repeats its last hop: count each hop once.
      if (st.last_source_utime != h.last_source || st.last_receive_utime != h.last_receive ||
          st.last_publish_utime != h.last_publish) {
        // The source's time on the node's clock: its utime live, its frame's first arrival
        // in the log when it is stamped by another clock (source_clock.hpp).
        std::optional<int64_t> source = st.last_source_utime;
        if (!on_receive_clock(st.last_source_utime, st.last_receive_utime)) {
          h.source_clock = true;
          const auto* first = arrivals_.find(st.last_source_utime);
          source = first ? std::optional(first->receive_utime) : std::nullopt;
        }
        if (source) {
          h.input.push_back(static_cast<double>(st.last_receive_utime - *source) / 1000.0);
          h.age.push_back(static_cast<double>(st.last_publish_utime - *source) / 1000.0);
        }
        h.processing.push_back(static_cast<double>(st.last_publish_utime - st.last_receive_utime) / 1000.0);
        h.last_source = st.last_source_utime;
        h.last_receive = st.last_receive_utime;
        h.last_publish = st.last_publish_utime;
      }
    }
  }
  const logtools::TypeInfo* type = logtools::find_type(fp);
  const auto utime = bus::peek_utime(data, size);
  const bool stamped = (type || options_.unknown_types) && utime && *utime > 0;
  // Every frame's first arrival, whatever the channel filter: the reference of the channels
  // stamped by another clock.
  // (Heartbeats are stamped when sent, not by a frame: never a frame's arrival.)
  std::optional<Measured> m;
  if (stamped && channel.rfind("STATUS_", 0) != 0)
    m = measure(arrivals_, channel, *utime, log_utime);
  else if (stamped && on_receive_clock(*utime, log_utime))
    m = Measured{static_cast<double>(log_utime - *utime) / 1000.0, false, ""};
  auto [it, fresh] = matches_.try_emplace(channel, false);
  if (fresh) it->second = std::regex_match(channel, channel_re_);
  if (!it->second) return;
  Acc& a = channels_[channel];
  ++a.messages;
  if (type) a.type = type->name;
  if (!stamped) {
    ++a.unstamped;
    return;
  }
  if (!on_receive_clock(*utime, log_utime)) ++a.other_clock;
  if (!m) {
    ++a.references;
    return;
  }
  if (m->source_clock) a.reference = m->reference;
  if (m->ms < 0) ++a.negative;
  a.ms.push_back(m->ms);
}

std::vector<ChannelLatency> LatencyAnalysis::channels() const {
  std::vector<ChannelLatency> out;
  for (const auto& [name, a] : channels_) {
    ChannelLatency c;
    c.channel = name;
    c.type = a.type;
    c.latency_ms = summarize(a.ms);
    c.messages = a.messages;
    c.unstamped = a.unstamped;
    c.other_clock = a.other_clock;
    c.references = a.references;
    c.reference = a.reference;
    c.negative = a.negative;
    out.push_back(std::move(c));
  }
  return out;
}

std::vector<HopLatency> LatencyAnalysis::hops() const {
  std::vector<HopLatency> out;
  for (const auto& [node, h] : hops_)
    out.push_back({node, summarize(h.input), summarize(h.processing), summarize(h.age), h.source_clock});
  return out;
}

std::string format_table(const std::vector<ChannelLatency>& channels, const std::vector<HopLatency>& hops) {
  std::ostringstream os;
  char b[512];
  os << "End-to-end latency per channel: log receive time - message utime (ms); stamps more than 1 h off\n"
        "the log's clock (recorded data): log receive time - that frame's first arrival in the log\n";
  std::snprintf(b, sizeof b, "%-22s %-28s %8s %9s %9s %9s %9s  %s\n", "CHANNEL", "TYPE", "N", "MEDIAN", "P90", "P99",
                "MAX", "NOTES");
  os << b;
  for (const auto& c : channels) {
    std::string notes;
    if (c.unstamped) notes += std::to_string(c.unstamped) + " without utime; ";
    if (c.other_clock) {
      notes += std::to_string(c.other_clock) + " stamped by another clock (dataset time?): ";
      notes += c.reference.empty() ? "first arrivals, no latency; "
                                   : "latency from the frame's first arrival on " + c.reference + "; ";
    }
    if (c.negative) notes += std::to_string(c.negative) + " negative: clocks differ; ";
    const auto& s = c.latency_ms;
    if (s.count > 0)
      std::snprintf(b, sizeof b, "%-22s %-28s %8lld %9.2f %9.2f %9.2f %9.2f  %s\n", c.channel.c_str(),
                    c.type.empty() ? "?" : c.type.c_str(), static_cast<long long>(s.count), s.median, s.p90, s.p99,
                    s.max, notes.c_str());
    else
      std::snprintf(b, sizeof b, "%-22s %-28s %8d %9s %9s %9s %9s  %s\n", c.channel.c_str(),
                    c.type.empty() ? "?" : c.type.c_str(), 0, "-", "-", "-", "-", notes.c_str());
    os << b;
  }
  if (!hops.empty()) {
    os << "\nPer hop, from the nodes' STATUS_* heartbeats (ms): input = receive - source utime,\n"
          "processing = publish - receive, age = publish - source utime (a source on another clock: its\n"
          "frame's first arrival in the log instead of its utime; marked *)\n";
    std::snprintf(b, sizeof b, "%-16s %6s  %-26s  %-26s  %-26s\n", "NODE", "N", "INPUT median/p90/max",
                  "PROCESSING median/p90/max", "AGE median/p90/max");
    os << b;
    auto three = [](const Summary& s) {
      char t[64];
      std::snprintf(t, sizeof t, "%8.2f %8.2f %8.2f", s.median, s.p90, s.max);
      return std::string(t);
    };
    for (const auto& h : hops) {
      std::snprintf(b, sizeof b, "%-16s %6lld  %-26s  %-26s  %-26s\n", (h.node + (h.source_clock ? " *" : "")).c_str(),
                    static_cast<long long>(h.input_ms.count), three(h.input_ms).c_str(),
                    three(h.processing_ms).c_str(), three(h.age_ms).c_str());
      os << b;
    }
  }
  return os.str();
}

std::string to_csv(const std::vector<ChannelLatency>& channels, const std::vector<HopLatency>& hops) {
  std::string out = "kind,name,type,count,min_ms,mean_ms,median_ms,p90_ms,p99_ms,max_ms,unstamped,other_clock,negative\n";
  for (const auto& c : channels)
    out += csv_row("channel", c.channel, c.type, c.latency_ms, c.unstamped, c.other_clock, c.negative);
  for (const auto& h : hops) {
    out += csv_row("hop_input", h.node, "", h.input_ms);
    out += csv_row("hop_processing", h.node, "", h.processing_ms);
    out += csv_row("hop_age", h.node, "", h.age_ms);
  }
  return out;
}

std::string to_json(const std::vector<ChannelLatency>& channels, const std::vector<HopLatency>& hops) {
  std::ostringstream os;
  os << "{\n  \"channels\": [";
  for (size_t i = 0; i < channels.size(); ++i) {
    const auto& c = channels[i];
    os << (i ? "," : "") << "\n    {\"channel\": " << json_string(c.channel) << ", \"type\": " << json_string(c.type)
       << ", \"messages\": " << c.messages << ", \"unstamped\": " << c.unstamped
       << ", \"other_clock\": " << c.other_clock << ", \"references\": " << c.references
       << ", \"reference\": " << json_string(c.reference) << ", \"negative\": " << c.negative
       << ", \"latency_ms\": " << json_summary(c.latency_ms) << "}";
  }
  os << "\n  ],\n  \"hops\": [";
  for (size_t i = 0; i < hops.size(); ++i) {
    const auto& h = hops[i];
    os << (i ? "," : "") << "\n    {\"node\": " << json_string(h.node) << ", \"input_ms\": " << json_summary(h.input_ms)
       << ", \"processing_ms\": " << json_summary(h.processing_ms) << ", \"age_ms\": " << json_summary(h.age_ms)
       << ", \"source_clock\": " << (h.source_clock ? "true" : "false") << "}";
  }
  os << "\n  ]\n}\n";
  return os.str();
}

}  // namespace aerie::latency
