// bench_door: the cost of the sealed door (issue 46 section 5; docs/results/security.md),
// side by side in one run, with and without sealing:
//  * CPU per message in process (thread CPU time) for the sending half (frame + seal) and the
//    receiving half (open + policy + reassembly), per message size, up to a raw 752x480 stereo
//    pair (aerie.stereo_image_t, GRAY8), and what that is at 20 Hz in percent of one core;
//  * the two halves as processes (aerie-link --half air|ground, in a network namespace the
//    bench creates; root): added latency p50 / p99 of 100-byte messages at 200 Hz against LCM
//    on one network, and a raw stereo stream at 20 Hz (delivered, latency, the air half's CPU).
// Writes door.csv in --out.
#include <aerie/stereo_image_t.hpp>
#include <signal.h>
#include <time.h>
#include <unistd.h>

#include <CLI/CLI.hpp>
#include <chrono>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <iostream>
#include <sstream>
#include <thread>

#include "common/bus/bus.hpp"
#include "common/seal/keys.hpp"
#include "procman/testbed.hpp"
#include "tools/latency/stats.hpp"
#include "tools/link/door.hpp"
#include "tools/link/probe.hpp"

using namespace aerie;
using namespace std::chrono_literals;
namespace testbed = aerie::procman::testbed;

namespace {

// Receive buffers for 0.7 MB messages (LCM drops fragments of large messages otherwise; the
// notes: raise net.core.rmem_max for high-rate images).
const std::string kAir = "udpm://239.255.76.67:7667?ttl=0&recv_buf_size=4194304";
const std::string kGround = "udpm://239.255.76.68:7668?ttl=0&recv_buf_size=4194304";

double thread_cpu_s() {
  timespec t{};
  clock_gettime(CLOCK_THREAD_CPUTIME_ID, &t);
  return static_cast<double>(t.tv_sec) + static_cast<double>(t.tv_nsec) * 1e-9;
}

// utime + stime of a process, seconds.
double process_cpu_s(pid_t pid) {
  std::ifstream f("/proc/" + std::to_string(pid) + "/stat");
  std::string s((std::istreambuf_iterator<char>(f)), std::istreambuf_iterator<char>());
  const auto close = s.rfind(')');
  if (close == std::string::npos) return 0;
  std::istringstream rest(s.substr(close + 2));
  std::string field;
  double ut = 0, st = 0;
  for (int i = 3; i <= 15 && rest >> field; ++i) {
    if (i == 14) ut = std::stod(field);
    if (i == 15) st = std::stod(field);
  }
  return (ut + st) / static_cast<double>(sysconf(_SC_CLK_TCK));
}

size_t stereo_size() {
  aerie::stereo_image_t m{};
  for (auto* im : {&m.left, &m.right}) {
    im->width = 752;
    im->height = 480;
    im->row_stride = 752;
    im->size = 752 * 480;
    im->data.assign(752 * 480, 0);
  }
  return static_cast<size_t>(m.getEncodedSize());
}

struct InProcess {
  size_t size;
  double send_us[2] = {0, 0}, recv_us[2] = {0, 0};  // [insecure, secure]
};

InProcess cost(size_t size, const seal::SecretKey& key) {
  InProcess r{size};
  std::vector<uint8_t> payload(size);
  for (size_t i = 0; i < size; ++i) payload[i] = static_cast<uint8_t>(i * 13);
  const int n = size > 100000 ? 200 : size > 10000 ? 2000 : 20000;
  for (int secure = 0; secure < 2; ++secure) {
    const seal::SecretKey* k = secure ? &key : nullptr;
    link::DoorSender tx(k, seal::Direction::AirToGround, 1, 0, 0);
    link::DoorReceiver rx(k, seal::Direction::AirToGround, link::DoorPolicy{".*", {}, ""});
    std::vector<std::vector<std::vector<uint8_t>>> all(static_cast<size_t>(n));
    double t0 = thread_cpu_s();
    for (int i = 0; i < n; ++i) tx.send("CAM_STEREO", payload, i * 1e-3, all[static_cast<size_t>(i)]);
    r.send_us[secure] = (thread_cpu_s() - t0) / n * 1e6;
    t0 = thread_cpu_s();
    size_t ok = 0;
    for (int i = 0; i < n; ++i)
      for (const auto& d : all[static_cast<size_t>(i)]) ok += rx.receive(d, i * 1e-3).has_value();
    r.recv_us[secure] = (thread_cpu_s() - t0) / n * 1e6;
    if (ok != static_cast<size_t>(n)) std::fprintf(stderr, "bench_door: %zu of %d delivered\n", ok, n);
  }
  return r;
}

struct Run {
  latency::Summary lat;
  int64_t sent = 0, received = 0;
  double cpu_s = 0, wall_s = 0;
};

}  // namespace

