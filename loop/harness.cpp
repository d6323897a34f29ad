#include "loop/harness.hpp"

namespace aerie::loop {

namespace {
std::unique_ptr<sim::FlightSim> make_sim(std::optional<sim::FlightSimConfig> config, uint64_t seed) {
  if (!config) return nullptr;
  config->seed = seed;
  return std::make_unique<sim::FlightSim>(*config);
}
}  // namespace

Harness::Harness(const Wiring& wiring, std::optional<sim::FlightSimConfig> sim, sim::FlightSimNodeOptions node_options)
    : wall0_(std::chrono::steady_clock::now()),
      sim_(make_sim(std::move(sim), wiring.seed)),
      buses_(wiring.split),
      injector_(wiring.faults, wiring.seed) {
  buses_.tap(injector_.tap(wiring.on_message));
  flight_.buses = &buses_;
  if (sim_) {
    node_options.answer_channels.clear();  // a frame is answered when the buses are settled
    sim_node_ = std::make_unique<sim::FlightSimNode>(air(), *sim_, node_options);
    flight_.stall_cameras = [this](bool stalled) { sim_node_->stall_cameras(stalled); };
  }
}

util::NodeClock Harness::clock() const {
  const sim::FlightSim* s = sim_.get();
  return [s] { return s->utime_of(s->time()); };
}

const sim::FlightFrame& Harness::step(const std::function<void(const sim::FlightFrame&)>& on_frame) {
  const sim::FlightFrame& f = sim_node_->publish_next();
  if (on_frame) on_frame(f);
  injector_.step(f.t, flight_);
  settle(f.utime);
  return f;
}

void Harness::settle(int64_t now_us) { buses_.settle(now_us, wait_); }

RunStats Harness::finish() {
  RunStats s;
  if (sim_) {
    s.faults = injector_.report(buses_, sim_node_->stalled_frames(), sim_->vehicle().command_timeouts());
    s.lockstep_timeouts = sim_node_->lockstep_timeouts();
    s.commands_refused = sim_->commands_refused();
    s.sim_s = sim_->time();
  }
  s.link_down = buses_.down_counters();
  s.link_up = buses_.up_counters();
  s.wall_s = std::chrono::duration<double>(std::chrono::steady_clock::now() - wall0_).count();
  return s;
}

}  // namespace aerie::loop
