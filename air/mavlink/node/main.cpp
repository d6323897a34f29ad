// aerie-mavlink: Aerie's bridge to a PX4 or ArduPilot autopilot over MAVLink 2 (docs/mavlink.md).
// CTRL_CMD, NAV_STATE, TARGET_POSE, PILOT_STATE -> setpoints, ODOMETRY, LANDING_TARGET, commands;
// the autopilot -> AUTOPILOT_STATE (and IMU); ground stations routed through. Status on STATUS_MAVLINK.
#include <spdlog/spdlog.h>

#include <CLI/CLI.hpp>
#include <chrono>
#include <cstdio>
#include <optional>
#include <thread>

#include "air/mavlink/autopilot_link.hpp"
#include "air/mavlink/node/mavlink_node.hpp"
#include "air/mavlink/preflight.hpp"
#include "common/bus/deployment.hpp"
#include "common/mavlink/transport.hpp"
#include "common/mavlink/signing.hpp"
#include "common/util/cli.hpp"
#include "common/util/time.hpp"

using namespace aerie;

namespace {

// Sends SETUP_SIGNING to the autopilot over a direct link (MAVLink's "Message Signing": the key
// must only travel over a secure, direct connection: USB or a wire, never a radio), waits for
// its heartbeat first; returns the exit code.
int setup_signing(mavlink::Endpoint& autopilot, const mavlink::Key& key, const bridge::BridgeConfig& cfg) {
  mavlink::Parser parser;
  std::vector<uint8_t> buf;
  const auto until = std::chrono::steady_clock::now() + std::chrono::seconds(5);
  std::optional<mavlink::Frame> heartbeat;
  while (!heartbeat && std::chrono::steady_clock::now() < until) {
    buf.clear();
    if (autopilot.read(buf) == 0) std::this_thread::sleep_for(std::chrono::milliseconds(10));
    parser.feed(buf, [&](const mavlink::Frame& f) {
      if (f.msgid == mavlink::Heartbeat::kId && mavlink::decode<mavlink::Heartbeat>(f).autopilot !=
                                                    mavlink::mav_autopilot::kInvalid)
        heartbeat = f;
    });
  }
  if (!heartbeat) {
    spdlog::error("no autopilot heartbeat on {} within 5 s: SETUP_SIGNING not sent", autopilot.name());
    return 1;
  }
  const auto msg = mavlink::make_setup_signing(heartbeat->sysid, heartbeat->compid, key, mavlink::signing_time_now());
  autopilot.write(mavlink::encode(msg, {static_cast<uint8_t>(cfg.system_id), static_cast<uint8_t>(cfg.component_id), 0}));
  spdlog::info("SETUP_SIGNING sent to system {} component {} (key {}); the autopilot now signs and checks every link",
               heartbeat->sysid, heartbeat->compid, mavlink::fingerprint(key));
  return 0;
}

// aerie-mavlink --check (air/mavlink/preflight.hpp): the autopilot's heartbeat, version and the
// parameters that matter, over the endpoint with the wall clock; one line per item on stdout.
// Exit code 0 when nothing FAILs. With a key it signs and verifies as the bridge does, and saves
// the signing timestamp, so the bridge started next never reuses one.
int run_check(mavlink::Endpoint& autopilot, const bridge::BridgeConfig& bc, const std::optional<mavlink::Key>& key,
              uint8_t link_id, const std::string& timestamp_file) {
  bridge::PreflightCheck check(bridge::PreflightConfig::from(bc));
  if (key) check.enable_signing(*key, link_id, mavlink::load_timestamp(timestamp_file));
  spdlog::info("checking the autopilot on {} ({}, the descent flown by {}, odometry {})", autopilot.name(),
               key ? "signed, key " + mavlink::fingerprint(*key) : std::string("unsigned"),
               bc.landing_path == bridge::LandingPath::Aerie ? "Aerie" : "the autopilot",
               bc.send_odometry ? "sent" : "not sent");
  std::vector<uint8_t> buf;
  while (!check.done()) {
    const int64_t now_us = util::wall_utime();
    buf.clear();
    if (autopilot.read(buf) > 0) check.receive(buf, now_us);
    for (const auto& frame : check.poll(now_us)) autopilot.write(frame);
    if (buf.empty()) std::this_thread::sleep_for(std::chrono::milliseconds(5));
  }
  if (const auto ts = check.last_signing_timestamp()) mavlink::save_timestamp(timestamp_file, *ts);
  int counts[3] = {0, 0, 0};
  for (const auto& item : check.items()) {
    std::printf("%s\n", bridge::to_line(item).c_str());
    ++counts[static_cast<int>(item.verdict)];
  }
  std::fflush(stdout);
  spdlog::info("{} PASS, {} WARN, {} FAIL", counts[0], counts[1], counts[2]);
  return check.passed() ? 0 : 1;
}

}  // namespace

