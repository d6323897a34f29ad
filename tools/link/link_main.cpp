// aerie-link: the air-ground radio link in user space, in two modes (docs/link.md):
//  * --half air|ground: one half of the door (tools/link/door_node.hpp) -- its host's LCM
//    joined to a sealed UDP link towards the other half; refuses to start without --key
//    unless --insecure is said;
//  * without --half: the emulator, relaying LCM channels between the air network and the
//    ground network in one process (one regex per direction).
// Both apply delay, jitter, loss, a bandwidth cap with a bounded queue, optional reordering
// and optional JPEG re-encoding of images, and publish LINK_STATS once a period.
#include <aerie/link_stats_t.hpp>
#include <fcntl.h>
#include <poll.h>
#include <sched.h>
#include <unistd.h>
#include <spdlog/spdlog.h>

#include <CLI/CLI.hpp>
#include <algorithm>
#include <chrono>
#include <cerrno>
#include <cmath>
#include <cstring>
#include <deque>
#include <unordered_set>

#include "common/bus/bus.hpp"
#include "common/bus/node.hpp"
#include "common/util/cli.hpp"
#include "common/util/time.hpp"
#include "common/seal/keys.hpp"
#include "tools/link/door_node.hpp"
#include "tools/link/link_config.hpp"
#include "tools/link/link_model.hpp"
#include "tools/latency/stats.hpp"
#include "tools/link/relay.hpp"
#include "tools/link/echo_filter.hpp"

namespace {

using namespace aerie;

int64_t mono_us() {
  return std::chrono::duration_cast<std::chrono::microseconds>(std::chrono::steady_clock::now().time_since_epoch())
      .count();
}

using link::EchoFilter;

struct Side {
  std::string name;
  std::unique_ptr<bus::Bus> bus;
  EchoFilter echo;
};

struct Route {
  link::Relay relay;
  Side* from;
  Side* to;
  link::ChannelMatcher reverse;  // the other direction's channels: only those can echo back
  std::vector<double> delays_ms;  // achieved over the stats period
  int64_t bytes_at_period_start = 0;
};

}  // namespace

