// aerie-control-sim: the simulated vehicle at the other end of CTRL_CMD, for demos and
// closed-loop checks of aerie-control over LCM. Runs the heading + forward-flight model
// (common/sim/vehicle) in real time, applies the latest CTRL_CMD (hover modes stop the
// vehicle), publishes GT_POSE (z-up world: x right, y toward the wall, camera looking
// along the heading) at the camera rate, and reports the zones of thesis Fig. 5.2.
// Message time (utime) is simulation time.
#include <aerie/control_cmd_t.hpp>
#include <aerie/gt_pose_t.hpp>
#include <spdlog/spdlog.h>

#include <CLI/CLI.hpp>
#include <Eigen/Geometry>
#include <cmath>

#include "common/bus/bus.hpp"
#include "common/bus/channels.hpp"
#include "common/bus/node.hpp"
#include "common/bus/status.hpp"
#include "common/sim/vehicle/avoidance.hpp"
#include "common/sim/vehicle/scenario_config.hpp"
#include "common/util/cli.hpp"
#include "common/util/time.hpp"

using namespace aerie;

int main(int argc, char** argv) {
  CLI::App app{"aerie-control-sim: simulated multirotor driven by CTRL_CMD, publishing GT_POSE (thesis 5.1.5 model)"};
  util::CommonOptions common;
  util::add_common_options(app, common);
  std::string vehicle = "ardrone";
  double rate_hz = 30.0, duration_s = 0.0, start_y = 1.0;
  int substeps = 10;
  std::string pose_channel = channels::kGtPose, command_channel = channels::kCtrlCmd;
  app.add_option("--pose-channel", pose_channel, "channel for the vehicle's aerie.gt_pose_t (another name keeps it apart from a scene simulator's GT_POSE)");
  app.add_option("--command-channel", command_channel, "channel of the aerie.control_cmd_t commands");
  app.add_option("--vehicle", vehicle, "ardrone or pelican (or scenario.vehicle of --config, a ceopt-style YAML)");
  app.add_option("--rate", rate_hz, "GT_POSE rate (Hz)");
  app.add_option("--duration", duration_s, "stop after this simulated time (s); 0 = until Ctrl-C");
  app.add_option("--start-y", start_y, "start distance along y (m); the wall is at scene.wall_m (default 5)");
  CLI11_PARSE(app, argc, argv);
  util::init_logging("control-sim", common.log_level);
  try {
    sim::AvoidanceConfig scen;
    if (!common.config.empty()) {
      scen = sim::avoidance_config_from(util::Config::load(common.config).section("scenario"));
    } else {
      scen.vehicle = sim::VehicleParams::by_name(vehicle);
    }
    if (!(rate_hz > 0.0)) throw std::invalid_argument("--rate must be positive");
    const double dt = 1.0 / (rate_hz * substeps);
    sim::VehicleState s0;
    s0.y = start_y;
    sim::Vehicle v(scen.vehicle, dt, s0);

    bus::Bus bus(common.lcm_url);
    bus::StatusReporter status(bus, "control-sim");
    aerie::control_cmd_t cmd{};
    cmd.mode = aerie::control_cmd_t::HOVER;
    bus.subscribe<aerie::control_cmd_t>(command_channel, [&](const aerie::control_cmd_t& m, const bus::ReceiveInfo&) {
      if (!std::isfinite(m.yaw_rate_deg_s) || !std::isfinite(m.velocity_body[0])) {
        status.count("bad_commands");
        return;
      }
      cmd = m;
      status.count("commands");
    });
    spdlog::info("vehicle {} from y = {} m, wall at {} m, dangerous area from {} m; poses on {} at {} Hz", scen.vehicle.name, start_y,
                 scen.scene.wall_y_m, scen.scene.dangerous_from(), pose_channel, rate_hz);

    const int64_t t0 = util::wall_utime();
    long steps = 0;
    int64_t seq = 0;
    double max_y = start_y;
    bool dangerous = false;
    bus::run(bus, status, [&] {
      const double now = static_cast<double>(util::wall_utime() - t0) * 1e-6;
      while (steps * dt < now) {
        const bool active = cmd.mode == aerie::control_cmd_t::ACTIVE;
        v.step(active ? cmd.yaw_rate_deg_s : 0.0, active ? cmd.velocity_body[0] : 0.0);
        ++steps;
        const auto& st = v.state();
        max_y = std::max(max_y, st.y);
        if (!dangerous && st.y >= scen.scene.dangerous_from()) {
          dangerous = true;
          status.warn("entered the dangerous alarm area");
          spdlog::warn("entered the dangerous alarm area at y = {:.2f} m", st.y);
        }
        if (steps % substeps == 0) {
          const double h = st.heading_deg * M_PI / 180.0;
          Eigen::Matrix3d r;  // camera axes in the world: x right, y down, z along the heading
          r.col(0) = Eigen::Vector3d(std::cos(h), -std::sin(h), 0);
          r.col(1) = Eigen::Vector3d(0, 0, -1);
          r.col(2) = Eigen::Vector3d(std::sin(h), std::cos(h), 0);
          const Eigen::Quaterniond q(r);
          aerie::gt_pose_t p{};
          p.utime = static_cast<int64_t>(std::llround(steps * dt * 1e6));
          p.seq = seq++;
          p.frame_id = "sim";
          p.position[0] = st.x;
          p.position[1] = st.y;
          p.position[2] = 1.0;
          p.orientation[0] = q.w();
          p.orientation[1] = q.x();
          p.orientation[2] = q.y();
          p.orientation[3] = q.z();
          bus.publish(pose_channel, p);
          status.set("min_wall_distance_mm", std::llround((scen.scene.wall_y_m - max_y) * 1000));
          status.set("heading_mdeg", std::llround(st.heading_deg * 1000));
        }
      }
      return duration_s <= 0.0 || now < duration_s;
    }, 2);
    const auto& st = v.state();
    spdlog::info("end: x {:.2f} m, y {:.2f} m, heading {:.1f} deg, min wall distance {:.2f} m{}", st.x, st.y, st.heading_deg,
                 scen.scene.wall_y_m - max_y, dangerous ? " (entered the dangerous area)" : "");
    return 0;
  } catch (const std::exception& e) {
    spdlog::error("{}", e.what());
    return 1;
  }
}
