#include "common/mavlink/parser.hpp"

#include <algorithm>
#include <cstdio>
#include <cstring>

#include "common/mavlink/crc.hpp"

namespace aerie::mavlink {

namespace {

bool is_magic(uint8_t b) { return b == kMagicV1 || b == kMagicV2; }

std::string hex16(uint16_t v) {
  char text[8];
  std::snprintf(text, sizeof text, "0x%04X", v);
  return text;
}

}  // namespace

bool accepted_unsigned(uint32_t msgid) {
  return msgid == 0 /* HEARTBEAT */ || msgid == 109 /* RADIO_STATUS */ || msgid == 246 /* ADSB_VEHICLE */ ||
         msgid == 247 /* COLLISION */;
}

void Parser::set_signing(const Key& key, bool require, SigningClock clock, size_t max_streams) {
  verifier_.emplace(key, std::move(clock), max_streams);
  require_signing_ = require;
}

void Parser::set_key(const Key& key) {
  if (verifier_)
    verifier_->set_key(key);
  else
    set_signing(key, require_signing_);
}

void Parser::clear_signing() {
  verifier_.reset();
  require_signing_ = false;
}

std::vector<Frame> Parser::feed(std::span<const uint8_t> bytes) {
  std::vector<Frame> frames;
  feed(bytes, [&](const Frame& f) { frames.push_back(f); });
  return frames;
}

// Bytes the candidate at buf_[0] needs before it can be checked.
size_t Parser::needed() const {
  if (buf_[0] == kMagicV1) return size_ < 2 ? 2 : kHeaderLengthV1 + buf_[1] + kChecksumLength;
  if (size_ < 3) return 3;
  return kHeaderLengthV2 + buf_[1] + kChecksumLength + ((buf_[2] & kIncompatSigned) ? kSignatureLength : 0);
}

void Parser::refuse(uint64_t& counter, const std::string& what) {
  ++counter;
  last_error_ = what;
}

// Drops the refused candidate's start byte and the garbage up to the next start byte.
void Parser::drop_front() {
  size_t skip = 1;
  while (skip < size_ && !is_magic(buf_[skip])) ++skip;
  counters_.garbage_bytes += skip - 1;
  std::memmove(buf_.data(), buf_.data() + skip, size_ - skip);
  size_ -= skip;
}

void Parser::feed(std::span<const uint8_t> bytes, const FrameHandler& on_frame) {
  size_t i = 0;
  for (;;) {
    if (size_ == 0) {
      while (i < bytes.size() && !is_magic(bytes[i])) {
        ++i;
        ++counters_.garbage_bytes;
      }
      if (i == bytes.size()) return;
      buf_[size_++] = bytes[i++];
    }
    // An unknown incompat flag: the frame's layout is unknown (the MAVLink C library drops it too).
    if (buf_[0] == kMagicV2 && size_ >= 3 && (buf_[2] & ~kIncompatSigned)) {
      char flags[8];
      std::snprintf(flags, sizeof flags, "0x%02X", buf_[2]);
      refuse(counters_.bad_incompat_flags,
             std::string("MAVLink 2 frame with unsupported incompat flags ") + flags + " (only 0x01, signed, is known)");
      drop_front();
      continue;
    }
    size_t need = needed();
    while (size_ < need && i < bytes.size()) {
      const size_t n = std::min(need - size_, bytes.size() - i);
      std::memcpy(buf_.data() + size_, bytes.data() + i, n);
      size_ += n;
      i += n;
      need = needed();  // the length / flags bytes may just have arrived
      if (buf_[0] == kMagicV2 && size_ >= 3 && (buf_[2] & ~kIncompatSigned)) break;
    }
    if (buf_[0] == kMagicV2 && size_ >= 3 && (buf_[2] & ~kIncompatSigned)) continue;
    if (size_ < need) return;
    const Outcome outcome = check(on_frame);
    if (outcome == Outcome::resync)
      drop_front();
    else
      size_ = 0;
  }
}

Parser::Outcome Parser::check(const FrameHandler& on_frame) {
  const uint8_t* b = buf_.data();
  const bool v2 = b[0] == kMagicV2;
  const size_t header = v2 ? kHeaderLengthV2 : kHeaderLengthV1;
  const uint8_t len = b[1];
  Frame frame;
  frame.version = v2 ? 2 : 1;
  if (v2) {
    frame.incompat_flags = b[2];
    frame.compat_flags = b[3];
    frame.seq = b[4];
    frame.sysid = b[5];
    frame.compid = b[6];
    frame.msgid = static_cast<uint32_t>(b[7]) | static_cast<uint32_t>(b[8]) << 8 | static_cast<uint32_t>(b[9]) << 16;
  } else {
    frame.seq = b[2];
    frame.sysid = b[3];
    frame.compid = b[4];
    frame.msgid = b[5];
  }
  // "HEARTBEAT (0) from 1/1 seq 7: ", built only for a refusal.
  const auto who = [&] {
    return message_name(frame.msgid) + " from " + std::to_string(frame.sysid) + "/" + std::to_string(frame.compid) +
           " seq " + std::to_string(frame.seq) + ": ";
  };

  const MessageInfo* info = find_message(frame.msgid);
  if (!info) {
    refuse(counters_.unknown_message, who() + "unknown message id, its CRC cannot be checked (CRC_EXTRA unknown)");
    return Outcome::resync;
  }
  Crc16 crc;
  crc.add(std::span<const uint8_t>(b + 1, header - 1 + len));
  crc.add(info->crc_extra);
  const uint16_t received = static_cast<uint16_t>(b[header + len] | (b[header + len + 1] << 8));
  if (crc.value() != received) {
    refuse(counters_.bad_crc, who() + "bad CRC (received " + hex16(received) + ", computed " + hex16(crc.value()) + ")");
    return Outcome::resync;
  }
  // From here the frame is real: a refusal consumes it.
  if (len > info->max_length) {
    refuse(counters_.payload_too_long, who() + "payload of " + std::to_string(len) + " bytes, at most " +
                                           std::to_string(info->max_length) + " expected");
    return Outcome::refused_frame;
  }
  if (!v2 && require_signing_) {
    refuse(counters_.mavlink1_refused, who() + "MAVLink 1 frame refused: signing is required");
    return Outcome::refused_frame;
  }
  const bool is_signed = v2 && (frame.incompat_flags & kIncompatSigned);
  if (v2 && !is_signed && require_signing_ && !accepted_unsigned(frame.msgid)) {
    refuse(counters_.unsigned_refused, who() + "unsigned frame refused: signing is required");
    return Outcome::refused_frame;
  }
  if (is_signed) {
    const size_t trailer = header + len + kChecksumLength;
    Signature sig;
    sig.link_id = b[trailer];
    for (size_t k = 0; k < 6; ++k) sig.timestamp |= static_cast<uint64_t>(b[trailer + 1 + k]) << (8 * k);
    std::copy_n(b + trailer + 7, 6, sig.value.begin());
    frame.signature = sig;
    if (verifier_) {
      const auto stream = [&] {
        return "link " + std::to_string(sig.link_id) + " timestamp " + std::to_string(sig.timestamp);
      };
      switch (verifier_->verify(std::span<const uint8_t>(b, trailer + kSignatureLength))) {
        case Verifier::Verdict::accepted: break;
        case Verifier::Verdict::bad_signature:
          refuse(counters_.bad_signature, who() + "bad signature (" + stream() + "): wrong key or altered frame");
          return Outcome::refused_frame;
        case Verifier::Verdict::replayed:
          refuse(counters_.replayed_timestamp, who() + "replayed signature (" + stream() +
                                                   " not newer than the stream's last)");
          return Outcome::refused_frame;
        case Verifier::Verdict::stale:
          refuse(counters_.stale_timestamp, who() + "signature of a new stream (" + stream() +
                                                ") more than a minute behind local time");
          return Outcome::refused_frame;
      }
    }
  }
  frame.payload.assign(b + header, b + header + len);
  ++counters_.frames;
  if (on_frame) on_frame(frame);
  return Outcome::accepted;
}

}  // namespace aerie::mavlink
