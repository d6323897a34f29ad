#pragma once
// One half of the door (aerie-link --half air|ground; docs/link.md "The two halves"): joins
// its host's LCM network (ttl=0, it stays on the host) to a UDP socket towards the other
// half, as libbot2's bot-lcm-tunnel joins two LCM networks, and seals every datagram between
// the halves (tools/link/door.hpp, common/seal/seal.hpp).
//
//   outgoing: LCM (the direction's `channels`) -> impairments (Relay: delay, loss, bandwidth,
//             JPEG; as the emulator) -> DoorSender (frame, fragment, seal) -> UDP to the peer
//   incoming: UDP -> DoorReceiver (open, reassemble, policy: channels + rate limits) -> LCM
//
// Status on STATUS_LINK_AIR / STATUS_LINK_GROUND (bus::Node "link-air" / "link-ground": both
// halves' status reach the ground station, so each has its own channel): counters per
// direction, the key's fingerprint, the epoch, SECURE or INSECURE (health WARN, every
// period). LINK_STATS as the emulator, for the half's outgoing direction.
#include <netinet/in.h>

#include <cstdint>
#include <memory>
#include <optional>
#include <string>
#include <vector>

#include "common/bus/node.hpp"
#include "common/seal/keys.hpp"
#include "tools/link/door.hpp"
#include "tools/link/echo_filter.hpp"
#include "tools/link/link_config.hpp"
#include "tools/link/relay.hpp"

namespace aerie::link {

// "ADDR:PORT" (IPv4, numeric); throws std::invalid_argument naming `what` and the text.
sockaddr_in parse_endpoint(const std::string& text, const std::string& what);

// A UDP socket bound to `listen` (non-blocking). Created before the half joins its LCM
// network, so that with --lcm-netns it belongs to the radio's namespace and LCM's to the nodes'.
class UdpSocket {
 public:
  explicit UdpSocket(const std::string& listen);
  ~UdpSocket();
  UdpSocket(const UdpSocket&) = delete;
  UdpSocket& operator=(const UdpSocket&) = delete;
  int fd() const { return fd_; }
  uint16_t port() const;  // the bound port (for listen port 0)

 private:
  int fd_ = -1;
};

// The operator's keys beside the mission key (common/seal/operator.hpp, docs/security.md "Roles").
struct CommandKeys {
  std::optional<seal::OperatorKey> operator_key;   // the ground half: signs the operator's commands
  std::vector<seal::OperatorPublicKey> operators;  // the air half: whose commands it accepts
};

struct HalfOptions {
  Half half = Half::kAir;
  std::string peer;       // ADDR:PORT of the other half
  uint32_t sender = 0;    // this half's sender id; 0 = random (a restart is a new sender)
  uint32_t first_epoch = 0;
};

class DoorHalf final : public bus::Node {
 public:
  // key null = insecure (the caller has checked that --insecure was said). A secure air half
  // needs the operators' public keys when the config names operator's channels (throws
  // std::invalid_argument saying so); a secure ground half without an operator key sends no
  // command (telemetry only: the commands are refused and counted).
  DoorHalf(bus::Bus& bus, UdpSocket& socket, const LinkConfig& config, HalfOptions options,
           const seal::SecretKey* key, CommandKeys commands = {});

  // Sends what the impairments release, expires reassembly, refreshes the status. The half's
  // clock is monotonic (the impairments' and the sealer's): `now_us` (wall) is not used.
  void tick(int64_t now_us) override;
  // Reads the datagrams waiting on the socket (at most 4096 per call); returns how many.
  int receive_datagrams();
  // The live loop: bus::run's shape with a second descriptor -- ppoll on LCM, the socket and
  // the impairments' next event; tick(); status -- until stop is requested (SIGINT/SIGTERM).
  void run();

  bool secure() const { return key_ != nullptr; }
  const std::string& fingerprint() const { return fingerprint_; }
  const SenderCounters& sent() const { return sender_.counters(); }
  const ReceiverCounters& received() const { return receiver_.counters(); }
  const LinkDirection& impairments() const { return relay_.model(); }
  // The status message, "SECURE key 3fa2:... epoch 2 peer epoch 2" or "INSECURE: ...".
  std::string status_line() const;
  void refresh_status();

 private:
  double now_s() const;
  void send_due(int64_t now_us);
  void send_hello();
  void publish_stats(int64_t now_us);

  UdpSocket& socket_;
  LinkConfig config_;
  HalfOptions options_;
  const seal::SecretKey* key_;
  std::string fingerprint_;
  std::string roles_;  // the operator's part of the status line
  seal::Session session_{};  // the air half's, announced in its hellos
  int64_t last_hello_us_ = 0;  // the last hello (air) or request for one (ground)
  sockaddr_in peer_{};
  Relay relay_;
  DoorSender sender_;
  DoorReceiver receiver_;
  ChannelMatcher out_channels_;
  EchoFilter echo_;
  std::vector<std::vector<uint8_t>> datagrams_;
  std::vector<uint8_t> buffer_;
  uint64_t send_errors_ = 0, oversize_in_ = 0;
  std::vector<double> delays_ms_;
  int64_t bytes_at_period_start_ = 0;
  int64_t next_stats_us_ = 0;
  int64_t stats_seq_ = 0;
  int64_t last_refresh_us_ = 0;
  std::string last_refusal_;
};

}  // namespace aerie::link
