#pragma once
// The sliding replay window of one (sender, epoch) stream: WireGuard's counter check
// (drivers/net/wireguard/receive.c, counter_validate; RFC 6479's bitmap without a lock), split
// into check() before the tag is verified and commit() after it, so that a forged datagram
// never moves the window.
#include <array>
#include <cstdint>
#include <limits>

namespace aerie::seal {

class ReplayWindow {
 public:
  static constexpr uint64_t kBitsTotal = 8192;               // WireGuard's COUNTER_BITS_TOTAL
  static constexpr uint64_t kWordBits = 64;                  // COUNTER_REDUNDANT_BITS
  static constexpr uint64_t kWindowSize = kBitsTotal - kWordBits;  // COUNTER_WINDOW_SIZE
  // WireGuard's REJECT_AFTER_MESSAGES: counters at or above it are never accepted.
  static constexpr uint64_t kRejectAfter = std::numeric_limits<uint64_t>::max() - kWindowSize - 1;

  enum class Verdict : uint8_t {
    Fresh,      // not seen, inside or right of the window
    Replayed,   // seen already
    TooOld,     // left of the window
    Exhausted,  // at or above kRejectAfter
  };

  Verdict check(uint64_t counter) const;
  // Marks `counter` as seen (advancing the window when it is right of it). Only after check()
  // said Fresh and the datagram authenticated.
  void commit(uint64_t counter);
  // check() then commit() when Fresh: WireGuard's counter_validate(), for its self-test.
  bool accept(uint64_t counter);

  // The highest counter accepted + 1 (0 before the first).
  uint64_t top() const { return top_; }

 private:
  static constexpr uint64_t kWords = kBitsTotal / kWordBits;
  uint64_t top_ = 0;
  std::array<uint64_t, kWords> bits_{};
};

}  // namespace aerie::seal
