#pragma once
// The door between air and ground (issue 46 sections 1 and 2; docs/link.md "The two halves",
// docs/security.md "The sealed door"): what one half of aerie-link does to an LCM message on
// its way to the other half (DoorSender: frame, fragment, seal) and to a datagram that comes
// from it (DoorReceiver: open, reassemble, check the per-channel policy). No LCM, no sockets,
// no clock: the caller gives the time (seconds, any monotonic base).
//
// Each sealed datagram's payload (seal.hpp) is a frame:
//   0      kind: 0 a whole LCM message, 1 a fragment of one
//   whole:    1.. the message
//   fragment: 1..4 message id (u32, per sender), 5..6 index (u16), 7..8 count (u16),
//             9..12 total size (u32), 13..16 offset (u32), 17.. the fragment's bytes
//   hello:    kind 2, sealed only, on the reserved channel kHelloChannel. Air -> ground: 1..16
//             the air half's session (common/seal/operator.hpp), for which the ground half signs
//             the operator's commands; ground -> air, empty: a request for it (a ground half that
//             has none, or whose commands were refused for another session)
// Integers little-endian. A message that does not fit one datagram is cut into fragments,
// each sealed on its own, and reassembled by the receiver in a bounded buffer
// (ReassemblyLimits); a message over max_message_bytes is refused at the sender and counted.
//
// Without a key (--insecure, said explicitly) the same frames travel in the clear after a
// distinct 5-byte header [kInsecureMagic, version 1, direction bit, 0, channel length] and the
// channel: a secure half refuses them ("insecure_peer") and an insecure half refuses sealed
// datagrams ("secure_peer"), so a secure and an insecure half never connect.
#include <cstdint>
#include <functional>
#include <map>
#include <optional>
#include <span>
#include <string>
#include <string_view>
#include <utility>
#include <vector>

#include "common/seal/operator.hpp"
#include "common/seal/seal.hpp"
#include "tools/link/relay.hpp"

namespace aerie::link {

inline constexpr uint8_t kInsecureMagic = 0xA1;
inline constexpr uint8_t kInsecureVersion = 1;
inline constexpr size_t kWholeHeader = 1;
inline constexpr size_t kFragmentHeader = 17;
inline constexpr char kHelloChannel[] = "#hello";  // never an LCM channel ('#' starts none of Aerie's)

enum class Half { kAir, kGround };
Half half_from_name(const std::string& name);  // air | ground; throws std::invalid_argument naming it
const char* half_name(Half h);
seal::Direction outgoing(Half h);  // air sends air->ground
seal::Direction incoming(Half h);
// "air_to_ground" / "ground_to_air": the prefix of a direction's status counters and config block.
const char* direction_key(seal::Direction d);

// --- per-channel rate limits (token buckets) --------------------------------------------------
struct RateRule {
  std::string channels;          // LCM channel regex (whole names) the rule applies to
  double messages_per_s = 0;     // 0 = no limit on messages
  double message_burst = 0;      // bucket depth in messages; 0 = one second's worth (at least 1)
  double bytes_per_s = 0;        // 0 = no limit on bytes
  double byte_burst = 0;         // bucket depth in bytes; 0 = one second's worth
  void validate() const;         // throws std::invalid_argument naming the field
};

class TokenBucket {
 public:
  TokenBucket() = default;
  TokenBucket(double rate_per_s, double burst);  // rate 0 = unlimited
  // Takes n tokens at now_s when there are that many (refilled at the rate, up to the burst).
  bool take(double n, double now_s);

 private:
  double rate_ = 0, burst_ = 0, tokens_ = 0, last_s_ = 0;
  bool started_ = false;
};

// Each channel gets its own buckets from the first rule whose regex matches it; a channel no
// rule matches is not limited. At most kMaxChannels channels get buckets: a new channel past
// that is refused (a valid sender cycling names must not grow the receiver without bound).
class RateLimiter {
 public:
  static constexpr size_t kMaxChannels = 1024;
  explicit RateLimiter(std::vector<RateRule> rules);
  bool admit(const std::string& channel, size_t bytes, double now_s);

