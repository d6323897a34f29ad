#pragma once
// CRC-16/MCRF4XX, the "X.25" checksum of MAVLink (init 0xFFFF, reflected polynomial 0x1021,
// no final XOR; check value of "123456789" is 0x6F91). It covers a frame from the length byte
// to the end of the payload as sent, then the message's CRC_EXTRA byte.
#include <cstddef>
#include <cstdint>
#include <span>
#include <string_view>

namespace aerie::mavlink {

class Crc16 {
 public:
  constexpr void add(uint8_t byte) {
    uint8_t tmp = byte ^ static_cast<uint8_t>(value_ & 0xFF);
    tmp = static_cast<uint8_t>(tmp ^ (tmp << 4));
    value_ = static_cast<uint16_t>((value_ >> 8) ^ (tmp << 8) ^ (tmp << 3) ^ (tmp >> 4));
  }
  constexpr void add(std::string_view text) {
    for (const char c : text) add(static_cast<uint8_t>(c));
  }
  constexpr void add(std::span<const uint8_t> bytes) {
    for (const uint8_t b : bytes) add(b);
  }
  constexpr uint16_t value() const { return value_; }

 private:
  uint16_t value_ = 0xFFFF;
};

constexpr uint16_t crc16(std::span<const uint8_t> bytes) {
  Crc16 crc;
  crc.add(bytes);
  return crc.value();
}

static_assert([] {
  Crc16 crc;
  crc.add(std::string_view("123456789"));
  return crc.value();
}() == 0x6F91);

}  // namespace aerie::mavlink
