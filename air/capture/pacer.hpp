#pragma once
// Plays recorded frames at real time, a multiple of it, or as fast as possible:
// frame k is due at wall0 + (utime_k - utime_0) / rate. Uses the frames' own times,
// so a sequence with irregular intervals keeps them.
#include <cstdint>
#include <stdexcept>

namespace aerie::capture {

class Pacer {
 public:
  // rate: 1 = real time, 2 = twice as fast, 0 = as fast as possible.
  explicit Pacer(double rate) : rate_(rate) {
    if (!(rate >= 0)) throw std::invalid_argument("rate must be >= 0 (0 = as fast as possible)");
  }
  // Wall-clock time (µs) at which the frame with this source utime is due; the first
  // frame is due at `now`.
  int64_t due(int64_t source_utime, int64_t now) {
    if (rate_ == 0) return now;
    if (!started_) {
      started_ = true;
      wall0_ = now;
      utime0_ = source_utime;
    }
    return wall0_ + static_cast<int64_t>(static_cast<double>(source_utime - utime0_) / rate_);
  }
  double rate() const { return rate_; }

 private:
  double rate_;
  bool started_ = false;
  int64_t wall0_ = 0, utime0_ = 0;
};

}  // namespace aerie::capture