 private:
  struct Buckets {
    bool limited = false;
    TokenBucket messages, bytes;
  };
  std::vector<RateRule> rules_;
  std::vector<ChannelMatcher> matchers_;
  std::map<std::string, Buckets> channels_;
};

// What may cross one direction: the channels (regex, whole names; "" = nothing), their rates,
// and the operator's channels (regex; "" = none): commands that must also carry the operator's
// signature (common/seal/operator.hpp) -- checked on ground -> air only, by a secure half.
struct DoorPolicy {
  std::string channels;
  std::vector<RateRule> rates;
  std::string operator_channels;
};
// The operator's commands, as config/link.yaml names them by default.
inline constexpr char kDefaultOperatorChannels[] =
    "PILOT_CMD|TRACK_CMD|FLC_PARAMS|MAP_CMD|PMD_ORDERS2|PMD_ORDERS2_SEALED";

struct ReassemblyLimits {
  size_t max_message_bytes = 8u << 20;   // a larger message is refused (sender) / dropped (receiver)
  size_t max_pending_bytes = 32u << 20;  // bytes held for messages not yet complete
  size_t max_pending_messages = 8;       // messages being reassembled at once
  double timeout_s = 2.0;                // an incomplete message is dropped after this
  size_t max_datagram_bytes = seal::kMaxDatagram;  // the largest datagram sent (an MTU on a real radio)
  void validate() const;                 // throws std::invalid_argument naming the field
};

// --- sending ---------------------------------------------------------------------------------
struct SenderCounters {
  uint64_t messages = 0;    // LCM messages sent
  uint64_t datagrams = 0;   // datagrams made (whole + fragments)
  uint64_t fragments = 0;   // of which fragments
  uint64_t bytes = 0;       // datagram bytes
  uint64_t too_large = 0;   // refused: over max_message_bytes
  uint64_t signed_commands = 0;    // operator's commands signed for the air half's session
  uint64_t unsigned_commands = 0;  // refused: an operator's channel, and this half has no operator key
  uint64_t no_session = 0;         // refused: an operator's command before the air half's first hello
  uint64_t hellos = 0;             // sessions announced (air half) or asked for (ground half)
};

class DoorSender {
 public:
  // key null: insecure (frames in the clear). sender: this half's id; epoch: its first epoch.
  DoorSender(const seal::SecretKey* key, seal::Direction direction, uint32_t sender, uint32_t epoch, double now_s,
             seal::RekeyPolicy rekey = {}, ReassemblyLimits limits = {});
  // The datagrams of one message, in order (replacing `out`). False (and counted) when the
  // message is over max_message_bytes; throws std::invalid_argument for an invalid channel.
  bool send(std::string_view channel, std::span<const uint8_t> payload, double now_s,
            std::vector<std::vector<uint8_t>>& out);
  // The same, handing each datagram to `sink` as soon as it is sealed (valid during the call):
  // the halves send it at once, so that the far half opens one fragment while this one seals
  // the next.
  using DatagramSink = std::function<void(std::span<const uint8_t>)>;
  bool send(std::string_view channel, std::span<const uint8_t> payload, double now_s, const DatagramSink& sink);
  // The ground half: messages on `operator_channels` (regex) are signed with `signer` for the
  // air half's session (set_session); without a signer they are refused and counted. Only a
  // secure sender signs (an insecure door authenticates nothing).
  void sign_commands(const std::string& operator_channels, std::optional<seal::CommandSigner> signer);
  void set_session(const seal::Session& session) { session_ = session; }
  bool has_session() const { return session_.has_value(); }
  // The air half: the datagram announcing its session (secure only; false when insecure).
  bool hello(const seal::Session& session, double now_s, std::vector<uint8_t>& out);
  // The ground half: the datagram asking for it (secure only).
  bool hello_request(double now_s, std::vector<uint8_t>& out);

  bool secure() const { return sealer_.has_value(); }
  uint32_t epoch() const { return sealer_ ? sealer_->epoch() : 0; }
  void rekey(double now_s) {
    if (sealer_) sealer_->rekey(now_s);
  }
  const SenderCounters& counters() const { return counters_; }

 private:
  void emit(std::string_view channel, std::span<const uint8_t> frame, double now_s, std::vector<uint8_t>& out);

  bool emit_hello(std::span<const uint8_t> body, double now_s, std::vector<uint8_t>& out);
  bool split(std::string_view channel, std::span<const uint8_t> payload, double now_s, const DatagramSink& sink);

