#pragma once
// An FNV-1a digest of a scripted flight (take off, fly forward, land) with wind: every
// frame's wind, vehicle position, down image and the landing's score. It pins the frames of
// the historical defaults (Gauss-Markov wind, a still platform) byte for byte.
#include <cstdint>
#include <cstring>
#include <string>

#include "common/sim/flight/flight_config.hpp"
#include "common/sim/flight/flight_sim.hpp"

namespace aerie::sim::test {

inline uint64_t flight_digest(const FlightSimConfig& cfg, int frames) {
  uint64_t h = 1469598103934665603ull;
  auto mix = [&](const void* data, size_t n) {
    const auto* p = static_cast<const unsigned char*>(data);
    for (size_t i = 0; i < n; ++i) h = (h ^ p[i]) * 1099511628211ull;
  };
  FlightSim sim(cfg);
  for (int k = 0; k < frames; ++k) {
    CommandInput c;
    if (k == 1) c.mode = 3;  // TAKEOFF
    if (k >= frames / 2) {   // forward and down, then LAND
      c.mode = 1;
      c.velocity = {0.5, 0.2, -0.3};
    }
    if (k >= frames - 10) c = CommandInput{4, {}, 0};
    if (k >= 1) sim.command(c);
    const FlightFrame f = sim.step();
    mix(f.wind.data(), sizeof(double) * 3);
    mix(f.vehicle.position.data(), sizeof(double) * 3);
    for (int r = 0; r < f.down.left.rows; ++r) mix(f.down.left.ptr(r), f.down.left.cols * f.down.left.elemSize());
  }
  const LandingScore s = score_landing(sim);
  mix(&s.touchdown_error_m, sizeof(double));
  return h;
}

}  // namespace aerie::sim::test