int main(int argc, char** argv) {
  CLI::App app{
      "aerie-link: emulates the air-ground radio link between two LCM networks (delay, jitter,\n"
      "loss, bandwidth cap, reordering, JPEG re-encoding); publishes LINK_STATS. See docs/link.md."};
  util::CommonOptions common;
  std::string air_url, ground_url;
  std::optional<uint64_t> seed;
  std::optional<double> delay_ms, jitter_ms, loss, bandwidth_kbps;
  app.add_option("-c,--config", common.config, "YAML configuration (config/link.yaml)")->check(CLI::ExistingFile);
  app.add_option("--air-url", air_url, "LCM URL of the air network (overrides the config)");
  app.add_option("--ground-url", ground_url, "LCM URL of the ground network (overrides the config)");
  app.add_option("--seed", seed, "random seed (both directions; overrides the config)");
  app.add_option("--delay-ms", delay_ms, "propagation delay, both directions");
  app.add_option("--jitter-ms", jitter_ms, "jitter (standard deviation), both directions");
  app.add_option("--loss", loss, "Bernoulli loss probability, both directions");
  app.add_option("--bandwidth-kbps", bandwidth_kbps, "bandwidth cap in kbit/s, both directions (0 = none)");
  int rt_priority = 0;
  app.add_option("--realtime-priority", rt_priority,
                 "run under SCHED_FIFO at this priority (1..99; needs root or CAP_SYS_NICE) so that a busy\n"
                 "host does not add scheduling delay; 0 = normal scheduling")
      ->check(CLI::Range(0, 99));
  std::string half, listen, peer, key_path, lcm_url, lcm_netns, operator_key_path;
  std::vector<std::string> operator_pubs;
  bool insecure = false;
  uint32_t first_epoch = 0;
  app.add_option("--half", half, "run one half of the door: air or ground (docs/link.md \"The two halves\")")
      ->check(CLI::IsMember({"air", "ground"}));
  app.add_option("--listen", listen, "half: ADDR:PORT of this half's UDP socket (the radio side)");
  app.add_option("--peer", peer, "half: ADDR:PORT of the other half");
  app.add_option("--key", key_path, "half: the mission key file (mode 0600; aerie-keys generate --out FILE)");
  app.add_option("--operator-key", operator_key_path,
                 "ground half: the operator's key (mode 0600; aerie-keys operator --out FILE): signs the operator's\n"
                 "commands (ground_to_air.operator_channels); without it this station only watches");
  app.add_option("--operator-pub", operator_pubs,
                 "air half: an operator's public key (FILE.pub of aerie-keys operator; repeat for several\n"
                 "ground stations): only commands signed by one of them are obeyed");
  app.add_flag("--insecure", insecure,
               "half: run WITHOUT a key -- datagrams in the clear, unauthenticated; the status says INSECURE");
  app.add_option("--lcm-url", lcm_url, "half: this host's LCM URL (default: air_url or ground_url of the config)");
  app.add_option("--lcm-netns", lcm_netns,
                 "half: open the LCM sockets in this network namespace (e.g. /run/netns/aerie-air) after the\n"
                 "UDP socket is opened in the current one (scripts/air-netns.sh; docs/security.md \"Deployment: one door\")");
  app.add_option("--first-epoch", first_epoch, "half: the sealer's first key epoch (a restarted half may start higher)");
  app.add_option("--log-level", common.log_level, "trace, debug, info, warn, error, critical or off")
      ->check(CLI::IsMember({"trace", "debug", "info", "warn", "error", "critical", "off"}));
  CLI11_PARSE(app, argc, argv);
  util::init_logging("aerie-link", common.log_level);

  try {
    link::LinkConfig cfg = link::load_link_config(common.config.empty() ? util::Config() : util::Config::load(common.config));
    if (!air_url.empty()) cfg.air_url = air_url;
    if (!ground_url.empty()) cfg.ground_url = ground_url;
    if (cfg.air_url == cfg.ground_url)
      throw std::invalid_argument("the air and ground URLs are the same (" + cfg.air_url + ")");
    for (auto* d : {&cfg.air_to_ground, &cfg.ground_to_air}) {
      if (seed) d->seed = d == &cfg.air_to_ground ? 2 * *seed - 1 : 2 * *seed;
      if (delay_ms) d->delay_ms = *delay_ms;
      if (jitter_ms) d->jitter_ms = *jitter_ms;
      if (loss) {
        d->loss_model = link::LossModel::Bernoulli;
        d->loss = *loss;
      }
      if (bandwidth_kbps) d->bandwidth_bps = *bandwidth_kbps * 1000.0;
    }

    if (!half.empty()) {
      if (listen.empty() || peer.empty())
        throw std::invalid_argument("--half " + half + " needs --listen ADDR:PORT and --peer ADDR:PORT");
      if (!key_path.empty() && insecure) throw std::invalid_argument("--key and --insecure exclude each other");
      if (key_path.empty() && !insecure) {
        spdlog::critical("refusing to start the {} half without a key: give --key FILE (aerie-keys generate --out FILE, "
                         "the same file on both hosts), or --insecure to run in the clear on purpose",
                         half);
        return 2;
      }
      std::optional<seal::SecretKey> key;
      if (!key_path.empty()) key.emplace(seal::load_key(key_path));  // refuses a file others can read
      if (rt_priority > 0) {
        sched_param sp{};
        sp.sched_priority = rt_priority;
        if (sched_setscheduler(0, SCHED_FIFO, &sp) != 0)
          spdlog::warn("cannot use SCHED_FIFO priority {}: {}", rt_priority, std::strerror(errno));
      }
      link::UdpSocket socket(listen);  // in the radio's namespace
      if (!lcm_netns.empty()) {
        const int fd = ::open(lcm_netns.c_str(), O_RDONLY | O_CLOEXEC);
        if (fd < 0) throw std::runtime_error("--lcm-netns " + lcm_netns + ": " + std::strerror(errno));
        if (setns(fd, CLONE_NEWNET) != 0) {
          const std::string why = std::strerror(errno);
          ::close(fd);
          throw std::runtime_error("--lcm-netns " + lcm_netns + ": setns: " + why);
        }
        ::close(fd);
      }
      const link::Half h = link::half_from_name(half);
      const std::string url = !lcm_url.empty() ? lcm_url : h == link::Half::kAir ? cfg.air_url : cfg.ground_url;
      bus::Bus bus(url);  // LCM's sockets, in the nodes' namespace with --lcm-netns
      link::HalfOptions opt;
      opt.half = h;
      opt.peer = peer;
      opt.first_epoch = first_epoch;
      link::CommandKeys commands;
      if (h == link::Half::kAir && !operator_key_path.empty())
        throw std::invalid_argument("--operator-key is the ground half's (the air half takes --operator-pub FILE.pub)");
      if (h == link::Half::kGround && !operator_pubs.empty())
        throw std::invalid_argument("--operator-pub is the air half's (the ground half takes --operator-key FILE)");
      if (!key && (!operator_key_path.empty() || !operator_pubs.empty()))
        throw std::invalid_argument("--operator-key/--operator-pub need --key: an --insecure door checks no signature");
      if (!operator_key_path.empty()) commands.operator_key.emplace(seal::OperatorKey::load(operator_key_path));
      for (const auto& p : operator_pubs) commands.operators.push_back(seal::OperatorPublicKey::load(p));
      link::DoorHalf door(bus, socket, cfg, opt, key ? &*key : nullptr, std::move(commands));
      const auto& o = h == link::Half::kAir ? cfg.air_to_ground : cfg.ground_to_air;
      const auto& i = h == link::Half::kAir ? cfg.ground_to_air : cfg.air_to_ground;
      spdlog::info("{} half: LCM {} <-> UDP {} (port {}) -> peer {}", half, url, listen, socket.port(), peer);
      spdlog::info("sends {} '{}'; accepts {} '{}'", o.name, o.channels, i.name, i.channels);
      if (key) spdlog::info("SECURE: key fingerprint {} (compare with the other half's)", door.fingerprint());
      else spdlog::warn("INSECURE: no key; datagrams in the clear, unauthenticated (--insecure)");
      door.run();
      return 0;
    }
    if (!listen.empty() || !peer.empty() || !key_path.empty() || insecure || !lcm_netns.empty() ||
        !operator_key_path.empty() || !operator_pubs.empty())
      throw std::invalid_argument(
          "--listen, --peer, --key, --operator-key, --operator-pub, --insecure and --lcm-netns are options of --half "
          "air|ground");

    if (rt_priority > 0) {
      // Before the LCM threads start: they inherit the policy.
      sched_param sp{};
      sp.sched_priority = rt_priority;
      if (sched_setscheduler(0, SCHED_FIFO, &sp) != 0)
        spdlog::warn("cannot use SCHED_FIFO priority {}: {} (running with normal scheduling)", rt_priority,
                     std::strerror(errno));
    }
    Side air{"air", std::make_unique<bus::Bus>(cfg.air_url), {}};
    Side ground{"ground", std::make_unique<bus::Bus>(cfg.ground_url), {}};
    std::vector<std::unique_ptr<Route>> routes;
    routes.push_back(std::make_unique<Route>(
        Route{link::Relay(cfg.air_to_ground), &air, &ground, link::ChannelMatcher(cfg.ground_to_air.channels), {}, 0}));
    routes.push_back(std::make_unique<Route>(
        Route{link::Relay(cfg.ground_to_air), &ground, &air, link::ChannelMatcher(cfg.air_to_ground.channels), {}, 0}));
    for (auto& rp : routes) {
      Route& r = *rp;
      r.from->bus->subscribe_raw(r.relay.model().config().channels, [&r, &cfg](const uint8_t* data, size_t size,
                                                                              const bus::ReceiveInfo& info) {
        if (info.channel == cfg.stats_channel) return;
        if (r.from->echo.is_echo(EchoFilter::key(info.channel, data, size))) return;
        r.relay.take(info.channel, data, size, info.recv_utime, mono_us());
      }, 10000);
    }

    spdlog::info("air {} <-> ground {}", cfg.air_url, cfg.ground_url);
    for (const auto& r : routes) {
      const auto& d = r->relay.model().config();
      spdlog::info("{}: channels '{}', delay {} ms, jitter {} ms ({}), loss {}, bandwidth {}, queue {} B, seed {}",
                   d.name, d.channels, d.delay_ms, d.jitter_ms, link::to_string(d.jitter),
                   d.loss_model == link::LossModel::Bernoulli ? std::to_string(d.loss)
                                                              : "GE mean " + std::to_string(d.gilbert_elliott.mean_loss()),
                   d.bandwidth_bps > 0 ? std::to_string(d.bandwidth_bps / 1000.0) + " kbit/s" : "unlimited",
                   d.queue_bytes, d.seed);
    }

    bus::install_stop_handlers();
    const int64_t period_us = static_cast<int64_t>(cfg.stats_period_s * 1e6);
    int64_t next_stats = mono_us() + period_us;
    int64_t stats_seq = 0;
    while (!bus::stop_requested()) {
      int64_t now = mono_us();
      int64_t wake = next_stats;
      for (const auto& r : routes)
        if (const int64_t t = r->relay.model().next_event_us(); t >= 0) wake = std::min(wake, t);
      pollfd fds[2] = {{air.bus->fileno(), POLLIN, 0}, {ground.bus->fileno(), POLLIN, 0}};
      const int64_t wait_us = std::max<int64_t>(0, wake - now);
      const timespec ts{static_cast<time_t>(wait_us / 1000000), static_cast<long>((wait_us % 1000000) * 1000)};
      ppoll(fds, 2, &ts, nullptr);
      for (int k = 0; k < 2; ++k) {
        if (!(fds[k].revents & POLLIN)) continue;
        bus::Bus& b = k == 0 ? *air.bus : *ground.bus;
        for (int n = 0; n < 1000 && b.handle(0) > 0; ++n) {
        }
      }
      now = mono_us();
      for (auto& rp : routes) {
        Route& r = *rp;
        for (auto& p : r.relay.due(now)) {
          const uint64_t k = EchoFilter::key(p.channel, p.data.data(), p.data.size());
          if (r.reverse(p.channel)) r.to->echo.sent(k, now);
          r.to->bus->publish_raw(p.channel, p.data.data(), static_cast<unsigned>(p.data.size()));
          r.delays_ms.push_back(static_cast<double>(util::wall_utime() - p.recv_wall_utime) / 1000.0);
        }
      }
      if (now >= next_stats) {
        aerie::link_stats_t s;
        s.utime = util::wall_utime();
        s.seq = stats_seq++;
        s.period_s = cfg.stats_period_s;
        for (auto& rp : routes) {
          Route& r = *rp;
          const auto& c = r.relay.model().counters();
          aerie::link_direction_stats_t d;
          d.name = r.relay.model().config().name;
          d.received = c.received;
          d.delivered = c.delivered;
          d.bytes_delivered = c.bytes_delivered;
          d.dropped_loss = c.dropped_loss;
          d.dropped_queue = c.dropped_queue;
          d.dropped_other = c.dropped_other;
          d.reencoded = c.reencoded;
          d.queue_depth = r.relay.model().queue_depth();
          d.queue_bytes = r.relay.model().queue_bytes();
          const auto delay = latency::summarize(std::move(r.delays_ms));
          d.delay_p50_ms = delay.median;
          d.delay_p90_ms = delay.p90;
          d.delay_p99_ms = delay.p99;
          d.delay_max_ms = delay.max;
          d.throughput_bps = static_cast<double>(c.bytes_delivered - r.bytes_at_period_start) * 8.0 / cfg.stats_period_s;
          r.bytes_at_period_start = c.bytes_delivered;
          r.delays_ms.clear();
          s.directions.push_back(std::move(d));
        }
        s.ndirections = static_cast<int32_t>(s.directions.size());
        if (cfg.stats_on_air) air.bus->publish(cfg.stats_channel, s);
        if (cfg.stats_on_ground) ground.bus->publish(cfg.stats_channel, s);
        next_stats += period_us;
        if (next_stats < now) next_stats = now + period_us;
      }
    }
    for (const auto& r : routes) {
      const auto& c = r->relay.model().counters();
      spdlog::info("{}: received {}, delivered {}, lost {}, queue drops {}, other drops {}, re-encoded {}, {} waiting",
                   r->relay.model().config().name, c.received, c.delivered, c.dropped_loss, c.dropped_queue, c.dropped_other,
                   c.reencoded, r->relay.model().queue_depth() + r->relay.model().in_flight());
    }
  } catch (const std::exception& e) {
    spdlog::critical("{}", e.what());
    return 1;
  }
  return 0;
}
