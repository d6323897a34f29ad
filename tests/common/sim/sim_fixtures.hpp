#pragma once
// Worlds shared by the simulator tests (built once per test process).
#include "common/sim/world.hpp"

namespace aerie::sim::test {

// The default room (the one the demo and the benchmarks use).
inline const World& default_world() {
  static const World w = World::room(WorldConfig{});
  return w;
}

// A lighter room (coarser textures) for the tests that only need geometry or consistency.
inline const World& light_world() {
  static const World w = [] {
    WorldConfig c;
    c.texels_per_metre = 80;
    return World::room(c);
  }();
  return w;
}

}  // namespace aerie::sim::test
