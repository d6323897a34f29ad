// aerie-deputy: one per host. Runs the commands a procman sheriff orders (Aerie's
// aerie-sheriff or libbot2's bot-procman-sheriff) and reports them on PMD_INFO2
// once a second and on every change; forwards their output on PMD_PRINTF.
// Keyed (--key, docs/procman.md "Keyed mode"): obeys only tagged, fresh, unreplayed orders
// of one sheriff on PMD_ORDERS2_SEALED; libbot2's unauthenticated PMD_ORDERS2 only with
// --insecure. Neither given: refuses to start.
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
#include "common/seal/keys.hpp"
#include "common/util/cli.hpp"
#include "common/util/time.hpp"
#include "procman/channels.hpp"
#include "procman/deputy.hpp"
#include "procman/orders_auth.hpp"

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

// ${XDG_STATE_HOME:-$HOME/.local/state}/aerie/deputy-NAME.counters (folder made with mode 0700).
std::string default_state_path(const std::string& name) {
  std::filesystem::path dir;
  if (const char* x = std::getenv("XDG_STATE_HOME"); x && *x) dir = x;
  else if (const char* h = std::getenv("HOME"); h && *h) dir = std::filesystem::path(h) / ".local" / "state";
  else dir = "/var/lib";
  dir /= "aerie";
  std::filesystem::create_directories(dir);
  std::filesystem::permissions(dir, std::filesystem::perms::owner_all, std::filesystem::perm_options::replace);
  return (dir / ("deputy-" + name + ".counters")).string();
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
  std::string key_path, state_path;
  bool insecure = false;
  procman::GateOptions gate_opts;
  app.add_option("--key", key_path,
                 "mission key file (mode 0600, aerie-keys generate): obey only orders tagged with it, on " +
                     std::string(procman::kSealedOrdersChannel));
  app.add_flag("--insecure,--libbot2-compatible", insecure,
               "libbot2 mode for trusted hosts: obey unauthenticated PMD_ORDERS2 from anyone on the LCM network");
  app.add_option("--sheriff-id", gate_opts.follow_sheriff,
                 "keyed: obey only the sheriff with this id (default: the first heard)");
  app.add_option("--sheriff-handover", gate_opts.handover_s,
                 "keyed, no --sheriff-id: another sheriff may take over once the followed one is silent this long "
                 "(seconds, 0 = never)")
      ->capture_default_str();
  app.add_option("--state", state_path,
                 "keyed: file of the last order counter accepted per sheriff, kept across restarts (default: "
                 "$XDG_STATE_HOME/aerie/deputy-NAME.counters)");
  util::add_common_options(app, common, /*with_config=*/false);
  CLI11_PARSE(app, argc, argv);
  util::init_logging("aerie-deputy", common.log_level);

  if (key_path.empty() && !insecure) {
    spdlog::critical(
        "refusing to start without a key: give the mission key with --key FILE (aerie-keys generate --out FILE; "
        "the sheriff needs the same file), or --insecure to obey libbot2's unauthenticated PMD_ORDERS2 from anyone "
        "on this LCM network (trusted hosts only; docs/procman.md \"Keyed mode\")");
    return 1;
  }
  if (!key_path.empty() && insecure) {
    spdlog::critical("--key and --insecure contradict each other: give one");
    return 1;
  }

  try {
    std::unique_ptr<procman::OrdersGate> gate;
    if (!key_path.empty()) {
      const seal::SecretKey key = seal::load_key(key_path);
      gate_opts.window_s = opts.max_order_age_s;
      gate_opts.state_path = state_path.empty() ? default_state_path(opts.name) : state_path;
      gate = std::make_unique<procman::OrdersGate>(key, opts.name, gate_opts);
    }
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
    int64_t last_refusal_ms = -1000000;
    std::string last_refusal;
    auto obey = [&](const bot_procman::orders2_t& m) {
      bool changed = false;
      const auto r = deputy.handle_orders(m, util::wall_utime(), &changed);
      if (r == procman::Deputy::OrdersResult::Applied) {
        status.count("orders_applied");
        info_due = info_due || changed;
      } else if (r == procman::Deputy::OrdersResult::Stale) {
        status.count("orders_stale");
        last_refusal = "refusing stale orders: check the clocks";
        last_refusal_ms = mono_ms();
      }
    };
    // Keyed: a refusal is counted (the gate's counters go into the status), said once per
    // reason and sender, and never fatal.
    auto refused = [&](const procman::GateVerdict& v) {
      if (!v.notice.empty()) {
        // A second sheriff is said loudly: an error in the log, ERROR on PMD_PRINTF.
        if (v.refusal == procman::OrdersRefusal::OtherSheriff) {
          spdlog::error("{}", v.notice);
          bot_procman::printf_t m;
          m.utime = util::wall_utime();
          m.deputy_name = opts.name;
          m.sheriff_id = 0;
          m.text = "ERROR: " + v.notice + "\n";
          bus.publish(procman::kPrintfChannel, m);
          status.count("printf_messages");
        } else {
          publish_printf(0, v.notice + "\n");
        }
      }
      if (v.refusal == procman::OrdersRefusal::None) return;
      last_refusal = std::string("refused orders: ") + procman::to_string(v.refusal);
      last_refusal_ms = mono_ms();
      if (v.first) publish_printf(0, v.why + "\n");
    };
    bus.subscribe<bot_procman::orders2_t>(procman::kOrdersChannel, [&](const bot_procman::orders2_t& m, const auto&) {
      if (discovering) return;
      if (!gate) return obey(m);
      if (m.host != opts.name) return;  // someone else's orders: not ours to judge
      refused(gate->refuse_plain(m));
    });
    if (gate) {
      bus.subscribe_raw(procman::kSealedOrdersChannel, [&](const uint8_t* data, size_t size, const auto&) {
        if (discovering) return;
        auto v = gate->check({data, size}, util::wall_utime(), mono_ms());
        refused(v);
        if (v.accepted()) obey(v.orders);
      });
    }
    // The status: the gate's counters, and its health (ERROR while two sheriffs are heard).
    auto update_status = [&] {
      const int64_t now = mono_ms();
      if (!gate) {
        const std::string insecure_mode =
            "INSECURE: libbot2 mode, unauthenticated orders on " + std::string(procman::kOrdersChannel);
        status.warn(now - last_refusal_ms < 5000 ? last_refusal + "; " + insecure_mode : insecure_mode);
        return;
      }
      for (size_t r = 1; r < procman::kOrdersRefusalCount; ++r) {
        const auto reason = static_cast<procman::OrdersRefusal>(r);
        status.set(procman::counter_name(reason), static_cast<int64_t>(gate->refused(reason)));
      }
      status.set("orders_accepted", static_cast<int64_t>(gate->accepted()));
      status.set("state_write_errors", static_cast<int64_t>(gate->state_write_errors()));
      const std::string keyed = "keyed, key " + gate->fingerprint() + ", " +
                                (gate->following() ? "following sheriff '" + gate->following_name() + "' (id " +
                                                         std::to_string(gate->following()) + ")"
                                                   : std::string("no sheriff heard yet"));
      if (const std::string c = gate->conflict(now); !c.empty()) status.error(c + "; " + keyed);
      else if (now - last_refusal_ms < 5000) status.warn(last_refusal + "; " + keyed);
      else status.ok(keyed);
    };

    bus::install_stop_handlers();
    spdlog::info("deputy '{}' on {} (PID {})", opts.name, bus.url().empty() ? "LCM default URL" : bus.url(), getpid());
    if (gate)
      spdlog::info("keyed: key {} ({}), orders only on {}, state {}", gate->fingerprint(), key_path,
                   procman::kSealedOrdersChannel, gate_opts.state_path);
    else
      spdlog::warn("INSECURE (libbot2-compatible): obeying unauthenticated {} from anyone on this LCM network",
                   procman::kOrdersChannel);
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
          spdlog::info("discovery done, taking orders on {}",
                       gate ? procman::kSealedOrdersChannel : procman::kOrdersChannel);
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
      update_status();
      status.tick();
    }
    spdlog::info("stopping all commands");
    deputy.shutdown();
    publish_info();
    update_status();
    status.publish_now();
  } catch (const std::exception& e) {
    spdlog::critical("{}", e.what());
    return 1;
  }
  return 0;
}
