#include "common/seal/replay_window.hpp"

#include <algorithm>

namespace aerie::seal {

// As WireGuard, the window works on counter + 1 so that counter 0 is a valid first value.
ReplayWindow::Verdict ReplayWindow::check(uint64_t counter) const {
  if (top_ >= kRejectAfter + 1 || counter >= kRejectAfter) return Verdict::Exhausted;
  const uint64_t c = counter + 1;
  if (kWindowSize + c < top_) return Verdict::TooOld;
  if (c > top_) return Verdict::Fresh;
  const uint64_t word = bits_[(c / kWordBits) & (kWords - 1)];
  return (word >> (c & (kWordBits - 1))) & 1u ? Verdict::Replayed : Verdict::Fresh;
}

void ReplayWindow::commit(uint64_t counter) {
  const uint64_t c = counter + 1;
  const uint64_t index = c / kWordBits;
  if (c > top_) {
    const uint64_t index_current = top_ / kWordBits;
    const uint64_t clear = std::min<uint64_t>(index - index_current, kWords);
    for (uint64_t i = 1; i <= clear; ++i) bits_[(i + index_current) & (kWords - 1)] = 0;
    top_ = c;
  }
  bits_[index & (kWords - 1)] |= uint64_t{1} << (c & (kWordBits - 1));
}

bool ReplayWindow::accept(uint64_t counter) {
  if (check(counter) != Verdict::Fresh) return false;
  commit(counter);
  return true;
}

}  // namespace aerie::seal
