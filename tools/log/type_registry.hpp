#pragma once
// The Aerie message types, looked up by their LCM fingerprint (the first 8 bytes of
// every encoded message), so that a log can be described without knowing in advance
// which type travels on which channel.
#include <cstddef>
#include <cstdint>
#include <optional>
#include <string>

namespace aerie::logtools {

// What the decoder found in one payload.
struct Stamp {
  bool decoded = false;      // false: fingerprint matched but the payload is corrupt
  std::optional<int64_t> utime;
  std::optional<int64_t> seq;  // image_t: metadata "seq"
  std::optional<int64_t> frames_skipped;  // cumulative frames the producer skipped (track_t)
};

struct TypeInfo {
  std::string name;  // e.g. "aerie.image_t"
  int64_t fingerprint;
  Stamp (*decode)(const uint8_t* data, size_t size);
};

// The fingerprint of a payload (0 when it is shorter than 8 bytes).
int64_t fingerprint_of(const uint8_t* data, size_t size);
// The registered type with this fingerprint, or nullptr.
const TypeInfo* find_type(int64_t fingerprint);

// LCM's own message: lcm_create() on a udpm URL publishes the plain string "lcm self test" on
// this channel to check the network, and lcm-logger records it. Not an Aerie type.
inline constexpr const char* kLcmSelfTestChannel = "LCM_SELF_TEST";

// How info and diff name the type of a payload on `channel`: the registered type's name,
// "lcm self-test (string)" on LCM_SELF_TEST, otherwise "unknown (fingerprint 0x...)".
std::string type_name(const TypeInfo* type, int64_t fingerprint, const std::string& channel);

}  // namespace aerie::logtools
