// bench_procman: procman figures (docs/results/procman.md).
//  * deputy overhead: CPU time of aerie-deputy (percent of one core) with no command,
//    10 idle commands, and 10 commands printing 100 lines/s each;
//  * order latency: sheriff publishes orders -> the deputy's report shows the
//    command running (start) or gone (stop), over many trials.
// Runs aerie-deputy in a network namespace it creates (root). Writes
// procman.json / procman.csv (and procman.png with /usr/bin/python3 + matplotlib).
#include <bot_procman/info2_t.hpp>
#include <signal.h>
#include <unistd.h>

#include <CLI/CLI.hpp>
#include <chrono>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <iostream>
#include <sstream>

#include "common/bus/bus.hpp"
#include "common/util/time.hpp"
#include "procman/channels.hpp"
#include "procman/proc_stats.hpp"
#include "procman/sheriff.hpp"
#include "procman/testbed.hpp"
#include "tools/latency/stats.hpp"

using namespace aerie;
using namespace std::chrono_literals;
using Clock = std::chrono::steady_clock;

namespace {

const std::string kUrl = "udpm://239.255.76.67:7667?ttl=0";

int64_t mono_ms() {
  return std::chrono::duration_cast<std::chrono::milliseconds>(Clock::now().time_since_epoch()).count();
}

// The sheriff side, in this process.
struct Driver {
  bus::Bus bus{kUrl};
  procman::Sheriff sheriff{"bench-sheriff"};
  int64_t next_orders = 0;
  int64_t last_info_ms = -1;

  Driver() {
    bus.subscribe<bot_procman::info2_t>(procman::kInfoChannel, [this](const bot_procman::info2_t& m, const auto&) {
      sheriff.on_info(m, mono_ms());
      last_info_ms = mono_ms();
    }, 1000);
  }
  void send_orders() {
    for (const auto& o : sheriff.orders(util::wall_utime())) bus.publish(procman::kOrdersChannel, o);
    next_orders = mono_ms() + 1000;
  }
  // Handles traffic (and sends orders like aerie-sheriff) until pred() or timeout.
  bool pump_until(const std::function<bool()>& pred, int timeout_ms) {
    const int64_t until = mono_ms() + timeout_ms;
    while (!pred()) {
      if (mono_ms() > until) return false;
      if (sheriff.take_dirty() || mono_ms() >= next_orders) send_orders();
      bus.handle(1);
    }
    return true;
  }
  void pump_for(int ms) {
    pump_until([] { return false; }, ms);
  }
  bool all(const std::string& group, procman::WaitFor what, int timeout_ms) {
    const auto keys = sheriff.select(procman::TargetKind::Group, group);
    return pump_until([&] { return sheriff.reached(keys, what, mono_ms()); }, timeout_ms);
  }
};

double cpu_seconds(pid_t pid) {
  const auto p = procman::read_process(pid);
  return p ? static_cast<double>(p->cpu_jiffies) / static_cast<double>(sysconf(_SC_CLK_TCK)) : 0.0;
}

}  // namespace

