// aerie-pilot's handlers (air/pilot/node/pilot_node.hpp) fed TARGET_POSE, TRACK, IMU and
// PILOT_CMD messages over memq:// (fuzz_support.hpp: kPilotChannels; record format there), with
// config/pilot.yaml: the bounded decoder, then the flight manager's state machine (take-off,
// survey, acquire, approach, descend, land, HOLD/ABORT), the landing controller and the
// CTRL_CMD / PILOT_STATE it publishes; the status report after each.
#include "air/pilot/node/pilot_node.hpp"
#include "air/pilot/pilot_config.hpp"
#include "common/util/config.hpp"
#include "fuzz/fuzz_support.hpp"

namespace {

using namespace aerie;

const pilot::PilotConfig& config() {
  static const pilot::PilotConfig c =
      pilot::load_pilot_config(util::Config::load(fuzz::source_path("config/pilot.yaml")));
  return c;
}

}  // namespace

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
  fuzz::quiet();
  bus::Bus bus("memq://");
  bus::StatusReporter status(bus, "pilot");
  const auto& ch = fuzz::kPilotChannels;
  pilot::PilotNodeOptions options;
  options.target_channel = ch[0];
  options.track_channel = ch[1];
  options.imu_channel = ch[2];
  options.operator_channel = ch[3];
  pilot::PilotNode node(bus, config(), options);
  fuzz::publish_records(bus, ch, data, size, [&] { node.report(status); });
  return 0;
}
