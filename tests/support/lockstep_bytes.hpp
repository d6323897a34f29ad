#pragma once
// A message's bytes as a lock-step or replay comparison sees them: TRACK with its
// processing_ms (the tracker's wall-clock time per frame, no run's to reproduce) zeroed; every
// other channel, or a TRACK that does not decode, as it came.
#include <aerie/track_t.hpp>

#include <cstdint>
#include <string>
#include <vector>

namespace aerie::test {

inline std::vector<uint8_t> comparable_bytes(const std::string& channel, const uint8_t* data, size_t size) {
  std::vector<uint8_t> bytes(data, data + size);
  aerie::track_t t;
  if (channel != "TRACK" || t.decode(data, 0, static_cast<int>(size)) <= 0) return bytes;
  t.processing_ms = 0;
  bytes.resize(static_cast<size_t>(t.getEncodedSize()));
  t.encode(bytes.data(), 0, static_cast<int>(bytes.size()));
  return bytes;
}

}  // namespace aerie::test