int main(int argc, char** argv) {
  CLI::App app{"aerie-mavlink: Aerie's bridge to a PX4 or ArduPilot autopilot over MAVLink 2 — velocity setpoints "
               "(offboard/GUIDED), vision odometry, landing targets, arming and modes with acknowledgement, signed "
               "links; ground stations routed through (docs/mavlink.md)"};
  util::CommonOptions common;
  common.config = "config/mavlink.yaml";
  util::add_common_options(app, common);
  std::string autopilot_spec, key_path, timestamp_path, landing;
  std::vector<std::string> ground_specs;
  bool insecure = false, publish_imu = false, do_setup_signing = false, do_check = false;
  int link_id = 0;
  app.add_option("--autopilot", autopilot_spec,
                 "the flight controller: serial:DEVICE:BAUD[:rtscts] (e.g. serial:/dev/ttyAMA0:921600:rtscts for a "
                 "Pixhawk's TELEM2), udp-listen:ADDRESS:PORT or udp:ADDRESS:PORT")
      ->required();
  app.add_option("--gcs", ground_specs, "a ground station to route to, e.g. udp:192.168.1.10:14550 (repeatable)");
  app.add_option("--key", key_path, "MAVLink signing key (32 bytes, mode 0600; make one with aerie-keys generate)");
  app.add_flag("--insecure", insecure, "run without signing: anyone on the link can command the autopilot");
  app.add_option("--timestamp-file", timestamp_path, "where the signing timestamp is kept (default: KEY.timestamp)");
  app.add_option("--link-id", link_id, "MAVLink signing link id of this connection")->check(CLI::Range(0, 255));
  app.add_option("--landing", landing, "who flies the descent: aerie (Aerie's pilot, offboard) or autopilot "
                                       "(its precision landing on LANDING_TARGET); overrides the config")
      ->check(CLI::IsMember({"aerie", "autopilot"}));
  app.add_flag("--publish-imu", publish_imu, "publish the autopilot's IMU on IMU (for aerie-nav and aerie-pilot)");
  app.add_flag("--setup-signing", do_setup_signing,
               "send the key to the autopilot with SETUP_SIGNING and exit (only over a direct wire or USB)");
  app.add_flag("--check", do_check,
               "check the autopilot's set-up for Aerie and exit: its heartbeat, version and parameters (PARAM_REQUEST_READ), "
               "one PASS/WARN/FAIL line each with the fix; exit code 1 when one FAILs (signs with --key)");
  CLI11_PARSE(app, argc, argv);
  util::init_logging("mavlink", common.log_level);
  try {
    const util::Config cfg = common.config.empty() ? util::Config() : util::Config::load(common.config);
    bridge::BridgeConfig bc = bridge::load_bridge(cfg);
    if (!landing.empty()) bc.landing_path = landing == "autopilot" ? bridge::LandingPath::Autopilot : bridge::LandingPath::Aerie;
    if (key_path.empty() && !insecure && !do_check)
      throw std::runtime_error("no signing key: give --key FILE (aerie-keys generate --out FILE makes one), or "
                               "--insecure to let anyone on the link command the autopilot");
    auto autopilot = mavlink::open_endpoint(autopilot_spec);
    std::optional<mavlink::Key> key;
    if (!key_path.empty()) key = mavlink::load_key(key_path);
    if (do_setup_signing) {
      if (!key) throw std::runtime_error("--setup-signing needs --key");
      return setup_signing(*autopilot, *key, bc);
    }
    if (do_check)
      return run_check(*autopilot, bc, key, static_cast<uint8_t>(link_id),
                       timestamp_path.empty() ? key_path + ".timestamp" : timestamp_path);
    std::vector<std::unique_ptr<mavlink::Endpoint>> ground;
    for (const auto& spec : ground_specs) ground.push_back(mavlink::open_endpoint(spec));

    bridge::AutopilotLink link(bc);
    bridge::MavlinkNodeOptions opt;
    opt.publish_imu = publish_imu;
    if (key) {
      opt.timestamp_file = timestamp_path.empty() ? key_path + ".timestamp" : timestamp_path;
      link.enable_signing(*key, static_cast<uint8_t>(link_id), mavlink::load_timestamp(opt.timestamp_file));
      spdlog::info("signing with key {} (link id {}), unsigned frames refused", mavlink::fingerprint(*key), link_id);
    } else {
      spdlog::warn("INSECURE: MAVLink signing is off; anyone on {} can command the autopilot", autopilot_spec);
    }
    bus::require_host_local_commands("aerie-mavlink", "CTRL_CMD", common.lcm_url);
    bus::Bus bus(common.lcm_url);
    bridge::MavlinkNode node(bus, std::move(link), std::move(autopilot), std::move(ground), opt);
    spdlog::info("autopilot on {}, {} ground station(s), the descent flown by {}", autopilot_spec, ground_specs.size(),
                 bc.landing_path == bridge::LandingPath::Aerie ? "Aerie" : "the autopilot");
    bus::run(node, 5);  // 5 ms: the endpoints are read between LCM messages
    return 0;
  } catch (const std::exception& e) {
    spdlog::error("{}", e.what());
    return 1;
  }
}
