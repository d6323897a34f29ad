#pragma once
// The operator's signature on commands (issue 46 section 2, "who may send them"; docs/security.md
// "Roles: the mission key and the operator's key"). The mission key seals every datagram between
// the link's halves, so it proves that a datagram came from one of the halves -- and every host
// holding it (the air host, a ground station that only watches) could seal a command. A command
// must therefore also carry the operator's Ed25519 signature (libsodium crypto_sign_detached):
// the air half holds only the operator's public key, so neither the vehicle itself nor a
// telemetry-only ground station can issue commands.
//
// Freshness without clocks: the air half draws a random session at start and announces it, sealed,
// to the ground half (tools/link/door.hpp, the "hello" frame); the operator signs the session with
// each command, with a counter rising per session (a WireGuard window, replay_window.hpp). A command
// captured and re-sealed by a mission-key holder is refused as replayed; one recorded before the air
// half restarted is refused for its old session.
//
// Envelope: the command's bytes as they cross (the door frames and seals the whole envelope):
//   0..15   session (the air half's)
//   16..23  counter (u64 little-endian; 1, 2, ... per session)
//   24..87  Ed25519 signature over "aerie-cmd1" || session || counter || channel length (u8) ||
//           channel || payload
//   88..    the payload, unchanged
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

inline constexpr size_t kSessionSize = 16;
inline constexpr size_t kSignatureSize = 64;  // crypto_sign_BYTES
inline constexpr size_t kCommandOverhead = kSessionSize + 8 + kSignatureSize;
using Session = std::array<uint8_t, kSessionSize>;
Session new_session();  // randombytes_buf: a fresh one at every start of the air half

// The operator's public key: 32 bytes in FILE.pub next to the secret key file (it is not secret;
// the air half reads it).
struct OperatorPublicKey {
  static constexpr size_t kSize = 32;  // crypto_sign_PUBLICKEYBYTES
  std::array<uint8_t, kSize> bytes{};
  // Throws std::runtime_error naming the file: missing, not a regular file, not 32 bytes.
  static OperatorPublicKey load(const std::string& path);
  void save(const std::string& path, bool overwrite = false) const;  // mode 0644
  std::string fingerprint() const;  // as the mission key's (keys.hpp), of the public bytes
};

// The operator's secret key: the Ed25519 seed (32 bytes) in a mode-0600 key file, read and
// written as the mission key is (util::read_key_file).
class OperatorKey {
 public:
  static OperatorKey generate();
  static OperatorKey from_seed(SecretKey seed);  // a key of known bytes (tests, fuzzing)
  static OperatorKey load(const std::string& path);
  void save(const std::string& path, bool overwrite = false) const;
  const OperatorPublicKey& public_key() const { return public_; }
  OperatorKey clone() const;
  // The detached signature of `message`.
  std::array<uint8_t, kSignatureSize> sign(std::span<const uint8_t> message) const;

  ~OperatorKey();  // zeroes the expanded secret (the seed zeroes itself)
  OperatorKey(OperatorKey&& other) noexcept;
  OperatorKey(const OperatorKey&) = delete;
  OperatorKey& operator=(const OperatorKey&) = delete;
  OperatorKey& operator=(OperatorKey&&) = delete;

 private:
  explicit OperatorKey(SecretKey seed);
  SecretKey seed_;
  std::array<uint8_t, 64> secret_{};  // libsodium's expanded secret key (seed || public key)
  OperatorPublicKey public_;
};

// The ground half's side: wraps each command for the air half's current session.
class CommandSigner {
 public:
  explicit CommandSigner(OperatorKey key);
  // The envelope of `payload` on `channel` (valid_channel, seal.hpp). A new session starts the
  // counter again at 1.
  std::vector<uint8_t> sign(const Session& session, std::string_view channel, std::span<const uint8_t> payload);
  // The same with a counter of the caller's choice (tests: replays and window edges).
  std::vector<uint8_t> sign_with_counter(const Session& session, uint64_t counter, std::string_view channel,
                                         std::span<const uint8_t> payload) const;
  const OperatorPublicKey& public_key() const { return key_.public_key(); }

 private:
  OperatorKey key_;
  Session session_{};
  uint64_t counter_ = 0;
};

enum class CommandRefusal : uint8_t {
  None = 0,
  Unsigned,      // shorter than an envelope: no signature at all
  OtherSession,  // signed for another session of the air half (an old recording, another vehicle)
  BadSignature,  // no operator key this half knows verifies it (forged, tampered, another operator)
  Replayed,      // this operator's counter was accepted already in this session
  TooOld,        // left of the replay window
  kCount
};
inline constexpr size_t kCommandRefusalCount = static_cast<size_t>(CommandRefusal::kCount);
const char* to_string(CommandRefusal r);  // "unsigned", "other session", ...

// The air half's side: checks the envelope of a command against the operators' public keys and
// the half's session; never throws on network input.
class CommandVerifier {
 public:
  // At least one operator (throws std::invalid_argument otherwise).
  CommandVerifier(std::vector<OperatorPublicKey> operators, Session session);
  // None: `payload` is set to the command's bytes (a view into `envelope`).
  CommandRefusal verify(std::string_view channel, std::span<const uint8_t> envelope, std::span<const uint8_t>& payload,
                        std::string& why);
  const Session& session() const { return session_; }
  const std::vector<OperatorPublicKey>& operators() const { return operators_; }

 private:
  std::vector<OperatorPublicKey> operators_;
  std::vector<ReplayWindow> windows_;  // one per operator
  Session session_;
};

}  // namespace aerie::seal
