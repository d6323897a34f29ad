#pragma once
// The sealed air-ground door's datagrams (issue 46 section 1; docs/security.md "The sealed door"):
// every datagram between the link's two halves is sealed with XChaCha20-Poly1305 (IETF AEAD,
// libsodium) under a per-epoch, per-direction subkey of the mission key, carries its channel
// name and payload encrypted, and is opened at most once (a WireGuard replay window per
// sender and epoch). No LCM, no sockets, no clock: the caller gives the time.
//
// Usage (the air half sends air->ground, the ground half opens what the air half sent):
//
//   #include "common/seal/seal.hpp"
//   using namespace aerie;
//   const seal::SecretKey key = seal::load_key("/etc/aerie/mission.key");        // mode 0600
//   seal::Sealer sealer(key, seal::Direction::AirToGround, /*sender=*/1, /*epoch=*/0, now_s);
//   std::vector<uint8_t> datagram = sealer.seal("VO_POSE", payload, now_s);      // send it over UDP
//
//   seal::Opener opener(key, {.direction = seal::Direction::AirToGround});
//   seal::Opened in = opener.open(datagram, now_s);     // never throws on network input
//   if (in) publish(in.channel, in.payload);            // authenticated, decrypted, fresh
//   else status.note(seal::to_string(in.refusal), in.why);   // counted in opener.counters()
//
// Status lines show seal::fingerprint(key) (keys.hpp), never the key. A Sealer or an Opener is
// used by one thread at a time (the link's send and receive loops each own theirs).
#include <array>
#include <cstddef>
#include <cstdint>
#include <span>
#include <string>
#include <string_view>
#include <vector>

#include "common/seal/keys.hpp"
#include "common/seal/replay_window.hpp"

namespace aerie::seal {

// Which way a datagram travels; each direction has its own subkeys, so a datagram sent one
// way and reflected back the other way does not open.
enum class Direction : uint8_t { AirToGround = 0, GroundToAir = 1 };
const char* to_string(Direction d);

// --- the datagram (docs/security.md, "Datagram layout"; integers little-endian) -----------------
//   0      magic 0xAE
//   1      version 1
//   2      flags: bit 0 the direction (0 air->ground, 1 ground->air); bits 1-7 zero
//   3      reserved, zero
//   4..7   key epoch (u32)
//   8..11  sender id (u32)
//   12..19 counter (u64; 1, 2, ... per sender and epoch)
//   20..35 salt: 16 random bytes drawn by the sealer for each epoch
//   36..   ciphertext of [channel length u8][channel][payload], then the 16-byte Poly1305 tag
// The 36 header bytes travel in the clear and are the AEAD's associated data. The 24-byte nonce
// is salt || counter: never repeated under one subkey, since the counter never repeats within a
// sealer's epoch and two sealers (or one restarted) draw different salts.
inline constexpr uint8_t kMagic = 0xAE;
inline constexpr uint8_t kVersion = 1;
inline constexpr size_t kHeaderSize = 36;
inline constexpr size_t kSaltSize = 16;
inline constexpr size_t kTagSize = 16;
inline constexpr size_t kMaxChannel = 63;       // as LCM's channel names
inline constexpr size_t kMaxDatagram = 65507;   // the largest UDP payload over IPv4
// The largest payload whatever the channel name: the datagram still fits kMaxDatagram.
inline constexpr size_t kMaxPayload = kMaxDatagram - kHeaderSize - kTagSize - 1 - kMaxChannel;
// A datagram with a one-byte channel name and an empty payload.
inline constexpr size_t kMinDatagram = kHeaderSize + 1 + 1 + kTagSize;
// Bytes a datagram adds to channel + payload.
inline constexpr size_t kOverhead = kHeaderSize + 1 + kTagSize;

// A channel name the door carries: 1..kMaxChannel printable ASCII characters, no space.
bool valid_channel(std::string_view channel);

// --- sealing --------------------------------------------------------------------------------------
// When the sealer moves to the next epoch (WireGuard's REKEY_AFTER_TIME and REKEY_AFTER_MESSAGES).
struct RekeyPolicy {
  double seconds = 120.0;
  uint64_t messages = uint64_t{1} << 60;
  void validate() const;  // throws std::invalid_argument naming the field
};

class Sealer {
 public:
  // `now_s` starts the first epoch's clock (any time base: wall or simulation seconds, the same
  // one later calls give). A sender id must be unique per direction; a restarted sender should
  // start at an epoch it has not used (its old counters are refused as replays otherwise).
  Sealer(const SecretKey& mission_key, Direction direction, uint32_t sender, uint32_t epoch, double now_s,
         RekeyPolicy policy = {});

  // One datagram (rekeying first when the policy says so). Throws std::invalid_argument for a
  // channel name that is not valid_channel() or a payload over kMaxPayload (naming which).
  [[nodiscard]] std::vector<uint8_t> seal(std::string_view channel, std::span<const uint8_t> payload, double now_s);
  // The same into `out` (resized), reusing its storage.
  void seal_into(std::string_view channel, std::span<const uint8_t> payload, double now_s,
                 std::vector<uint8_t>& out);
  // Moves to the next epoch now (new subkey, new salt, counter back to 1).
  void rekey(double now_s);

