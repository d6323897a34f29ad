// The YAML configuration loader (common/util/config.hpp: util::Config::parse, duplicate keys,
// check_keys, typed and ranged reads) on the input as a config file, then every node's reader
// of it, where it touches no other file: aerie-control (node_setup; its `controller` file is
// overridden as on the command line), aerie-nav, aerie-pilot (unless `fuzzy_rules` names a
// file), aerie-map (MapServiceConfig), aerie-link (load_link_config: the link configuration),
// aerie-track (node_options, which builds every tracker of `trackers.*` with its parameters;
// unless `camera.calibration` names a file), aerie-vo (load_vo_node_config and the odometry's
// validate), aerie-capture (load_capture_config), aerie-sim (load_simulation_config),
// aerie-flightsim (load_flight_config, which validates) and aerie-ceopt (ceopt_config_from,
// unless `controller` names a file; landing_tuning_config_from).
#include "air/capture/capture_node.hpp"
#include "air/control/control_config.hpp"
#include "air/nav/nav_config.hpp"
#include "air/pilot/pilot_config.hpp"
#include "air/stereo/node/vo_node.hpp"
#include "air/track/node/track_node.hpp"
#include "common/sim/flight/flight_config.hpp"
#include "common/sim/sim_config.hpp"
#include "common/util/config.hpp"
#include "fuzz/fuzz_support.hpp"
#include "ground/ceopt/landing_tuning.hpp"
#include "ground/ceopt/pipeline.hpp"
#include "ground/map/map_service.hpp"
#include "tools/link/link_config.hpp"

namespace {

using namespace aerie;

// Reads every top-level key the generic ways a node does.
void read_generically(const util::Config& cfg) {
  if (!cfg.node().IsMap()) return;
  for (const auto& kv : cfg.node()) {
    const std::string key = kv.first.Scalar();
    fuzz::refusal_ok([&] { cfg.get<double>(key, 0.0); });
    fuzz::refusal_ok([&] { cfg.get_in<int>(key, 0, -100, 100); });
    fuzz::refusal_ok([&] { cfg.get<std::string>(key, ""); });
    fuzz::refusal_ok([&] { cfg.get<std::vector<double>>(key, {}); });
    fuzz::refusal_ok([&] { cfg.section(key).check_keys({"a", "b.c", "d.*"}); });
  }
}

}  // namespace

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
  fuzz::quiet();
  util::Config cfg;
  try {
    cfg = util::Config::parse(fuzz::as_text(data, size), "input.yaml");
  } catch (const std::runtime_error&) {
    return 0;
  }
  read_generically(cfg);
  static const control::CliOverrides cli = [] {
    control::CliOverrides c;
    c.controller = fuzz::source_path("config/flc/initial.yaml");
    return c;
  }();
  fuzz::refusal_ok([&] { control::node_setup(cfg, cli); });
  fuzz::refusal_ok([&] { nav::load_nav_config(cfg); });
  fuzz::refusal_ok([&] {
    if (cfg.get<std::string>("fuzzy_rules", "").empty()) pilot::load_pilot_config(cfg);
  });
  fuzz::refusal_ok([&] { map::MapServiceConfig::from_config(cfg); });
  fuzz::refusal_ok([&] { link::load_link_config(cfg); });
  fuzz::refusal_ok([&] {
    if (!cfg.section("camera").has("calibration")) track::node_options(cfg);
  });
  fuzz::refusal_ok([&] { stereo::load_vo_node_config(cfg).vo.validate(); });
  fuzz::refusal_ok([&] { capture::load_capture_config(cfg); });
  fuzz::refusal_ok([&] { sim::load_simulation_config(cfg); });
  fuzz::refusal_ok([&] { sim::load_flight_config(cfg); });
  fuzz::refusal_ok([&] {
    if (cfg.get<std::string>("controller", "").empty()) ceopt::ceopt_config_from(cfg);
  });
  fuzz::refusal_ok([&] { ceopt::landing_tuning_config_from(cfg); });
  return 0;
}
