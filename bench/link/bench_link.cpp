// bench_link: aerie-link figures (docs/results/procman.md, "Link emulator").
//  * added latency at zero configured delay: probe messages at 200 Hz straight from
//    one LCM instance to another on the same network (baseline) and through the
//    link between two networks; median / p90 / p99 of both;
//  * throughput: messages/s and MB/s the link relays when flooded, per message size.
// Runs aerie-link in a network namespace it creates (root). Writes link.json /
// link.csv (and link.png with /usr/bin/python3 + matplotlib).
#include <signal.h>

#include <CLI/CLI.hpp>
#include <chrono>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <iostream>
#include <thread>

#include "common/bus/bus.hpp"
#include "procman/testbed.hpp"
#include "tools/latency/stats.hpp"
#include "tools/link/probe.hpp"

using namespace aerie;
using namespace std::chrono_literals;
namespace testbed = aerie::procman::testbed;

namespace {

const std::string kAir = "udpm://239.255.76.67:7667?ttl=0";
const std::string kGround = "udpm://239.255.76.68:7668?ttl=0";

std::string json_array(const std::vector<double>& v) {
  std::string s = "[";
  char b[32];
  for (size_t i = 0; i < v.size(); ++i) {
    std::snprintf(b, sizeof b, "%s%.4f", i ? ", " : "", v[i]);
    s += b;
  }
  return s + "]";
}

}  // namespace

