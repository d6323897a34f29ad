#pragma once
// A streaming MAVLink parser: bytes in any chunking -> complete, checked frames. It never throws
// on input and holds at most one frame's bytes (kMaxFrameLength), whatever arrives. Each refused
// candidate is counted under its reason and described in last_error(); after a candidate that
// cannot be checked (bad CRC, unknown id, unknown incompat flag) the parser resynchronises on the
// next start byte after the refused one, so that a real frame behind garbage is still found.
//
// Usage:
//   mav::Parser parser;
//   parser.set_signing(key, /*require=*/true);   // optional (signing.hpp)
//   parser.feed(std::span<const uint8_t>(buf, n), [&](const mav::Frame& frame) {
//     if (frame.msgid == mav::Heartbeat::kId) on_heartbeat(mav::decode<mav::Heartbeat>(frame));
//   });
//   status.refused = parser.counters().refused(); status.error = parser.last_error();
#include <array>
#include <cstdint>
#include <functional>
#include <optional>
#include <span>
#include <string>
#include <vector>

#include "common/mavlink/frame.hpp"
#include "common/mavlink/signing.hpp"

namespace aerie::mavlink {

struct ParserCounters {
  uint64_t frames = 0;                  // accepted
  uint64_t bad_crc = 0;                 // checksum wrong (corrupt frame, or a start byte in garbage)
  uint64_t unknown_message = 0;         // id outside the catalogue: CRC_EXTRA unknown, cannot be checked
  uint64_t payload_too_long = 0;        // longer than the message's maximum payload
  uint64_t bad_incompat_flags = 0;      // an incompat flag other than "signed"
  uint64_t mavlink1_refused = 0;        // MAVLink 1 frame while signing is required
  uint64_t unsigned_refused = 0;        // unsigned MAVLink 2 frame while signing is required
  uint64_t bad_signature = 0;           // signature does not match the key
  uint64_t replayed_timestamp = 0;      // timestamp not newer than its stream's last
  uint64_t stale_timestamp = 0;         // a new stream more than a minute behind local time
  uint64_t garbage_bytes = 0;           // bytes skipped while looking for a start byte

  // Every refused candidate (garbage bytes not included).
  uint64_t refused() const {
    return bad_crc + unknown_message + payload_too_long + bad_incompat_flags + mavlink1_refused +
           unsigned_refused + bad_signature + replayed_timestamp + stale_timestamp;
  }
};

// Accepted unsigned while signing is required, as PX4 does: HEARTBEAT, RADIO_STATUS,
// ADSB_VEHICLE, COLLISION.
bool accepted_unsigned(uint32_t msgid);

class Parser {
 public:
  using FrameHandler = std::function<void(const Frame&)>;

  Parser() = default;

  // With a key, every signed frame is verified; with `require`, unsigned frames (but those of
  // accepted_unsigned) and MAVLink 1 frames are refused. Without a key, signed frames are
  // passed on unchecked.
  void set_signing(const Key& key, bool require = true, SigningClock clock = signing_time_now,
                   size_t max_streams = 256);
  // Replaces the key, keeping each stream's last timestamp.
  void set_key(const Key& key);
  void clear_signing();
  bool signing_required() const { return require_signing_; }

  // Calls on_frame for each accepted frame, in order.
  void feed(std::span<const uint8_t> bytes, const FrameHandler& on_frame);
  std::vector<Frame> feed(std::span<const uint8_t> bytes);

  const ParserCounters& counters() const { return counters_; }
  // The last refusal, e.g. "COMMAND_LONG (76) from 1/1 seq 7: bad CRC (received 0x1234, computed 0x4321)".
  const std::string& last_error() const { return last_error_; }

 private:
  enum class Outcome { accepted, refused_frame, resync };
  size_t needed() const;
  Outcome check(const FrameHandler& on_frame);
  void refuse(uint64_t& counter, const std::string& what);
  void drop_front();

  std::array<uint8_t, kMaxFrameLength> buf_{};
  size_t size_ = 0;
  ParserCounters counters_;
  std::string last_error_;
  bool require_signing_ = false;
  std::optional<Verifier> verifier_;
};

}  // namespace aerie::mavlink