  Direction direction() const { return direction_; }
  uint32_t sender() const { return sender_; }
  uint32_t epoch() const { return epoch_; }
  uint64_t next_counter() const { return counter_; }
  uint64_t sealed() const { return sealed_; }  // datagrams sealed, all epochs

 private:
  void start_epoch(uint32_t epoch, double now_s);

  SecretKey mission_;
  SecretKey subkey_;
  Direction direction_;
  uint32_t sender_;
  RekeyPolicy policy_;
  uint32_t epoch_ = 0;
  double epoch_start_s_ = 0;
  uint64_t counter_ = 1;
  uint64_t sealed_ = 0;
  std::array<uint8_t, kSaltSize> salt_{};
};

// --- opening ----------------------------------------------------------------------------------
enum class Refusal : uint8_t {
  None = 0,
  TooShort,          // shorter than kMinDatagram
  Oversize,          // longer than kMaxDatagram, or a payload over kMaxPayload
  BadVersion,        // not magic 0xAE version 1, or unknown flag / reserved bits
  WrongDirection,    // the other direction's datagram (a reflection)
  UnknownEpoch,      // more than max_epochs_ahead epochs ahead
  ExpiredEpoch,      // an epoch before the previous one, or the previous one after the overlap
  TooManySenders,    // a new sender while max_senders are known
  Replayed,          // the sender's counter was opened already
  TooOld,            // left of the replay window
  CounterExhausted,  // a counter at or past ReplayWindow::kRejectAfter
  AuthFailed,        // the tag does not verify: another key, or a tampered header or body
  ChannelMalformed,  // channel length 0, over kMaxChannel, past the end, or not printable
  kCount
};
inline constexpr size_t kRefusalCount = static_cast<size_t>(Refusal::kCount);
const char* to_string(Refusal r);  // "authentication failed", ...

struct Opened {
  Refusal refusal = Refusal::None;
  std::string why;  // what was wrong, for a log line (names no secret)
  std::string channel;
  std::vector<uint8_t> payload;
  uint32_t sender = 0;
  uint32_t epoch = 0;
  uint64_t counter = 0;
  bool ok() const { return refusal == Refusal::None; }
  explicit operator bool() const { return ok(); }
};

struct OpenerConfig {
  Direction direction = Direction::AirToGround;  // the direction this opener receives
  double overlap_s = 5.0;          // how long the previous epoch still opens after a sender's switch
  uint32_t max_epochs_ahead = 64;  // a sender's epoch may jump at most this far ahead
  uint32_t min_epoch = 0;          // epochs below are expired (a restarted receiver's floor)
  size_t max_senders = 16;         // senders tracked (only authenticated datagrams make one known)
  void validate() const;           // throws std::invalid_argument naming the field
};

// What an opener did, per reason: the numbers for a status message.
struct OpenerCounters {
  uint64_t opened = 0;
  std::array<uint64_t, kRefusalCount> refused{};  // indexed by Refusal; [None] stays 0
  uint64_t operator[](Refusal r) const { return refused[static_cast<size_t>(r)]; }
  uint64_t refused_total() const;
};

class Opener {
 public:
  Opener(const SecretKey& mission_key, OpenerConfig config);

  // Never throws on any input: a refusal is returned and counted.
  [[nodiscard]] Opened open(std::span<const uint8_t> datagram, double now_s);
  // The same into `out` (its storage reused); returns out.ok().
  [[nodiscard]] bool open_into(std::span<const uint8_t> datagram, double now_s, Opened& out);

  const OpenerCounters& counters() const { return counters_; }
  const OpenerConfig& config() const { return config_; }
  // A sender's current epoch, or -1 before its first authenticated datagram.
  int64_t current_epoch(uint32_t sender) const;

 private:
  struct SenderState {
    uint32_t sender = 0;
    uint32_t epoch = 0;
    double since_s = 0;  // when `epoch` became current
    bool has_previous = false;
    ReplayWindow current;
    ReplayWindow previous;
  };
  struct CachedKey {
    bool valid = false;
    uint32_t epoch = 0;
    SecretKey key;
  };
  const SecretKey& subkey(uint32_t epoch);
  bool refuse(Opened& out, Refusal r, std::string why);

  SecretKey mission_;
  OpenerConfig config_;
  OpenerCounters counters_;
  std::vector<SenderState> senders_;
  std::array<CachedKey, 4> keys_;
  size_t next_key_slot_ = 0;
  std::vector<uint8_t> plain_;
};

// The per-epoch, per-direction subkey: crypto_kdf_derive_from_key(mission key, context
// "aerielnk", subkey id = epoch * 2 + direction).
SecretKey derive_subkey(const SecretKey& mission_key, uint32_t epoch, Direction direction);

}  // namespace aerie::seal
