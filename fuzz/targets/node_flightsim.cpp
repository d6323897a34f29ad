// aerie-flightsim's handlers (common/sim/flight/node/flightsim_node.hpp) fed what it receives,
// CTRL_CMD, over memq:// (fuzz_support.hpp: kFlightSimChannels; record format there), with
// config/sim/landing_room.yaml (aerie-flightsim's default world) and --stereo as the demo runs
// it: the bounded decoder, the command's checks (mode, finite values, the vehicle's limits) and
// the autopilot, and the lock-step answer (CTRL_CMD is also the answer channel: its utime
// answers a frame). As aerie-flightsim's lock-step loop: frame 0 is published first, then after
// each message the answer is checked (answer_timeout_s 0: an unanswered frame is counted at
// once, never waited for), the status reported and the next frame stepped and published
// (physics, wind, IMU, ground truth, SIM_STATE, both cameras rendered), at most kMaxFrames per
// input.
// Each input gets a copy of one simulator built at the first input (FlightSim copies share
// the world's textures): the same initial state every time, without drawing the world and
// baking its lighting again (that was 90 % of an input's time).
// Changes for cost: both cameras render 32 x 24 pixels (rendering is most of a frame's time,
// and the config's 376 x 240 costs 118 times the rays; the fields of view are kept, so the same
// scene is seen, and no one here looks at the images), and an input steps at most kMaxFrames
// frames (5 s of flight: enough to take off, fly and land, as the seed does); the messages
// after that are still handled. A frame still costs about 0.3 ms under ASan (physics at 200 Hz,
// 10 IMU messages, three images), so an input's cost is its number of messages.
#include "common/sim/flight/flight_config.hpp"
#include "common/sim/flight/node/flightsim_node.hpp"
#include "common/util/config.hpp"
#include "fuzz/fuzz_support.hpp"

namespace {

using namespace aerie;

constexpr int kMaxFrames = 100;

const sim::FlightSim& prototype() {
  static const sim::FlightSim s = [] {
    sim::FlightSimConfig c = sim::load_flight_config(util::Config::load(fuzz::source_path("config/sim/landing_room.yaml")));
    c.stereo = true;
    for (sim::RigConfig* rig : {&c.down_camera, &c.stereo_rig}) {
      rig->width = 32;
      rig->height = 24;
    }
    return sim::FlightSim(c);
  }();
  return s;
}

}  // namespace

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
  fuzz::quiet();
  bus::Bus bus("memq://");
  bus::StatusReporter status(bus, "flightsim");
  sim::FlightSim simulator(prototype());
  sim::FlightSimNodeOptions options;
  options.command_channel = fuzz::kFlightSimChannels[0];
  options.answer_channels = {fuzz::kFlightSimChannels[0]};
  options.answer_timeout_s = 0;
  sim::FlightSimNode node(bus, simulator, options);
  node.publish_next();
  int frames = 1;
  fuzz::publish_records(bus, fuzz::kFlightSimChannels, data, size, [&] {
    node.wait_answers();
    node.report(status);
    if (frames < kMaxFrames) {
      node.publish_next();
      ++frames;
    }
  });
  return 0;
}