int main(int argc, char** argv) {
  CLI::App app{"bench_link: aerie-link added latency at zero delay and relay throughput"};
  std::string out_dir = "bench-results/link";
  int latency_messages = 2000;
  bool realtime = false;
  app.add_option("--out", out_dir, "output folder")->capture_default_str();
  app.add_option("--latency-messages", latency_messages, "probe messages per latency run (200 Hz)")->capture_default_str();
  app.add_flag("--realtime", realtime, "run the link and the probe under SCHED_FIFO (as aerie-link --realtime-priority)");
  CLI11_PARSE(app, argc, argv);
  if (const auto why = testbed::namespaces_unavailable(); !why.empty()) {
    std::cerr << "bench_link: " << why << "\n";
    return 2;
  }
  std::filesystem::create_directories(out_dir);
  const std::string bin = std::filesystem::read_symlink("/proc/self/exe").parent_path().string();
  std::optional<testbed::RealtimePriority> rt;
  if (realtime) rt.emplace(10);

  testbed::NetNamespace ns(testbed::unique_name("bench-link"));
  const std::string cfg = out_dir + "/link.yaml";
  std::ofstream(cfg) << "air_to_ground: {channels: \"PROBE.*\", queue_bytes: 100000000}\n";
  auto argv_link = ns.exec_prefix();
  argv_link.insert(argv_link.end(), {bin + "/aerie-link", "--config", cfg, "--air-url", kAir, "--ground-url", kGround});
  if (realtime) argv_link.insert(argv_link.end(), {"--realtime-priority", "10"});
  testbed::Process link(argv_link, out_dir + "/link.log");
  std::this_thread::sleep_for(1500ms);

  testbed::EnterNamespace inside(ns);
  bus::Bus air(kAir), air2(kAir), ground(kGround);

  // Added latency at zero configured delay.
  link::Probe direct(air, air2, "DIRECT");
  direct.run(latency_messages, 200, 100, 300);
  link::Probe relayed(air, ground, "PROBE_LAT");
  relayed.run(latency_messages, 200, 100, 300);
  const auto d = latency::summarize(direct.delays_ms()), r = latency::summarize(relayed.delays_ms());
  std::printf("latency, 100-byte messages at 200 Hz (ms)     median    p90    p99    max   received\n");
  std::printf("  same network (no link)                    %7.3f %6.3f %6.3f %6.2f   %lld/%lld\n", d.median, d.p90, d.p99,
              d.max, static_cast<long long>(d.count), static_cast<long long>(direct.sent()));
  std::printf("  through aerie-link, zero delay            %7.3f %6.3f %6.3f %6.2f   %lld/%lld\n", r.median, r.p90, r.p99,
              r.max, static_cast<long long>(r.count), static_cast<long long>(relayed.sent()));
  std::printf("  added by the link: median %.3f ms, p99 %.3f ms\n", r.median - d.median, r.p99 - d.p99);

  // Throughput when flooded.
  struct Flood {
    size_t size;
    int messages;
    double msgs_per_s = 0, mb_per_s = 0, delivered_fraction = 0, sender_msgs_per_s = 0;
  };
  std::vector<Flood> floods = {{100, 40000}, {1000, 30000}, {10000, 10000}, {60000, 2000}};
  std::printf("\nthroughput (flooded, zero delay)   size    sent/s  relayed/s     MB/s  delivered\n");
  for (auto& f : floods) {
    link::Probe p(air, ground, "PROBE_" + std::to_string(f.size));
    const auto t0 = std::chrono::steady_clock::now();
    p.run(f.messages, 0, f.size, 0);
    const double send_s = std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
    p.pump(1500);
    const auto& rx = p.received();
    f.sender_msgs_per_s = f.messages / send_s;
    f.delivered_fraction = static_cast<double>(rx.size()) / f.messages;
    if (rx.size() > 1) {
      const double span = static_cast<double>(rx.back().recv_utime - rx.front().recv_utime) * 1e-6;
      f.msgs_per_s = static_cast<double>(rx.size() - 1) / span;
      f.mb_per_s = f.msgs_per_s * static_cast<double>(rx.front().payload_bytes) / 1e6;
    }
    std::printf("                                  %6zu %9.0f %10.0f %8.2f  %8.1f %%\n", f.size, f.sender_msgs_per_s,
                f.msgs_per_s, f.mb_per_s, 100 * f.delivered_fraction);
  }

  std::ofstream json(out_dir + "/link.json");
  json << "{\n  \"realtime\": " << (realtime ? "true" : "false") << ",\n  \"direct_ms\": " << json_array(direct.delays_ms())
       << ",\n  \"link_ms\": " << json_array(relayed.delays_ms()) << ",\n  \"throughput\": [";
  for (size_t i = 0; i < floods.size(); ++i)
    json << (i ? ", " : "") << "{\"size\": " << floods[i].size << ", \"msgs_per_s\": " << floods[i].msgs_per_s
         << ", \"mb_per_s\": " << floods[i].mb_per_s << ", \"sender_msgs_per_s\": " << floods[i].sender_msgs_per_s
         << ", \"delivered_fraction\": " << floods[i].delivered_fraction << "}";
  json << "]\n}\n";
  json.close();
  std::ofstream csv(out_dir + "/link.csv");
  csv << "figure,value\n"
      << "direct_median_ms," << d.median << "\ndirect_p99_ms," << d.p99 << "\nlink_median_ms," << r.median
      << "\nlink_p99_ms," << r.p99 << "\nadded_median_ms," << r.median - d.median << "\nadded_p99_ms,"
      << r.p99 - d.p99 << "\n";
  for (const auto& f : floods)
    csv << "relayed_msgs_per_s[" << f.size << "B]," << f.msgs_per_s << "\nrelayed_MB_per_s[" << f.size << "B],"
        << f.mb_per_s << "\ndelivered_fraction[" << f.size << "B]," << f.delivered_fraction << "\n";
  csv.close();
  const std::string plot = std::filesystem::path(__FILE__).parent_path() / "plot_link.py";
  if (std::filesystem::exists(plot) && std::filesystem::exists("/usr/bin/python3"))
    if (std::system(("/usr/bin/python3 " + plot + " " + out_dir + "/link.json " + out_dir + "/link.png").c_str()) == 0)
      std::printf("plot: %s/link.png\n", out_dir.c_str());
  std::printf("results: %s/link.json, %s/link.csv\n", out_dir.c_str(), out_dir.c_str());
  link.stop(SIGINT, 5s);
  const std::string log = link.log();
  if (const size_t at = log.rfind("air->ground: received"); at != std::string::npos)
    std::printf("aerie-link %s", log.substr(at, log.find('\n', at) - at + 1).c_str());
  return 0;
}
