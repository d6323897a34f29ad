#pragma once
// Per-stage timings of the stereo pipeline are thread CPU time: on an unloaded core it
// equals the wall clock, and on a machine shared with other jobs it still measures the
// work done (the node reports wall-clock latency separately).
#include <time.h>

namespace aerie::stereo {

inline double cpu_ms() {
  timespec ts{};
  clock_gettime(CLOCK_THREAD_CPUTIME_ID, &ts);
  return static_cast<double>(ts.tv_sec) * 1e3 + static_cast<double>(ts.tv_nsec) * 1e-6;
}

// CPU time of the whole process, every thread (the bundle adjuster's, OpenCV's pool).
inline double process_cpu_ms() {
  timespec ts{};
  clock_gettime(CLOCK_PROCESS_CPUTIME_ID, &ts);
  return static_cast<double>(ts.tv_sec) * 1e3 + static_cast<double>(ts.tv_nsec) * 1e-6;
}

class CpuStopwatch {
 public:
  CpuStopwatch() : t0_(cpu_ms()) {}
  double ms() const { return cpu_ms() - t0_; }
  void reset() { t0_ = cpu_ms(); }
  // Milliseconds since the last lap (or construction), restarting the count.
  double lap() {
    const double now = cpu_ms(), dt = now - t0_;
    t0_ = now;
    return dt;
  }

 private:
  double t0_;
};

}  // namespace aerie::stereo