int main(int argc, char** argv) {
  CLI::App app{"bench_procman: deputy CPU overhead and sheriff->deputy order latency"};
  std::string out_dir = "bench-results/procman";
  double seconds = 20;
  int trials = 50;
  app.add_option("--out", out_dir, "output folder")->capture_default_str();
  app.add_option("--seconds", seconds, "measurement time per overhead scenario")->capture_default_str();
  app.add_option("--trials", trials, "start/stop trials for the order latency")->capture_default_str();
  CLI11_PARSE(app, argc, argv);
  if (const auto why = procman::testbed::namespaces_unavailable(); !why.empty()) {
    std::cerr << "bench_procman: " << why << "\n";
    return 2;
  }
  std::filesystem::create_directories(out_dir);
  const std::string bin = std::filesystem::read_symlink("/proc/self/exe").parent_path().string();

  procman::testbed::NetNamespace ns(procman::testbed::unique_name("bench-pm"));
  auto argv_deputy = ns.exec_prefix();
  // libbot2 mode: this bench sends plain PMD_ORDERS2 itself.
  argv_deputy.insert(argv_deputy.end(), {bin + "/aerie-deputy", "--name", "bench", "--lcm-url", kUrl, "--insecure"});
  procman::testbed::Process deputy(argv_deputy, out_dir + "/deputy.log");

  std::ostringstream pmd;
  for (int i = 0; i < 10; ++i) {
    pmd << "group \"idle\" { cmd \"idle" << i << "\" { exec = \"sleep 100000\"; host = \"bench\"; } }\n";
    pmd << "group \"chatty\" { cmd \"chatty" << i << "\" { exec = \"sh -c 'while :; do echo line " << i
        << " of the chatty command; sleep 0.01; done'\"; host = \"bench\"; } }\n";
  }
  pmd << "group \"lat\" { cmd \"lat\" { exec = \"sleep 100000\"; host = \"bench\"; } }\n";
  const procman::PmdConfig config = procman::parse_pmd(pmd.str(), "bench.pmd");

  procman::testbed::EnterNamespace inside(ns);
  Driver d;
  d.sheriff.load(config);
  if (!d.pump_until([&] { return d.sheriff.deputy_alive("bench", mono_ms()); }, 15000)) {
    std::cerr << "bench_procman: no report from the deputy\n" << deputy.log();
    return 1;
  }

  // Deputy overhead.
  struct Overhead {
    std::string scenario;
    double cpu_percent;
  };
  std::vector<Overhead> overhead;
  auto measure = [&](const std::string& scenario) {
    d.pump_for(2000);  // settle
    const double c0 = cpu_seconds(deputy.pid());
    const auto t0 = Clock::now();
    d.pump_for(static_cast<int>(seconds * 1000));
    const double c1 = cpu_seconds(deputy.pid());
    const double wall = std::chrono::duration<double>(Clock::now() - t0).count();
    overhead.push_back({scenario, 100.0 * (c1 - c0) / wall});
    std::printf("deputy CPU, %-34s %6.2f %% of one core\n", scenario.c_str(), overhead.back().cpu_percent);
  };
  measure("no command running");
  for (const char* group : {"idle", "chatty"}) {
    d.sheriff.start(d.sheriff.select(procman::TargetKind::Group, group));
    if (!d.all(group, procman::WaitFor::Running, 20000)) {
      std::cerr << "bench_procman: group " << group << " did not start\n";
      return 1;
    }
    measure(std::string("10 commands, ") + (std::string(group) == "idle" ? "idle" : "1000 output lines/s"));
    d.sheriff.stop(d.sheriff.select(procman::TargetKind::Group, group));
    d.all(group, procman::WaitFor::Stopped, 20000);
  }

  // Order latency: orders published -> report shows the new state.
  std::vector<double> start_ms, stop_ms;
  const auto lat = d.sheriff.select(procman::TargetKind::Command, "lat");
  for (int t = 0; t < trials; ++t) {
    d.pump_for(100);
    auto t0 = Clock::now();
    d.sheriff.start(lat);
    if (!d.pump_until([&] { return d.sheriff.reached(lat, procman::WaitFor::Running, mono_ms()); }, 10000)) continue;
    start_ms.push_back(std::chrono::duration<double, std::milli>(Clock::now() - t0).count());
    d.pump_for(100);
    t0 = Clock::now();
    d.sheriff.stop(lat);
    if (!d.pump_until([&] { return d.sheriff.reached(lat, procman::WaitFor::Stopped, mono_ms()); }, 10000)) continue;
    stop_ms.push_back(std::chrono::duration<double, std::milli>(Clock::now() - t0).count());
  }
  const auto s_start = latency::summarize(start_ms), s_stop = latency::summarize(stop_ms);
  std::printf("order -> running  (n=%lld): median %.2f ms, p90 %.2f, p99 %.2f, max %.2f\n",
              static_cast<long long>(s_start.count), s_start.median, s_start.p90, s_start.p99, s_start.max);
  std::printf("order -> stopped  (n=%lld): median %.2f ms, p90 %.2f, p99 %.2f, max %.2f\n",
              static_cast<long long>(s_stop.count), s_stop.median, s_stop.p90, s_stop.p99, s_stop.max);

  std::ofstream csv(out_dir + "/procman.csv");
  csv << "figure,value\n";
  for (const auto& o : overhead) csv << "deputy_cpu_percent[" << o.scenario << "]," << o.cpu_percent << "\n";
  csv << "start_latency_median_ms," << s_start.median << "\nstart_latency_p99_ms," << s_start.p99
      << "\nstop_latency_median_ms," << s_stop.median << "\nstop_latency_p99_ms," << s_stop.p99 << "\n";
  std::ofstream json(out_dir + "/procman.json");
  json << "{\n  \"deputy_cpu_percent\": {";
  for (size_t i = 0; i < overhead.size(); ++i)
    json << (i ? ", " : "") << "\"" << overhead[i].scenario << "\": " << overhead[i].cpu_percent;
  json << "},\n  \"start_latency_ms\": [";
  for (size_t i = 0; i < start_ms.size(); ++i) json << (i ? ", " : "") << start_ms[i];
  json << "],\n  \"stop_latency_ms\": [";
  for (size_t i = 0; i < stop_ms.size(); ++i) json << (i ? ", " : "") << stop_ms[i];
  json << "]\n}\n";
  json.close();
  const std::string plot = std::filesystem::path(__FILE__).parent_path() / "plot_procman.py";
  if (std::filesystem::exists(plot) && std::filesystem::exists("/usr/bin/python3"))
    if (std::system(("/usr/bin/python3 " + plot + " " + out_dir + "/procman.json " + out_dir + "/procman.png").c_str()) == 0)
      std::printf("plot: %s/procman.png\n", out_dir.c_str());
  std::printf("results: %s/procman.json, %s/procman.csv\n", out_dir.c_str(), out_dir.c_str());
  deputy.stop(SIGTERM, 15s);
  return 0;
}
