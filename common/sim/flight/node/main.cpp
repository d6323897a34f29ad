// aerie-flightsim: the closed-loop flight simulator as an LCM node. It publishes IMU,
// CAM_DOWN (and CAM_STEREO), GT_POSE, GT_TRACK and SIM_STATE, and moves the vehicle by
// CTRL_CMD alone; lock-step (default) or real time. At the end of the flight it prints
// one line: landed or not, touchdown error, yaw error, time. See docs/sim.md.
#include <spdlog/spdlog.h>

#include <CLI/CLI.hpp>
#include <chrono>
#include <thread>

#include "common/bus/deployment.hpp"
#include "common/bus/node.hpp"
#include "common/mavlink/signing.hpp"
#include "common/mavlink/transport.hpp"
#include "common/sim/autopilot/mavlink_face.hpp"
#include "common/sim/flight/flight_config.hpp"
#include "common/sim/flight/node/flightsim_node.hpp"
#include "common/util/cli.hpp"
#include "common/util/time.hpp"

using namespace aerie;

int main(int argc, char** argv) {
  CLI::App app{"aerie-flightsim: closed-loop flight simulator (CTRL_CMD -> IMU, CAM_DOWN, CAM_STEREO, GT_*, SIM_STATE)"};
  util::CommonOptions common;
  common.config = "config/sim/landing_room.yaml";
  util::add_common_options(app, common);
  std::string mode = "lockstep";
  double speed = 1.0, timeout = 5.0, wind = -1, linger = 1.0;
  int64_t seed = -1;
  std::string vibration;
  std::vector<std::string> answers{"CTRL_CMD"};
  bool stereo = false;
  std::string result_path, autopilot, mavlink_spec, mavlink_key;
  bool insecure = false;
  app.add_option("--mode", mode, "lockstep: frame k+1 only after every answer channel answered frame k; "
                                 "realtime: frames at wall-clock rate")
      ->check(CLI::IsMember({"lockstep", "realtime"}));
  app.add_option("--speed", speed, "real-time factor (realtime mode)")->check(CLI::PositiveNumber);
  app.add_option("--answer", answers, "lock-step answer channels (default CTRL_CMD)");
  app.add_option("--answer-timeout", timeout, "wall seconds to wait for an answer before counting a timeout")
      ->check(CLI::PositiveNumber);
  app.add_option("--seed", seed, "seed of placement, wind, vibration, IMU and image noise (overrides the config)");
  app.add_option("--wind", wind, "mean wind in m/s (gusts 0.3 x that; overrides the config)");
  app.add_option("--vibration", vibration, "camera vibration on|off (overrides the config)")
      ->check(CLI::IsMember({"on", "off"}));
  app.add_flag("--stereo", stereo, "also render and publish the forward stereo pair (CAM_STEREO)");
  app.add_option("--linger", linger, "seconds to keep publishing after the flight ended");
  app.add_option("--result", result_path, "also write the one-line result into this file");
  app.add_option("--autopilot", autopilot, "put the vehicle behind a simulated autopilot that speaks MAVLink 2: px4 or "
                                           "ardupilot (ArduCopter); CTRL_CMD is then ignored (docs/mavlink.md)")
      ->check(CLI::IsMember({"px4", "ardupilot"}));
  app.add_option("--mavlink", mavlink_spec, "the autopilot's MAVLink endpoint, e.g. udp-listen:127.0.0.1:14540 "
                                            "(aerie-mavlink --autopilot udp:127.0.0.1:14540) or serial:/dev/pts/N:921600");
  app.add_option("--mavlink-key", mavlink_key, "the autopilot's signing key (32 bytes, mode 0600): it then signs and "
                                               "refuses unsigned frames, as PX4 once a key is set up");
  app.add_flag("--insecure", insecure, "let the simulated autopilot run without a signing key");
  CLI11_PARSE(app, argc, argv);
  util::init_logging("flightsim", common.log_level);
  try {
    const util::Config cfg = common.config.empty() ? util::Config() : util::Config::load(common.config);
    sim::FlightSimConfig fc = sim::load_flight_config(cfg);
    if (seed >= 0) fc.seed = static_cast<uint64_t>(seed);
    if (wind >= 0) fc.wind.mean_m_s = wind;
    if (!vibration.empty()) fc.vibration.enabled = vibration == "on";
    if (stereo) fc.stereo = true;
    sim::FlightSim simulator(fc);
    bus::require_host_local_commands("aerie-flightsim", "CTRL_CMD", common.lcm_url);
    bus::Bus bus(common.lcm_url);
    bus::StatusReporter status(bus, "flightsim");
    const bool lockstep = mode == "lockstep";
    sim::FlightSimNodeOptions opt;
    opt.answer_channels = answers;
    opt.answer_timeout_s = timeout;
    // Behind a simulated autopilot the vehicle obeys MAVLink alone; a frame is then answered by time.
    std::optional<sim::autopilot::MavlinkFace> face;
    std::unique_ptr<mavlink::Endpoint> endpoint;
    if (!autopilot.empty()) {
      if (mavlink_spec.empty()) throw std::runtime_error("--autopilot needs --mavlink ENDPOINT");
      if (mavlink_key.empty() && !insecure)
        throw std::runtime_error("--autopilot: no --mavlink-key (or --insecure to let anyone command the vehicle)");
      if (lockstep) throw std::runtime_error("--autopilot runs in --mode realtime (lock-step flights through MAVLink: "
                                             "aerie-bench-landing --via)");
      face.emplace(autopilot == "px4" ? sim::autopilot::Personality::Px4 : sim::autopilot::Personality::ArduCopter,
                   sim::autopilot::airframe_params(fc.vehicle, fc.seed));
      if (!mavlink_key.empty()) face->enable_signing(mavlink::load_key(mavlink_key), mavlink::signing_time_now);
      endpoint = mavlink::open_endpoint(mavlink_spec);
      opt.command_channel.clear();
      opt.answer_channels.clear();
      spdlog::info("behind a simulated {} autopilot on {} ({})", autopilot, mavlink_spec,
                   mavlink_key.empty() ? "INSECURE: unsigned" : "signed");
    }
    sim::FlightSimNode node(bus, simulator, opt);
    std::vector<uint8_t> bytes;
    // The autopilot reads what came in, acts on the vehicle's state and answers, once per frame.
    auto autopilot_step = [&] {
      if (!face) return;
      bytes.clear();
      endpoint->read(bytes);
      face->receive(bytes, simulator.time());
      const auto out = face->step(simulator.time(), simulator.vehicle().state());
      simulator.command(sim::autopilot::command_input(out.command));
      if (!out.bytes.empty()) endpoint->write(out.bytes);
    };
    bus::install_stop_handlers();
    spdlog::info("{} world, seed {}, wind {} m/s, vibration {}, {} at {} Hz", fc.world.kind, fc.seed, fc.wind.mean_m_s,
                 fc.vibration.enabled ? "on" : "off", lockstep ? "lock-step" : "real time", fc.frame_rate_hz);
    const int64_t wall0 = util::wall_utime();
    // Real time: message time is wall time, so that latency tools and other nodes' clocks agree.
    if (!lockstep && fc.start_utime == 0) simulator.set_start_utime(wall0);
    double ended_at = -1;
    std::string touchdown_mode;  // the simulated autopilot's mode when the flight ended
    while (!bus::stop_requested()) {
      const auto& f = node.publish_next();
      autopilot_step();
      if (lockstep) {
        node.wait_answers();
      } else {
        const int64_t due = wall0 + static_cast<int64_t>((f.t + 1.0 / fc.frame_rate_hz) / speed * 1e6);
        for (int64_t now = util::wall_utime(); now < due && !bus::stop_requested(); now = util::wall_utime())
          bus.handle(static_cast<int>(std::max<int64_t>(1, (due - now) / 1000)));
      }
      node.report(status);
      status.tick();
      if (simulator.outcome().ended() && ended_at < 0) {
        ended_at = f.t;
        if (face) touchdown_mode = face->autopilot().mode_name();
      }
      if (ended_at >= 0 && f.t >= ended_at + linger) break;
    }
    const auto& o = simulator.outcome();
    const sim::LandingScore score = sim::score_landing(simulator);
    char line[256];
    if (o.landed)
      std::snprintf(line, sizeof line,
                    "LANDED (%s) after %.1f s: touchdown error %.3f m, yaw error %.1f deg, %lld lock-step timeouts",
                    score.success ? "success" : "outside the success bounds", score.time_s, score.touchdown_error_m,
                    score.yaw_error_deg, static_cast<long long>(node.lockstep_timeouts()));
    else
      std::snprintf(line, sizeof line, "NOT LANDED (%s) after %.1f s",
                    o.collided ? ("collision: " + o.collision).c_str() : o.timed_out ? "timed out" : "stopped",
                    simulator.time());
    std::string result = line;
    if (face)
      result += std::string(", through MAVLink to a simulated ") + (autopilot == "px4" ? "PX4" : "ArduCopter") +
                " (" + touchdown_mode + " at the end)";
    std::printf("flightsim: %s\n", result.c_str());
    if (!result_path.empty()) {
      std::FILE* f = std::fopen(result_path.c_str(), "w");
      if (!f) throw std::runtime_error("--result: cannot write '" + result_path + "'");
      std::fprintf(f, "%s\n", result.c_str());
      std::fclose(f);
    }
    return 0;
  } catch (const std::exception& e) {
    spdlog::error("{}", e.what());
    return 1;
  }
}