  std::optional<seal::Sealer> sealer_;
  seal::Direction direction_;
  ReassemblyLimits limits_;
  uint32_t next_message_ = 1;
  std::vector<uint8_t> frame_, datagram_;
  ChannelMatcher operator_channels_{""};
  std::optional<seal::CommandSigner> signer_;
  std::optional<seal::Session> session_;
  SenderCounters counters_;
};

// --- receiving -------------------------------------------------------------------------------
struct ReceiverCounters {
  uint64_t datagrams = 0;            // datagrams received
  uint64_t fragments = 0;            // authentic fragments received
  uint64_t delivered = 0;            // LCM messages handed on (whole or reassembled)
  uint64_t bytes_delivered = 0;
  uint64_t not_allowed = 0;          // authentic, but the channel may not cross this way
  uint64_t rate_limited = 0;         // authentic and allowed, over its channel's rate
  uint64_t insecure_peer = 0;        // a datagram in the clear reached a secure half
  uint64_t secure_peer = 0;          // a sealed datagram reached an insecure half
  uint64_t malformed = 0;            // an authentic datagram whose frame is not valid
  uint64_t reassembly_dropped = 0;   // an incomplete message dropped (timeout, limits, too large)
  uint64_t too_large = 0;            // an authentic message over max_message_bytes (whole or announced)
  uint64_t hellos = 0;               // session announcements (ground half) or requests (air half)
  uint64_t commands_verified = 0;    // operator's commands whose signature verified (air half)
  std::array<uint64_t, seal::kCommandRefusalCount> commands_refused{};  // by seal::CommandRefusal
  seal::OpenerCounters opener;       // opened + refused per seal::Refusal (secure only)
};

struct Delivered {
  std::string channel;
  std::vector<uint8_t> payload;
};

class DoorReceiver {
 public:
  // key null: insecure. `direction`: the direction this half receives.
  DoorReceiver(const seal::SecretKey* key, seal::Direction direction, DoorPolicy policy,
               seal::OpenerConfig opener = {}, ReassemblyLimits limits = {});
  // Never throws on network input: a message to publish, or nullopt (a fragment kept for
  // later, or a refusal counted; why() says what).
  std::optional<Delivered> receive(std::span<const uint8_t> datagram, double now_s);
  // Drops incomplete messages older than the timeout.
  void expire(double now_s);
  // The air half (secure): the operator's channels of the policy must carry a signature this
  // verifier accepts. Without one, a secure receiver refuses every operator's command (unsigned).
  void require_operator(seal::CommandVerifier verifier) { verifier_.emplace(std::move(verifier)); }
  // The ground half: the air half's session from its latest authentic hello.
  const std::optional<seal::Session>& peer_session() const { return peer_session_; }
  // The air half: whether the ground half asked for the session (a request, or a command signed
  // for another session) since the last call.
  bool take_hello_request() { return std::exchange(hello_wanted_, false); }

  bool secure() const { return opener_.has_value(); }
  const ReceiverCounters& counters() const;
  const std::string& why() const { return why_; }
  // The far half's current epoch (its latest authentic sender), -1 before the first.
  int64_t peer_epoch() const;

 private:
  struct Pending {
    std::string channel;
    uint32_t total = 0;
    uint16_t count = 0;
    uint16_t received = 0;
    size_t bytes = 0;
    double first_s = 0;
    std::vector<bool> have;
    std::vector<uint8_t> data;
  };
  std::optional<Delivered> on_frame(uint32_t sender, std::string_view channel, std::span<const uint8_t> frame,
                                    double now_s);
  std::optional<Delivered> admit(std::string channel, std::vector<uint8_t> payload, double now_s);
  bool on_hello(const std::string& channel, std::span<const uint8_t> frame);
  void drop(std::map<uint64_t, Pending>::iterator it);
  bool refuse(uint64_t& counter, std::string why);

  std::optional<seal::Opener> opener_;
  seal::Direction direction_;
  ChannelMatcher allowed_;
  ChannelMatcher operator_channels_;  // ground -> air only
  std::optional<seal::CommandVerifier> verifier_;
  std::optional<seal::Session> peer_session_;
  bool hello_wanted_ = false;
  RateLimiter rates_;
  ReassemblyLimits limits_;
  std::map<uint64_t, Pending> pending_;  // key: sender << 32 | message id
  size_t pending_bytes_ = 0;
  uint32_t last_sender_ = 0;
  bool any_sender_ = false;
  seal::Opened opened_;
  std::string why_;
  mutable ReceiverCounters counters_;
};

}  // namespace aerie::link
