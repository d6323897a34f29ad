// aerie-deputy: one per host. Runs the commands a procman sheriff orders (Aerie's
// aerie-sheriff or libbot2's bot-procman-sheriff) and reports them on PMD_INFO2
// once a second and on every change; forwards their output on PMD_PRINTF.
#include <bot_procman/discovery_t.hpp>
#include <bot_procman/info2_t.hpp>
#include <bot_procman/orders2_t.hpp>
#include <bot_procman/printf_t.hpp>
#include <poll.h>
#include <spdlog/spdlog.h>
#include <unistd.h>

#include <CLI/CLI.hpp>
#include <chrono>
#include <filesystem>
#include <random>

#include "common/bus/bus.hpp"
#include "common/bus/node.hpp"
#include "common/bus/status.hpp"
#include "common/util/cli.hpp"
#include "common/util/time.hpp"
#include "procman/channels.hpp"
#include "procman/deputy.hpp"

namespace {

int64_t mono_ms() {
  return std::chrono::duration_cast<std::chrono::milliseconds>(std::chrono::steady_clock::now().time_since_epoch())
      .count();
}

std::string default_name() {
  char buf[256] = {0};
  gethostname(buf, sizeof buf - 1);
  return buf;
}

}  // namespace

int main(int argc, char** argv) {
  using namespace aerie;
  CLI::App app{
      "aerie-deputy: runs the commands a procman sheriff orders on this host and reports them\n"
      "(libbot2 bot_procman protocol: PMD_ORDERS2 in, PMD_INFO2 / PMD_PRINTF out)."};
  util::CommonOptions common;
  procman::DeputyOptions opts;
  opts.name = default_name();
  app.add_option("-n,--name", opts.name, "deputy name, the 'host' of the sheriff's config (default: hostname)");
  app.add_option("--max-order-age", opts.max_order_age_s,
                 "refuse orders older than this (seconds; the clocks of sheriff and deputy must agree)")
      ->capture_default_str()
      ->check(CLI::PositiveNumber);
  app.add_option("--respawn-min-ms", opts.respawn_min_ms, "first auto-respawn delay")->capture_default_str()->check(CLI::PositiveNumber);
  app.add_option("--respawn-max-ms", opts.respawn_max_ms, "longest auto-respawn delay (back-off doubles up to it)")
      ->capture_default_str()
      ->check(CLI::PositiveNumber);
  bool no_bin_path = false;
  app.add_flag("--no-bin-path", no_bin_path, "do not put this executable's folder first on the commands' PATH");
  util::add_common_options(app, common, /*with_config=*/false);
  CLI11_PARSE(app, argc, argv);
  util::init_logging("aerie-deputy", common.log_level);

  try {
    if (!no_bin_path) opts.extra_path = std::filesystem::read_symlink("/proc/self/exe").parent_path().string();
    bus::Bus bus(common.lcm_url);
    bus::StatusReporter status(bus, "deputy-" + opts.name);

    auto publish_printf = [&](int32_t id, const std::string& text) {
      bot_procman::printf_t m;
      m.utime = util::wall_utime();
      m.deputy_name = opts.name;
      m.sheriff_id = id;
      m.text = text;
      bus.publish(procman::kPrintfChannel, m);
      status.count("printf_messages");
      if (id == 0) spdlog::info("{}", text.substr(0, text.find_last_not_of('\n') + 1));
    };
    procman::Deputy deputy(opts, publish_printf);

    auto publish_info = [&] {
      bus.publish(procman::kInfoChannel, deputy.report(util::wall_utime()));
      status.count("reports");
    };

    // Discovery (as libbot2): for 1.5 s announce ourselves and watch for another
    // deputy with our name; only then take orders.
    std::random_device rd;
    const int64_t nonce = (static_cast<int64_t>(rd()) << 31) ^ rd() ^ getpid();
    const int64_t t0 = mono_ms();
    bool discovering = true;
    int conflict = 0;
    bool info_due = false;
    int64_t last_discovery_reply = -1000;
    bus.subscribe<bot_procman::discovery_t>(procman::kDiscoverChannel, [&](const bot_procman::discovery_t& m, const auto&) {
      if (discovering) {
        if (m.host == opts.name && m.nonce != nonce) conflict = 1;
      } else if (mono_ms() - last_discovery_reply >= 100) {
        info_due = true;  // a sheriff (or a new deputy) asks who is there
        last_discovery_reply = mono_ms();
      }
    });
    bus.subscribe<bot_procman::info2_t>(procman::kInfoChannel, [&](const bot_procman::info2_t& m, const auto&) {
      if (discovering && m.host == opts.name) conflict = 2;
    });
    bus.subscribe<bot_procman::orders2_t>(procman::kOrdersChannel, [&](const bot_procman::orders2_t& m, const auto&) {
      if (discovering) return;
      bool changed = false;
      const auto r = deputy.handle_orders(m, util::wall_utime(), &changed);
      if (r == procman::Deputy::OrdersResult::Applied) {
        status.count("orders_applied");
        info_due = info_due || changed;
      } else if (r == procman::Deputy::OrdersResult::Stale) {
        status.count("orders_stale");
        status.warn("refusing stale orders: check the clocks");
      }
    });

    bus::install_stop_handlers();
    spdlog::info("deputy '{}' on {} (PID {})", opts.name, bus.url().empty() ? "LCM default URL" : bus.url(), getpid());
    int64_t next_discovery = t0;
    int64_t next_report = t0 + 1500;
    while (!bus::stop_requested()) {
      int64_t now = mono_ms();
      if (discovering) {
        if (conflict) {
          spdlog::error("another deputy named '{}' is running on this LCM network; exiting", opts.name);
          return 2;
        }
        if (now - t0 >= 1500) {
          discovering = false;
          info_due = true;
          spdlog::info("discovery done, taking orders on {}", procman::kOrdersChannel);
        } else if (now >= next_discovery) {
          bot_procman::discovery_t d;
          d.utime = util::wall_utime();
          d.host = opts.name;
          d.nonce = nonce;
          bus.publish(procman::kDiscoverChannel, d);
          next_discovery += 200;
        }
      }
      std::vector<pollfd> fds;
      fds.push_back({bus.fileno(), POLLIN, 0});
      for (int fd : deputy.wait_fds()) fds.push_back({fd, POLLIN, 0});
      int64_t timeout = std::max<int64_t>(0, next_report - now);
      if (discovering) timeout = std::min(timeout, std::max<int64_t>(0, next_discovery - now));
      if (const int t = deputy.next_timer_ms(); t >= 0) timeout = std::min<int64_t>(timeout, t);
      if (info_due) timeout = 0;
      poll(fds.data(), fds.size(), static_cast<int>(timeout));
      if (fds[0].revents & POLLIN) {
        for (int k = 0; k < 100 && bus.handle(0) > 0; ++k) {
        }
      }
      if (deputy.step()) info_due = true;
      now = mono_ms();
      if (now >= next_report) {
        deputy.sample_usage();
        if (!discovering) info_due = true;
        next_report += 1000;
        if (next_report < now) next_report = now + 1000;
      }
      if (info_due && !discovering) {
        publish_info();
        info_due = false;
      }
      status.tick();
    }
    spdlog::info("stopping all commands");
    deputy.shutdown();
    publish_info();
    status.publish_now();
  } catch (const std::exception& e) {
    spdlog::critical("{}", e.what());
    return 1;
  }
  return 0;
}
