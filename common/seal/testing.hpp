#pragma once
// For tests and the fuzz target only: seals an arbitrary inner plaintext (channel length byte,
// channel, payload -- possibly malformed) with explicit header fields, so that the opener's
// inner decoder can be reached with authentic datagrams it must still refuse. A caller picks
// the counter and salt itself: never use this to send (a repeated (salt, counter) repeats a nonce).
#include <array>
#include <cstdint>
#include <span>
#include <vector>

#include "common/seal/seal.hpp"

namespace aerie::seal::for_tests {

struct RawHeader {
  Direction direction = Direction::AirToGround;
  uint32_t epoch = 0;
  uint32_t sender = 0;
  uint64_t counter = 1;
  std::array<uint8_t, kSaltSize> salt{};
};

std::vector<uint8_t> seal_plaintext(const SecretKey& mission_key, const RawHeader& header,
                                    std::span<const uint8_t> inner_plaintext);

// A key of known bytes first, first + 1, ..., first + 31 (the fuzz targets' fixed keys: seeds
// sealed with it open in every run).
inline SecretKey counting_key(uint8_t first) {
  std::array<uint8_t, SecretKey::kSize> b{};
  for (size_t i = 0; i < b.size(); ++i) b[i] = static_cast<uint8_t>(first + i);
  return SecretKey::from_bytes(b);
}

}  // namespace aerie::seal::for_tests
