#pragma once
// Seeded randomness for the trackers: one 64-bit Mersenne twister per tracker, and
// draws defined here (not by std:: distributions, whose results differ between
// standard libraries), so the same seed gives the same track on every platform.
#include <cstdint>
#include <random>

namespace aerie::track {

using Rng = std::mt19937_64;

// Uniform integer in [lo, hi] (inclusive); lo <= hi.
inline int uniform_int(Rng& rng, int lo, int hi) {
  const uint64_t span = static_cast<uint64_t>(hi - lo) + 1;
  return lo + static_cast<int>(rng() % span);
}

// Uniform real in [0, 1).
inline double uniform01(Rng& rng) { return static_cast<double>(rng() >> 11) * 0x1.0p-53; }

}  // namespace aerie::track
