#pragma once
// The one closed loop (issue 51): the flight simulator and its node, the split bus (one
// memq:// bus, or an air and a ground bus joined by the link in simulation time,
// tools/link/sim_link.hpp), the fault injector (loop/faults.hpp) and the bookkeeping every
// run shares. A scenario (loop/landing, loop/avoidance, loop/replay) builds its nodes on the
// harness's buses, calls step() once per frame — publish the frame, inject what is due,
// settle the buses — and ends with finish(). Each frame is settled (every message handled,
// the workers idle, the link's due messages delivered) before the physics steps, so a run is
// a function of its configuration and seed.
#include <chrono>
#include <cstdint>
#include <functional>
#include <memory>
#include <optional>
#include <string>
#include <vector>

#include "common/sim/flight/flight_sim.hpp"
#include "common/sim/flight/node/flightsim_node.hpp"
#include "common/util/message_clock.hpp"
#include "loop/faults.hpp"
#include "tools/link/sim_link.hpp"

namespace aerie::loop {

// What every run configuration holds, declared once.
struct Wiring {
  // The simulator's (world, wind), the faults' and the link-free draws; the loaders also give it
  // to the tracker (its options' own seed, so that a recorded flight can be flown again as it was).
  uint64_t seed = 1;
  // Nodes on the ground side, and the link; none: one bus.
  std::optional<link::Split> split;
  // Sees every message on each side's bus in bus order, with the simulation time it is
  // handled at, e.g. to record it (the air side only without a split).
  link::SplitBus::Tap on_message;
  // Injected during the flight (docs/faults.md): the nodes the scenario names can be killed.
  std::vector<faults::Fault> faults;
};

// What every run reports, counted by the harness.
struct RunStats {
  faults::Report faults;
  int64_t lockstep_timeouts = 0, commands_refused = 0;
  link::DirectionCounters link_down, link_up;  // with a split
  double sim_s = 0, wall_s = 0;                // wall_s: the machine's, the only figure that is not lock-step
};

class Harness {
 public:
  // A closed loop on `sim` (its seed: wiring.seed), the simulator's node answered when the
  // buses are settled; without `sim`, the buses alone (an open-loop replay).
  Harness(const Wiring& wiring, std::optional<sim::FlightSimConfig> sim, sim::FlightSimNodeOptions node_options = {});
  Harness(const Harness&) = delete;
  Harness& operator=(const Harness&) = delete;

  sim::FlightSim& sim() { return *sim_; }
  sim::FlightSimNode& sim_node() { return *sim_node_; }
  link::SplitBus& buses() { return buses_; }
  bus::Bus& air() { return buses_.on(link::Side::kAir); }
  bus::Bus& bus_of(const std::string& node) { return buses_.of(node); }
  // The simulation's clock (µs), for the nodes whose rules measure time.
  util::NodeClock clock() const;

  // A node faults may kill and respawn, by name.
  template <typename Node>
  void add(const std::string& name, faults::Respawnable<Node>& node) {
    flight_.add(name, node);
  }
  // Waited for at each settling round (e.g. the tracker's worker thread).
  void wait_workers(std::function<void()> wait) { wait_ = std::move(wait); }

  // One frame: published, `on_frame` told (before anything is injected or handled), the faults
  // due started or ended, the buses settled.
  const sim::FlightFrame& step(const std::function<void(const sim::FlightFrame&)>& on_frame = {});
  // The buses settled at now_us (with the workers waited for).
  void settle(int64_t now_us);

  // The shared figures at the end of the run (sim_s: the simulator's time, 0 without one).
  RunStats finish();

 private:
  std::chrono::steady_clock::time_point wall0_;
  std::unique_ptr<sim::FlightSim> sim_;
  link::SplitBus buses_;
  faults::Injector injector_;
  std::unique_ptr<sim::FlightSimNode> sim_node_;
  faults::Flight flight_;
  std::function<void()> wait_;
};

}  // namespace aerie::loop
