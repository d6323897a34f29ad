#pragma once
#include <chrono>
#include <cmath>
#include <cstdint>
#include <optional>

namespace aerie::util {

// Wall-clock microseconds since the epoch. For status and latency measurement only:
// algorithms use message time (utime), so replays reproduce live results.
inline int64_t wall_utime() {
  return std::chrono::duration_cast<std::chrono::microseconds>(
             std::chrono::system_clock::now().time_since_epoch())
      .count();
}

// A message's age (s) on a node's clock: now_us minus the capture time it carries, or nullopt
// when the two are more than a minute apart, i.e. the message was not stamped on this clock (a
// lock-step simulation starts at 0, a replayed log at its recording; no link delays a frame
// that long). The age rules of aerie-pilot and aerie-control use it.
inline std::optional<double> message_age_s(int64_t utime, int64_t now_us) {
  constexpr double kComparableClockS = 60;
  const double age_s = (static_cast<double>(now_us) - static_cast<double>(utime)) * 1e-6;
  if (!(std::abs(age_s) <= kComparableClockS)) return std::nullopt;
  return age_s;
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
