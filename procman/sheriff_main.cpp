// aerie-sheriff: loads a procman config, sends orders to the deputies, shows a live
// status table; runs scripts headless (--script NAME --on-script-complete exit);
// --observe only watches (also a log being replayed).
// Keyed (--key, docs/procman.md "Keyed mode"): orders go out tagged on PMD_ORDERS2_SEALED;
// libbot2's unauthenticated PMD_ORDERS2 only with --insecure. Neither given: refuses to start
// (an observer needs neither).
#include <bot_procman/discovery_t.hpp>
#include <bot_procman/info2_t.hpp>
#include <bot_procman/printf_t.hpp>
#include <poll.h>
#include <spdlog/spdlog.h>
#include <unistd.h>

#include <CLI/CLI.hpp>
#include <chrono>
#include <cstdio>
#include <iostream>
#include <map>
#include <memory>
#include <random>
#include <set>
#include <sstream>

#include "common/bus/bus.hpp"
#include "common/bus/node.hpp"
#include "common/seal/keys.hpp"
#include "common/util/cli.hpp"
#include "common/util/time.hpp"
#include "procman/channels.hpp"
#include "procman/orders_auth.hpp"
#include "procman/pmd_config.hpp"
#include "procman/sheriff.hpp"

namespace {

int64_t mono_ms() {
  return std::chrono::duration_cast<std::chrono::milliseconds>(std::chrono::steady_clock::now().time_since_epoch())
      .count();
}

std::string hostname() {
  char buf[256] = {0};
  gethostname(buf, sizeof buf - 1);
  return buf;
}

// One line typed at the terminal: "start cmd NAME", "stop group NAME", "restart
// everything", "script NAME", "table", "quit". Returns a message for the user.
std::string interactive(const std::string& line, aerie::procman::Sheriff& sheriff,
                        const aerie::procman::PmdConfig& config,
                        std::unique_ptr<aerie::procman::ScriptRunner>& runner, bool& quit) {
  using namespace aerie::procman;
  std::istringstream ss(line);
  std::string verb, kind, name;
  ss >> verb >> kind;
  std::getline(ss >> std::ws, name);
  if (name.size() >= 2 && name.front() == '"' && name.back() == '"') name = name.substr(1, name.size() - 2);
  if (verb.empty()) return "";
  if (verb == "quit" || verb == "exit") {
    quit = true;
    return "bye (the deputies keep running what they run)";
  }
  if (verb == "script") {
    try {
      runner = std::make_unique<ScriptRunner>(sheriff, config, kind + (name.empty() ? "" : " " + name),
                                              [](const std::string& m) { std::cout << "script: " << m << "\n"; });
      return "running script " + kind;
    } catch (const std::exception& e) {
      return e.what();
    }
  }
  if (verb == "start" || verb == "stop" || verb == "restart") {
    TargetKind t = TargetKind::Everything;
    if (kind == "cmd") t = TargetKind::Command;
    else if (kind == "group") t = TargetKind::Group;
    else if (kind != "everything") return "usage: " + verb + " everything | cmd NAME | group NAME";
    try {
      const auto keys = sheriff.select(t, name);
      if (verb == "start") sheriff.start(keys);
      if (verb == "stop") sheriff.stop(keys);
      if (verb == "restart") sheriff.restart(keys);
      return verb + ": " + std::to_string(keys.size()) + " command(s)";
    } catch (const std::exception& e) {
      return e.what();
    }
  }
  return "commands: start|stop|restart everything|cmd NAME|group NAME, script NAME, quit";
}

}  // namespace

