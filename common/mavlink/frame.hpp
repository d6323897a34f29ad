#pragma once
// MAVLink frames (protocol documentation, "Packet Serialization"):
//   v2: 0xFD len incompat compat seq sysid compid msgid[3, LE] payload[len] crc[2, LE] [signature 13]
//   v1: 0xFE len seq sysid compid msgid payload[len] crc[2, LE]
// The CRC (crc.hpp) covers len .. end of payload, then the message's CRC_EXTRA. MAVLink 2 strips
// trailing zero bytes of the payload on send (keeping at least one); decode zero-fills.
//
// Usage:
//   namespace mav = aerie::mavlink;
//   mav::SetPositionTargetLocalNed sp;
//   sp.vx = 1.0f; sp.type_mask = mav::type_mask::kVelocityYawRate; sp.coordinate_frame = mav::mav_frame::kBodyNed;
//   std::vector<uint8_t> bytes = mav::encode(sp, {.sysid = 1, .compid = 191, .seq = seq++});
//   std::vector<uint8_t> signed_bytes = mav::encode(sp, {1, 191, seq++}, signer);  // signing.hpp
//   // receiving: see parser.hpp; then
//   if (frame.msgid == mav::Heartbeat::kId) mav::Heartbeat hb = mav::decode<mav::Heartbeat>(frame);
//   mav::visit_frame(frame, [](const auto& msg) { ... });  // any catalogue message, typed
#include <algorithm>
#include <array>
#include <cstdint>
#include <optional>
#include <span>
#include <stdexcept>
#include <string>
#include <vector>

#include "common/mavlink/catalogue.hpp"

namespace aerie::mavlink {

inline constexpr uint8_t kMagicV1 = 0xFE;
inline constexpr uint8_t kMagicV2 = 0xFD;
inline constexpr uint8_t kIncompatSigned = 0x01;  // MAVLINK_IFLAG_SIGNED, the only incompat flag defined
inline constexpr size_t kHeaderLengthV1 = 6;
inline constexpr size_t kHeaderLengthV2 = 10;
inline constexpr size_t kChecksumLength = 2;
inline constexpr size_t kSignatureLength = 13;  // link id, timestamp[6], signature[6]
inline constexpr size_t kMaxFrameLength = kHeaderLengthV2 + 255 + kChecksumLength + kSignatureLength;

class Signer;

struct Signature {
  uint8_t link_id = 0;
  uint64_t timestamp = 0;  // 48 bits, 10 µs units since 2015-01-01 00:00 UTC
  std::array<uint8_t, 6> value{};
  bool operator==(const Signature&) const = default;
};

struct Header {
  uint8_t sysid = 0;
  uint8_t compid = 0;
  uint8_t seq = 0;
};

struct Frame {
  uint8_t version = 2;  // 1 or 2
  uint8_t incompat_flags = 0;
  uint8_t compat_flags = 0;
  uint8_t seq = 0;
  uint8_t sysid = 0;
  uint8_t compid = 0;
  uint32_t msgid = 0;             // 24 bits (v2), 8 bits (v1)
  std::vector<uint8_t> payload;   // as sent (MAVLink 2: possibly truncated)
  std::optional<Signature> signature;
};

// A MAVLink 2 frame of `msg` (payload truncated), unsigned.
template <class Msg>
Frame make_frame(const Msg& msg, Header header) {
  std::array<uint8_t, max_length<Msg>()> full{};
  write_payload(msg, full);
  size_t n = full.size();
  while (n > 1 && full[n - 1] == 0) --n;
  Frame frame;
  frame.seq = header.seq;
  frame.sysid = header.sysid;
  frame.compid = header.compid;
  frame.msgid = Msg::kId;
  frame.payload.assign(full.begin(), full.begin() + static_cast<std::ptrdiff_t>(n));
  return frame;
}

// The bytes of `frame`, its CRC computed with the catalogue's CRC_EXTRA (std::invalid_argument
// for a message id not in the catalogue, a payload over 255 bytes, a v1 frame with an id > 255).
// A frame that carries a signature is written with it, as it is (a router forwards it so).
std::vector<uint8_t> serialize(const Frame& frame);
// The same with the incompat flag "signed" set and a signature from `signer` appended.
std::vector<uint8_t> serialize(const Frame& frame, Signer& signer);
// With an explicit CRC_EXTRA (tests, fuzzing: frames of ids outside the catalogue).
std::vector<uint8_t> serialize_with_crc_extra(const Frame& frame, uint8_t crc_extra);

template <class Msg>
std::vector<uint8_t> encode(const Msg& msg, Header header) {
  return serialize(make_frame(msg, header));
}
template <class Msg>
std::vector<uint8_t> encode(const Msg& msg, Header header, Signer& signer) {
  return serialize(make_frame(msg, header), signer);
}
// A MAVLink 1 frame: ids < 256, no extension fields, no truncation.
template <class Msg>
std::vector<uint8_t> encode_v1(const Msg& msg, Header header) {
  static_assert(Msg::kId < 256, "MAVLink 1 carries message ids 0..255");
  std::array<uint8_t, max_length<Msg>()> full{};
  write_payload(msg, full);
  Frame frame;
  frame.version = 1;
  frame.seq = header.seq;
  frame.sysid = header.sysid;
  frame.compid = header.compid;
  frame.msgid = Msg::kId;
  frame.payload.assign(full.begin(), full.begin() + min_length<Msg>());
  return serialize(frame);
}

// The message of `frame`, the payload zero-filled to the full length. std::invalid_argument when
// the frame holds another message or a payload longer than the message's.
template <class Msg>
Msg decode(const Frame& frame) {
  if (frame.msgid != Msg::kId)
    throw std::invalid_argument("MAVLink decode: frame holds message id " + std::to_string(frame.msgid) +
                                ", expected " + std::string(Msg::kName) + " (" + std::to_string(Msg::kId) + ")");
  if (frame.payload.size() > max_length<Msg>())
    throw std::invalid_argument("MAVLink decode: " + std::string(Msg::kName) + " payload of " +
                                std::to_string(frame.payload.size()) + " bytes, at most " +
                                std::to_string(max_length<Msg>()) + " expected");
  std::array<uint8_t, max_length<Msg>()> full{};
  std::copy(frame.payload.begin(), frame.payload.end(), full.begin());
  Msg msg;
  read_payload(std::span<const uint8_t>(full), msg);
  return msg;
}

// The catalogue message of `frame`, or nullopt for an id Aerie does not know (std::invalid_argument
// for a payload too long, as decode).
std::optional<Message> decode_message(const Frame& frame);

// Calls `visitor` with the typed message of `frame` (as decode_message); false for an unknown id.
template <class V>
bool visit_frame(const Frame& frame, V&& visitor) {
  const std::optional<Message> msg = decode_message(frame);
  if (!msg) return false;
  std::visit(std::forward<V>(visitor), *msg);
  return true;
}

// "HEARTBEAT (0)", or "message 12345" for an id outside the catalogue.
std::string message_name(uint32_t msgid);

}  // namespace aerie::mavlink
