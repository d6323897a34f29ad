#pragma once
// MAVLink 2 message signing (protocol documentation, "Message Signing"): a signed frame has
// the incompat flag 0x01 and a 13-byte trailer: link id, timestamp (48 bits, LE, 10 µs units
// since 2015-01-01 00:00 UTC), signature = the first 6 bytes of
// SHA-256(key[32] ‖ header[10] ‖ payload ‖ CRC[2] ‖ link id ‖ timestamp[6]).
// Timestamps are strictly increasing per (sysid, compid, link id) stream; a stream not seen
// before is accepted only if its timestamp is within one minute of local time or newer than the
// newest timestamp seen. Keys are never logged: status lines show fingerprint(key).
//
// Usage:
//   mav::Key key = mav::load_key("/etc/aerie/mavlink.key");            // mode 0600
//   mav::Signer signer(key, /*link_id=*/0, mav::load_timestamp(ts_path));
//   auto bytes = mav::encode(msg, {1, 191, seq++}, signer);
//   if (signer.should_persist(mav::signing_time_now())) mav::save_timestamp(ts_path, signer.mark_persisted());
//   parser.set_signing(key, /*require=*/true);                          // parser.hpp
#include <array>
#include <chrono>
#include <cstdint>
#include <functional>
#include <map>
#include <optional>
#include <span>
#include <string>
#include <tuple>
#include <vector>

#include "common/mavlink/catalogue.hpp"

namespace aerie::mavlink {

using Key = std::array<uint8_t, 32>;
using SignatureBytes = std::array<uint8_t, 6>;
// The signing clock: 10 µs ticks since 2015-01-01 00:00 UTC (Unix time − 1420070400 s).
using SigningClock = std::function<uint64_t()>;

inline constexpr uint64_t kTicksPerSecond = 100'000;
inline constexpr uint64_t kSigningEpochUnixSeconds = 1'420'070'400;
inline constexpr uint64_t kOneMinuteTicks = 60 * kTicksPerSecond;  // 6,000,000
inline constexpr uint64_t kMaxTimestamp = (uint64_t{1} << 48) - 1;

uint64_t to_signing_time(std::chrono::system_clock::time_point t);
uint64_t signing_time_now();

// The 6-byte signature of a frame: `frame` is the frame from its magic byte to the end of the CRC.
SignatureBytes compute_signature(const Key& key, std::span<const uint8_t> frame, uint8_t link_id, uint64_t timestamp);

// Signs outgoing frames of one link.
class Signer {
 public:
  // Starts after max(now, persisted_timestamp + one minute) (the margin covers the time between
  // the last save and a restart); persisted_timestamp 0 = none saved.
  Signer(const Key& key, uint8_t link_id, uint64_t persisted_timestamp = 0, SigningClock clock = signing_time_now);

  // max(now, last + 1): strictly increasing even when the clock stands still or steps back.
  uint64_t next_timestamp();
  // `frame`: a MAVLink 2 frame with the signed flag set, up to its CRC; appends the trailer.
  void append_signature(std::vector<uint8_t>& frame);

  void set_key(const Key& key) { key_ = key; }
  uint8_t link_id() const { return link_id_; }
  uint64_t last_timestamp() const { return last_; }
  // True when the last timestamp has not been saved for a minute of the signing clock (or never):
  // the caller saves it (save_timestamp) and calls mark_persisted.
  bool should_persist(uint64_t now) const;
  // Records that the current last timestamp is saved; returns it.
  uint64_t mark_persisted();
  uint64_t mark_persisted(uint64_t now);

 private:
  Key key_;
  uint8_t link_id_;
  SigningClock clock_;
  uint64_t last_ = 0;
  std::optional<uint64_t> persisted_at_;
};

// Checks incoming signed frames.
class Verifier {
 public:
  enum class Verdict { accepted, bad_signature, replayed, stale };

  explicit Verifier(const Key& key, SigningClock clock = signing_time_now, size_t max_streams = 256);

  // `frame`: a complete signed MAVLink 2 frame (header .. signature), CRC already checked.
  // Updates the stream's last timestamp only when accepted.
  Verdict verify(std::span<const uint8_t> frame);

  // A new key (frames signed with the old one are refused from now on); streams are kept.
  void set_key(const Key& key) { key_ = key; }
  size_t stream_count() const { return streams_.size(); }
  uint64_t newest_timestamp() const { return newest_; }

 private:
  using StreamId = std::tuple<uint8_t, uint8_t, uint8_t>;  // sysid, compid, link id
  Key key_;
  SigningClock clock_;
  size_t max_streams_;
  std::map<StreamId, uint64_t> streams_;  // last accepted timestamp of each stream
  uint64_t newest_ = 0;
};

std::string to_string(Verifier::Verdict verdict);

// Keys: 32 raw bytes in a file of mode 0600 (common/util/key_file.hpp).
Key load_key(const std::string& path);
void save_key(const std::string& path, const Key& key, bool overwrite = false);
Key generate_key();  // libsodium randombytes
// First 8 bytes of SHA-256(key) in hex, for status lines (the key itself is never shown).
std::string fingerprint(const Key& key);

// The newest signing timestamp as a decimal number in a small text file (written atomically).
void save_timestamp(const std::string& path, uint64_t timestamp);
// 0 when the file does not exist; std::runtime_error naming the file when it does not hold a number.
uint64_t load_timestamp(const std::string& path);

// SETUP_SIGNING for (target_system, target_component): the key and the initial timestamp.
SetupSigning make_setup_signing(uint8_t target_system, uint8_t target_component, const Key& key,
                                uint64_t initial_timestamp);

}  // namespace aerie::mavlink
