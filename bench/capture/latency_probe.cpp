// Receives camera messages in another process and measures the LCM transport latency:
// receive time (LCM's, when the last fragment arrived) minus the message utime, which
// aerie-capture --stamp wall sets to the wall clock just before it builds and publishes
// the frame. Both ends run on the same host (same clock). Writes one CSV row per
// message and prints a JSON summary (median, p99, max per channel; sequence gaps).
#include <aerie/image_t.hpp>
#include <aerie/stereo_image_t.hpp>

#include <algorithm>
#include <cstdio>
#include <fstream>
#include <map>
#include <vector>

#include "common/bus/bus.hpp"
#include "common/bus/node.hpp"
#include "common/util/cli.hpp"
#include "common/util/time.hpp"

int main(int argc, char** argv) {
  CLI::App app{"LCM loopback latency of camera messages (receive time - utime)", "aerie-bench-capture-latency"};
  aerie::util::CommonOptions common;
  aerie::util::add_common_options(app, common, false);
  std::string out = "latency.csv";
  double duration_s = 30;
  int64_t count = 0;
  app.add_option("--out", out, "CSV file: channel,seq,utime,recv_utime,latency_ms");
  app.add_option("--duration", duration_s, "Stop this many seconds after the first message");
  app.add_option("--count", count, "Stop after this many CAM_STEREO messages (0: use --duration)");
  CLI11_PARSE(app, argc, argv);
  aerie::util::init_logging("latency", common.log_level);

  aerie::bus::Bus bus(common.lcm_url);
  struct Sample {
    std::string channel;
    int64_t seq, utime, recv;
  };
  std::vector<Sample> samples;
  samples.reserve(100000);
  int64_t stereo_count = 0, first_recv = 0;
  bus.subscribe<aerie::stereo_image_t>("CAM_STEREO", [&](const aerie::stereo_image_t& m, const aerie::bus::ReceiveInfo& r) {
    samples.push_back({"CAM_STEREO", m.seq, m.utime, r.recv_utime});
    ++stereo_count;
  }, 1000);
  bus.subscribe<aerie::image_t>("CAM_LEFT", [&](const aerie::image_t& m, const aerie::bus::ReceiveInfo& r) {
    samples.push_back({"CAM_LEFT", -1, m.utime, r.recv_utime});
  }, 1000);
  aerie::bus::install_stop_handlers();
  while (!aerie::bus::stop_requested()) {
    bus.handle(100);
    if (!samples.empty() && first_recv == 0) first_recv = samples.front().recv;
    if (count > 0 && stereo_count >= count) break;
    if (count == 0 && first_recv && aerie::util::wall_utime() - first_recv > duration_s * 1e6) break;
  }

  std::ofstream csv(out);
  csv << "channel,seq,utime,recv_utime,latency_ms\n";
  std::map<std::string, std::vector<double>> lat;
  for (const auto& s : samples) {
    const double ms = (s.recv - s.utime) / 1000.0;
    csv << s.channel << "," << s.seq << "," << s.utime << "," << s.recv << "," << ms << "\n";
    lat[s.channel].push_back(ms);
  }
  int64_t gaps = 0;
  for (const auto& sub : bus.subscriptions())
    if (sub->channel() == "CAM_STEREO") gaps = sub->counters().sequence_gaps;
  std::printf("{\"messages\": %zu, \"stereo_sequence_gaps\": %lld", samples.size(), static_cast<long long>(gaps));
  for (auto& [ch, v] : lat) {
    std::sort(v.begin(), v.end());
    auto q = [&](double p) { return v[std::min(v.size() - 1, static_cast<size_t>(p * (v.size() - 1) + 0.5))]; };
    std::printf(", \"%s\": {\"n\": %zu, \"median_ms\": %.3f, \"p99_ms\": %.3f, \"max_ms\": %.3f}", ch.c_str(), v.size(),
                q(0.5), q(0.99), v.back());
  }
  std::printf("}\n");
  return 0;
}
