#pragma once
#include <chrono>
#include <cstdint>

namespace aerie::util {

// Wall-clock microseconds since the epoch. For status and latency measurement only:
// algorithms use message time (utime), so replays reproduce live results.
inline int64_t wall_utime() {
  return std::chrono::duration_cast<std::chrono::microseconds>(
             std::chrono::system_clock::now().time_since_epoch())
      .count();
}

// Monotonic milliseconds, for timing a computation.
inline double mono_ms() {
  return std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now().time_since_epoch()).count();
}

class Stopwatch {
 public:
  Stopwatch() : t0_(mono_ms()) {}
  double ms() const { return mono_ms() - t0_; }
  void reset() { t0_ = mono_ms(); }

 private:
  double t0_;
};

}  // namespace aerie::util