int main(int argc, char** argv) {
  using namespace aerie;
  CLI::App app{
      "aerie-sheriff: procman sheriff. Loads a config (libbot2 .pmd format), sends orders to the\n"
      "deputies (PMD_ORDERS2) and shows their reports (PMD_INFO2) as a live table."};
  util::CommonOptions common;
  std::string config_path, script, on_complete = "observe", name = "aerie-sheriff@" + hostname();
  bool observe = false, no_table = false, show_output = false;
  double wait_timeout_s = 0, deputy_timeout_s = 3, deputy_wait_s = 15, table_period_s = 1;
  app.add_option("config", config_path, "procman config (.pmd); not needed with --observe")->check(CLI::ExistingFile);
  app.add_option("--script", script, "run this script of the config at start (once all its deputies report)");
  app.add_option("--on-script-complete", on_complete, "after the script: exit, or observe (keep running)")
      ->check(CLI::IsMember({"exit", "observe"}))
      ->capture_default_str();
  app.add_flag("--observe", observe, "only watch: send no orders (works on a replayed log)");
  app.add_option("--name", name, "sheriff name sent with the orders")->capture_default_str();
  app.add_option("--wait-timeout", wait_timeout_s, "fail a script wait after this many seconds (0 = never)")
      ->capture_default_str();
  app.add_option("--deputy-timeout", deputy_timeout_s, "a deputy silent this long is shown LOST")->capture_default_str();
  app.add_option("--deputy-wait", deputy_wait_s, "script mode: fail if a deputy of the config is not heard from by then")
      ->capture_default_str();
  app.add_flag("--no-table", no_table, "do not redraw the status table (state changes are still printed)");
  app.add_option("--table-period", table_period_s, "seconds between table redraws")->capture_default_str();
  app.add_flag("--show-output", show_output, "print the commands' output (PMD_PRINTF)");
  std::string key_path;
  bool insecure = false;
  uint32_t sheriff_id = 0;
  app.add_option("--key", key_path,
                 "mission key file (mode 0600, aerie-keys generate): tag the orders with it, on " +
                     std::string(procman::kSealedOrdersChannel) + " (the deputies need the same file)");
  app.add_flag("--insecure,--libbot2-compatible", insecure,
               "libbot2 mode for trusted hosts: unauthenticated orders on PMD_ORDERS2");
  app.add_option("--sheriff-id", sheriff_id, "keyed: this sheriff's sender id (default: random per session)");
  util::add_common_options(app, common, /*with_config=*/false);
  CLI11_PARSE(app, argc, argv);
  util::init_logging("aerie-sheriff", common.log_level);

  try {
    if (config_path.empty() && !observe) throw std::invalid_argument("give a config file, or --observe to only watch");
    if (!script.empty() && observe) throw std::invalid_argument("--script cannot be used with --observe");
    if (!observe && key_path.empty() && !insecure)
      throw std::invalid_argument(
          "refusing to send orders without a key: give the mission key with --key FILE (aerie-keys generate --out "
          "FILE; the deputies need the same file), or --insecure for libbot2's unauthenticated PMD_ORDERS2 on a "
          "trusted network (docs/procman.md \"Keyed mode\")");
    if (!key_path.empty() && insecure) throw std::invalid_argument("--key and --insecure contradict each other: give one");
    std::unique_ptr<procman::OrdersSigner> signer;
    std::unique_ptr<seal::SecretKey> orders_key;  // to recognise other keyed sheriffs
    std::string fingerprint;
    if (!key_path.empty()) {
      const seal::SecretKey key = seal::load_key(key_path);
      while (sheriff_id == 0) sheriff_id = static_cast<uint32_t>(std::random_device{}() & 0x7fffffff);
      signer = std::make_unique<procman::OrdersSigner>(key, sheriff_id);
      orders_key = std::make_unique<seal::SecretKey>(procman::derive_orders_key(key));
      fingerprint = seal::fingerprint(key);
      spdlog::info("keyed: sheriff '{}' id {}, key {} ({}), orders on {}", name, sheriff_id, fingerprint, key_path,
                   procman::kSealedOrdersChannel);
    } else if (!observe) {
      spdlog::warn("INSECURE (libbot2-compatible): unauthenticated orders on {}; any host on this LCM network can "
                   "give the deputies orders", procman::kOrdersChannel);
    }
    procman::PmdConfig config;
    if (!config_path.empty()) config = procman::load_pmd(config_path);
    procman::Sheriff sheriff(name, observe, deputy_timeout_s);
    if (!observe) sheriff.load(config);

    bus::Bus bus(common.lcm_url);
    bus.subscribe<bot_procman::info2_t>(procman::kInfoChannel, [&](const bot_procman::info2_t& m, const auto&) {
      sheriff.on_info(m, mono_ms());
    }, 200);
    bus.subscribe<bot_procman::printf_t>(procman::kPrintfChannel, [&](const bot_procman::printf_t& m, const auto&) {
      if (!show_output) return;
      std::string who = m.deputy_name;
      if (m.sheriff_id != 0) {
        const auto* c = sheriff.find(m.deputy_name, m.sheriff_id);
        who += ":" + (c ? c->cmd.command_name : std::to_string(m.sheriff_id));
      }
      std::istringstream lines(m.text);
      for (std::string l; std::getline(lines, l);) std::cout << "[" << who << "] " << l << "\n";
      std::cout.flush();
    }, 1000);
    // Another keyed sheriff giving orders: say it once per sheriff (the deputies follow one).
    std::set<uint32_t> rivals;
    if (orders_key) {
      bus.subscribe_raw(procman::kSealedOrdersChannel, [&](const uint8_t* data, size_t size, const auto&) {
        procman::VerifiedOrders v;
        if (procman::verify_sealed_orders(*orders_key, {data, size}, v) != procman::OrdersRefusal::None) return;
        if (v.leaving || v.sender == sheriff_id || rivals.size() >= 64 || !rivals.insert(v.sender).second) return;
        spdlog::error("two sheriffs: '{}' (id {}) also gives orders to deputy '{}' with this key; a deputy obeys "
                      "only one of them: stop one, or run it with --observe", v.orders.sheriff_name, v.sender,
                      v.orders.host);
      });
    }

    const bool tty = isatty(STDOUT_FILENO) && !no_table;
    const bool typed = isatty(STDIN_FILENO) && script.empty();
    std::unique_ptr<procman::ScriptRunner> runner;
    auto log = [](const std::string& m) {
      std::cout << "script: " << m << std::endl;
    };
    bool script_pending = !script.empty();
    if (script_pending) {
      // Check the name now, so a typo fails at once.
      procman::ScriptRunner check(sheriff, config, script);
    }

    bus::install_stop_handlers();
    std::mt19937_64 rng(std::random_device{}());
    const int64_t nonce = static_cast<int64_t>(rng() >> 1);
    const int64_t t0 = mono_ms();
    int64_t next_orders = t0, next_table = t0, next_discovery = t0;
    int discoveries = 0;
    std::map<std::pair<std::string, int32_t>, procman::CommandStatus> last_status;
    bool quit = false;
    int exit_code = 0;
    std::string typed_reply;

    while (!bus::stop_requested() && !quit) {
      int64_t now = mono_ms();
      // Ask every deputy for an immediate report (a few times: UDP may drop one).
      if (discoveries < 3 && now >= next_discovery) {
        bot_procman::discovery_t d;
        d.utime = util::wall_utime();
        d.host = name;
        d.nonce = nonce;
        bus.publish(procman::kDiscoverChannel, d);
        ++discoveries;
        next_discovery = now + 300;
      }
      if (script_pending) {
        bool all = true;
        std::string missing;
        for (const auto& h : config.hosts())
          if (!sheriff.deputy_alive(h, now)) {
            all = false;
            missing += (missing.empty() ? "" : ", ") + h;
          }
        if (all) {
          runner = std::make_unique<procman::ScriptRunner>(sheriff, config, script, log, wait_timeout_s);
          script_pending = false;
        } else if (now - t0 > static_cast<int64_t>(deputy_wait_s * 1000)) {
          spdlog::error("no report from deputy {} after {} s: is aerie-deputy --name running there, on the same "
                        "LCM network?", missing, deputy_wait_s);
          exit_code = 3;
          break;
        }
      }
      if (runner && runner->status() == procman::ScriptRunner::Status::Running) {
        const auto st = runner->step(now);
        if (st != procman::ScriptRunner::Status::Running) {
          if (st == procman::ScriptRunner::Status::Done) std::cout << "script: done" << std::endl;
          else exit_code = 1;
          if (on_complete == "exit") break;
        }
      }
      if (sheriff.take_dirty() || now >= next_orders) {
        for (const auto& o : sheriff.orders(util::wall_utime())) {
          if (signer) {
            const auto sealed = signer->sign(o, util::wall_utime());
            bus.publish_raw(procman::kSealedOrdersChannel, sealed.data(), sealed.size());
          } else {
            bus.publish(procman::kOrdersChannel, o);
          }
        }
        next_orders = now + 1000;
      }
      // State changes, one line each (what a log or a test reads).
      for (const auto& c : sheriff.commands()) {
        const auto s = sheriff.status(c, now);
        auto& prev = last_status[{c.host, c.sheriff_id}];
        if (s != prev && !tty)
          std::cout << c.host << "/" << c.cmd.command_name << ": " << procman::to_string(prev) << " -> "
                    << procman::to_string(s) << std::endl;
        prev = s;
      }
      if (tty && now >= next_table) {
        std::cout << "\x1b[H\x1b[2J" << "aerie-sheriff " << (observe ? "(observer) " : "") << config_path
                  << (signer ? "  [keyed, key " + fingerprint + ", id " + std::to_string(sheriff_id) + "]"
                             : observe ? std::string() : std::string("  [INSECURE: libbot2 mode]"))
                  << "\n\n"
                  << sheriff.table(now);
        if (!typed_reply.empty()) std::cout << "\n" << typed_reply << "\n";
        if (typed) std::cout << "\n> " << std::flush;
        next_table = now + static_cast<int64_t>(table_period_s * 1000);
      }

      std::vector<pollfd> fds{{bus.fileno(), POLLIN, 0}};
      if (typed) fds.push_back({STDIN_FILENO, POLLIN, 0});
      int64_t timeout = std::min(next_orders, tty ? next_table : next_orders) - now;
      if (discoveries < 3) timeout = std::min(timeout, next_discovery - now);
      if (runner) {
        const int t = runner->next_timer_ms(now);
        if (t >= 0) timeout = std::min<int64_t>(timeout, t);
      }
      if (script_pending) timeout = std::min<int64_t>(timeout, 100);
      poll(fds.data(), fds.size(), static_cast<int>(std::max<int64_t>(0, timeout)));
      if (fds[0].revents & POLLIN) {
        for (int k = 0; k < 200 && bus.handle(0) > 0; ++k) {
        }
      }
      if (typed && (fds[1].revents & (POLLIN | POLLHUP))) {
        std::string line;
        if (!std::getline(std::cin, line)) {
          quit = true;
        } else {
          typed_reply = interactive(line, sheriff, config, runner, quit);
          next_table = mono_ms();
        }
      }
    }
    if (signer) {
      // "Leaving": the deputies that follow this sheriff may follow the next one at once
      // (twice: a lost datagram only delays that to the deputy's --sheriff-handover).
      for (int k = 0; k < 2; ++k)
        for (const auto& o : sheriff.orders(util::wall_utime())) {
          const auto sealed = signer->sign(o, util::wall_utime(), /*leaving=*/true);
          bus.publish_raw(procman::kSealedOrdersChannel, sealed.data(), sealed.size());
        }
    }
    if (runner && runner->status() == procman::ScriptRunner::Status::Failed)
      std::cerr << "script \"" << script << "\" failed: " << runner->error() << std::endl;
    if (!tty) std::cout << "\n" << sheriff.table(mono_ms()) << std::flush;
    return exit_code;
  } catch (const std::exception& e) {
    spdlog::critical("{}", e.what());
    return 1;
  }
}