int main(int argc, char** argv) {
  CLI::App app{"bench_door: the sealed door's cost, with and without sealing"};
  std::string out_dir = "bench-results/door";
  int latency_messages = 2000;
  double stereo_s = 5;
  bool realtime = true;
  app.add_option("--out", out_dir, "output folder")->capture_default_str();
  app.add_option("--latency-messages", latency_messages, "probe messages per latency run (200 Hz)")->capture_default_str();
  app.add_option("--stereo-seconds", stereo_s, "seconds of the 20 Hz raw stereo stream per mode")->capture_default_str();
  app.add_option("--realtime", realtime, "SCHED_FIFO for the halves and the probe (figures of the door, not the scheduler)")
      ->capture_default_str();
  CLI11_PARSE(app, argc, argv);
  std::filesystem::create_directories(out_dir);
  const seal::SecretKey key = seal::SecretKey::generate();
  const size_t stereo = stereo_size();

  std::printf("in process, CPU per message (us)     size   send clear  send sealed   open clear  open sealed\n");
  std::vector<InProcess> inproc;
  for (size_t size : {size_t{100}, size_t{1000}, size_t{60000}, stereo}) {
    inproc.push_back(cost(size, key));
    const auto& r = inproc.back();
    std::printf("                                  %7zu %12.2f %12.2f %12.2f %12.2f\n", size, r.send_us[0], r.send_us[1],
                r.recv_us[0], r.recv_us[1]);
  }
  const auto& st = inproc.back();
  std::printf("raw stereo (%zu B) at 20 Hz, one core: sender %.2f %% sealed vs %.2f %% clear; receiver %.2f %% vs %.2f %%\n",
              stereo, 20 * st.send_us[1] / 1e4, 20 * st.send_us[0] / 1e4, 20 * st.recv_us[1] / 1e4,
              20 * st.recv_us[0] / 1e4);

  std::ofstream csv(out_dir + "/door.csv");
  csv << "figure,value\n";
  for (const auto& r : inproc) {
    csv << "send_us_clear[" << r.size << "B]," << r.send_us[0] << "\nsend_us_sealed[" << r.size << "B]," << r.send_us[1]
        << "\nopen_us_clear[" << r.size << "B]," << r.recv_us[0] << "\nopen_us_sealed[" << r.size << "B],"
        << r.recv_us[1] << "\n";
  }

  if (const auto why = testbed::namespaces_unavailable(); !why.empty()) {
    std::cerr << "bench_door: skipping the process part: " << why << "\n";
    return 0;
  }
  const std::string bin = std::filesystem::read_symlink("/proc/self/exe").parent_path().string();
  const std::string key_file = out_dir + "/mission.key";
  std::filesystem::remove(key_file);
  seal::save_key(key_file, key);
  const std::string cfg = out_dir + "/door.yaml";
  std::ofstream(cfg) << "air_to_ground: {channels: \"PROBE.*\", queue_bytes: 100000000, rate: []}\n"
                     << "ground_to_air: {channels: \"PROBE_UP\", rate: [], operator_channels: \"\"}\n";

  std::optional<testbed::RealtimePriority> rt;
  if (realtime) rt.emplace(10);
  testbed::NetNamespace ns(testbed::unique_name("bench-door"));
  Run lat[2], stream[2];
  latency::Summary direct;
  for (int secure = 0; secure < 2; ++secure) {
    auto half = [&](const std::string& h, const std::string& listen, const std::string& peer, const std::string& url) {
      auto a = ns.exec_prefix();
      a.insert(a.end(), {bin + "/aerie-link", "--half", h, "--config", cfg, "--listen", listen, "--peer", peer,
                         "--lcm-url", url});
      if (realtime) a.insert(a.end(), {"--realtime-priority", "10"});
      if (secure) a.insert(a.end(), {"--key", key_file});
      else a.push_back("--insecure");
      return a;
    };
    testbed::Process air_half(half("air", "127.0.0.1:17301", "127.0.0.1:17302", kAir), out_dir + "/air.log");
    testbed::Process ground_half(half("ground", "127.0.0.1:17302", "127.0.0.1:17301", kGround), out_dir + "/ground.log");
    std::this_thread::sleep_for(1500ms);
    testbed::EnterNamespace inside(ns);
    bus::Bus air(kAir), air2(kAir), ground(kGround);
    if (secure == 0) {
      link::Probe d(air, air2, "DIRECT");
      d.run(latency_messages, 200, 100, 300);
      direct = latency::summarize(d.delays_ms());
    }
    link::Probe p(air, ground, "PROBE_LAT");
    p.run(latency_messages, 200, 100, 300);
    lat[secure].lat = latency::summarize(p.delays_ms());
    lat[secure].sent = p.sent();
    lat[secure].received = static_cast<int64_t>(p.received().size());

    link::Probe s(air, ground, "PROBE_STEREO");
    const double cpu0 = process_cpu_s(air_half.pid());
    const auto t0 = std::chrono::steady_clock::now();
    s.run(static_cast<int>(20 * stereo_s), 20, stereo, 500);
    stream[secure].wall_s = std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
    stream[secure].cpu_s = process_cpu_s(air_half.pid()) - cpu0;
    stream[secure].lat = latency::summarize(s.delays_ms());
    stream[secure].sent = s.sent();
    stream[secure].received = static_cast<int64_t>(s.received().size());
    air_half.stop(SIGINT, 5s);
    ground_half.stop(SIGINT, 5s);
  }
  std::printf("\nthrough the halves (processes)          median     p99   received\n");
  std::printf("  100 B at 200 Hz, LCM one network    %7.3f %7.3f\n", direct.median, direct.p99);
  for (int s = 0; s < 2; ++s)
    std::printf("  100 B at 200 Hz, halves %-8s    %7.3f %7.3f   %lld/%lld\n", s ? "sealed" : "clear", lat[s].lat.median,
                lat[s].lat.p99, static_cast<long long>(lat[s].received), static_cast<long long>(lat[s].sent));
  std::printf("  sealing adds: p50 %.3f ms, p99 %.3f ms\n", lat[1].lat.median - lat[0].lat.median,
              lat[1].lat.p99 - lat[0].lat.p99);
  for (int s = 0; s < 2; ++s)
    std::printf("  raw stereo %zu B at 20 Hz, %-7s %7.3f %7.3f   %lld/%lld   air half CPU %.1f %% of a core\n", stereo,
                s ? "sealed" : "clear", stream[s].lat.median, stream[s].lat.p99,
                static_cast<long long>(stream[s].received), static_cast<long long>(stream[s].sent),
                100 * stream[s].cpu_s / stream[s].wall_s);
  csv << "direct_median_ms," << direct.median << "\ndirect_p99_ms," << direct.p99 << "\n";
  for (int s = 0; s < 2; ++s) {
    const char* m = s ? "sealed" : "clear";
    csv << "halves_median_ms_" << m << "," << lat[s].lat.median << "\nhalves_p99_ms_" << m << "," << lat[s].lat.p99
        << "\nstereo_median_ms_" << m << "," << stream[s].lat.median << "\nstereo_p99_ms_" << m << ","
        << stream[s].lat.p99 << "\nstereo_delivered_" << m << "," << stream[s].received << "/" << stream[s].sent
        << "\nair_half_cpu_percent_" << m << "," << 100 * stream[s].cpu_s / stream[s].wall_s << "\n";
  }
  std::printf("results: %s/door.csv\n", out_dir.c_str());
  return 0;
}
