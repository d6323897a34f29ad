#include "common/mavlink/frame.hpp"

#include "common/mavlink/crc.hpp"
#include "common/mavlink/signing.hpp"

namespace aerie::mavlink {

namespace {

template <class... M>
std::optional<Message> decode_any(const Frame& frame, std::variant<M...>*) {
  std::optional<Message> out;
  (void)((frame.msgid == M::kId ? (out = decode<M>(frame), true) : false) || ...);
  return out;
}

}  // namespace

std::vector<uint8_t> serialize_with_crc_extra(const Frame& frame, uint8_t crc_extra) {
  if (frame.payload.size() > 255)
    throw std::invalid_argument("MAVLink serialize: " + message_name(frame.msgid) + " payload of " +
                                std::to_string(frame.payload.size()) + " bytes, at most 255 fit a frame");
  std::vector<uint8_t> out;
  out.reserve(kMaxFrameLength);
  const auto len = static_cast<uint8_t>(frame.payload.size());
  if (frame.version == 1) {
    if (frame.msgid > 255)
      throw std::invalid_argument("MAVLink serialize: message id " + std::to_string(frame.msgid) +
                                  " does not fit a MAVLink 1 frame (ids 0..255)");
    out = {kMagicV1, len, frame.seq, frame.sysid, frame.compid, static_cast<uint8_t>(frame.msgid)};
  } else if (frame.version == 2) {
    if (frame.msgid > 0xFFFFFF)
      throw std::invalid_argument("MAVLink serialize: message id " + std::to_string(frame.msgid) +
                                  " does not fit 24 bits");
    uint8_t incompat = frame.incompat_flags;
    if (frame.signature) incompat |= kIncompatSigned;
    out = {kMagicV2,
           len,
           incompat,
           frame.compat_flags,
           frame.seq,
           frame.sysid,
           frame.compid,
           static_cast<uint8_t>(frame.msgid),
           static_cast<uint8_t>(frame.msgid >> 8),
           static_cast<uint8_t>(frame.msgid >> 16)};
  } else {
    throw std::invalid_argument("MAVLink serialize: frame version " + std::to_string(frame.version) +
                                ", expected 1 or 2");
  }
  out.insert(out.end(), frame.payload.begin(), frame.payload.end());
  Crc16 crc;
  crc.add(std::span<const uint8_t>(out).subspan(1));
  crc.add(crc_extra);
  out.push_back(static_cast<uint8_t>(crc.value() & 0xFF));
  out.push_back(static_cast<uint8_t>(crc.value() >> 8));
  if (frame.version == 2 && frame.signature) {
    out.push_back(frame.signature->link_id);
    for (int i = 0; i < 6; ++i) out.push_back(static_cast<uint8_t>(frame.signature->timestamp >> (8 * i)));
    out.insert(out.end(), frame.signature->value.begin(), frame.signature->value.end());
  }
  return out;
}

std::vector<uint8_t> serialize(const Frame& frame) {
  const MessageInfo* info = find_message(frame.msgid);
  if (!info)
    throw std::invalid_argument("MAVLink serialize: message id " + std::to_string(frame.msgid) +
                                " is not in Aerie's catalogue (CRC_EXTRA unknown)");
  return serialize_with_crc_extra(frame, info->crc_extra);
}

std::vector<uint8_t> serialize(const Frame& frame, Signer& signer) {
  if (frame.version != 2) throw std::invalid_argument("MAVLink serialize: only MAVLink 2 frames can be signed");
  Frame unsigned_frame = frame;
  unsigned_frame.signature.reset();
  unsigned_frame.incompat_flags |= kIncompatSigned;
  std::vector<uint8_t> bytes = serialize(unsigned_frame);
  signer.append_signature(bytes);
  return bytes;
}

std::optional<Message> decode_message(const Frame& frame) {
  return decode_any(frame, static_cast<Message*>(nullptr));
}

std::string message_name(uint32_t msgid) {
  if (const MessageInfo* info = find_message(msgid)) return std::string(info->name) + " (" + std::to_string(msgid) + ")";
  return "message " + std::to_string(msgid);
}

}  // namespace aerie::mavlink
