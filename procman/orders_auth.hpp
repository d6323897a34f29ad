#pragma once
// Keyed procman (issue 46 section 3; docs/procman.md "Keyed mode"): a sheriff holding the
// mission key tags its orders, and a keyed deputy obeys only tagged, fresh, unreplayed orders
// from the one sheriff it follows. Transport-free: the nodes move the bytes over LCM on
// kSealedOrdersChannel; PMD_ORDERS2 and bot_procman.orders2_t are unchanged (libbot2's).
//
// Orders are not secret (every deputy report shows the exec strings) but must be authentic,
// fresh and unreplayable, so they are authenticated, not encrypted: HMAC-SHA-512-256
// (libsodium crypto_auth) under a subkey of the mission key of procman's own (crypto_kdf,
// context "aeriepmd"), so that a tag made for procman never verifies as the link's AEAD and
// the reverse (the link derives its subkeys with context "aerielnk", common/seal/seal.hpp).
//
// Wire layout (integers little-endian), the whole LCM payload on PMD_ORDERS2_SEALED:
//   0       magic 0xAF
//   1       version 1
//   2       flags: bit 0 "leaving" (the sheriff's last orders: it exits); bits 1-7 zero
//   3       reserved, zero
//   4..7    sender id (u32, != 0): the sheriff's id, random per session or --sheriff-id
//   8..15   counter (u64): rises with every message of a sender (MAVLink 2 signing's
//           timestamp rule): max(previous + 1, the sheriff's wall clock in microseconds),
//           so a restarted sheriff with the same id stays above its old counters
//   16..n-33 bot_procman.orders2_t, LCM-encoded (fingerprint included)
//   n-32..  tag: HMAC-SHA-512-256 over bytes 0..n-33
//
// Freshness, checked by OrdersGate after the tag: the orders' own utime within +-window_s of
// the deputy's clock (both ways: orders dated ten years ahead are refused), AND a counter
// above the last one accepted from that sender, persisted in a small state file before the
// orders are applied, so a replay after a deputy restart is refused too.
#include <bot_procman/orders2_t.hpp>

#include <array>
#include <cstddef>
#include <cstdint>
#include <map>
#include <set>
#include <span>
#include <string>
#include <utility>
#include <vector>

#include "common/seal/keys.hpp"

namespace aerie::procman {

inline constexpr uint8_t kSealedOrdersMagic = 0xAF;
inline constexpr uint8_t kSealedOrdersVersion = 1;
inline constexpr size_t kSealedOrdersHeader = 16;
inline constexpr size_t kSealedOrdersTag = 32;  // crypto_auth_hmacsha512256_BYTES
inline constexpr size_t kMaxSealedOrders = size_t{16} << 20;
inline constexpr uint8_t kSealedOrdersLeaving = 0x01;  // flags bit 0

// procman's own subkey: crypto_kdf_derive_from_key(mission key, id 1, context "aeriepmd").
seal::SecretKey derive_orders_key(const seal::SecretKey& mission_key);

// The sheriff's side: tags orders.
class OrdersSigner {
 public:
  // sender: != 0 (throws std::invalid_argument otherwise).
  OrdersSigner(const seal::SecretKey& mission_key, uint32_t sender);
  // The sealed message for `orders` (whose utime the caller set); now_utime: the wall clock.
  // leaving: the sheriff's last orders before it exits (a deputy that followed it is free to
  // follow the next sheriff at once instead of after handover_s of silence).
  std::vector<uint8_t> sign(const bot_procman::orders2_t& orders, int64_t now_utime, bool leaving = false);
  // The same with a counter of the caller's choice (tests: forged or replayed counters).
  std::vector<uint8_t> sign_with_counter(const bot_procman::orders2_t& orders, uint64_t counter,
                                         bool leaving = false) const;
  uint32_t sender() const { return sender_; }
  uint64_t last_counter() const { return counter_; }

 private:
  seal::SecretKey key_;
  uint32_t sender_;
  uint64_t counter_ = 0;
};

// A sealed message whose tag verified (header fields authenticated).
struct VerifiedOrders {
  uint32_t sender = 0;
  uint64_t counter = 0;
  bool leaving = false;
  bot_procman::orders2_t orders;
};

// Why orders were not obeyed; the deputy counts each as its status counter (counter_name).
enum class OrdersRefusal : uint8_t {
  None = 0,
  Unauthenticated,  // plain PMD_ORDERS2 reached a keyed deputy
  Malformed,        // too short or long, bad magic/version/reserved bits, or undecodable orders
  AuthFailed,       // the tag does not verify: another key, or a tampered message
  TooOld,           // the orders' utime is more than window_s behind the deputy's clock
  FromFuture,       // ... or more than window_s ahead of it
  Replayed,         // counter not above the last one accepted from that sender
  OtherSheriff,     // a valid keyed sheriff, but not the one this deputy follows
  kCount
};
inline constexpr size_t kOrdersRefusalCount = static_cast<size_t>(OrdersRefusal::kCount);
const char* to_string(OrdersRefusal r);     // "authentication failed", ...
const char* counter_name(OrdersRefusal r);  // "orders_auth_failed", ...

// Checks tag and layout only (no freshness, no state). Returns the refusal (None when ok);
// `why` says what was wrong (never a secret). Never throws on network input.
OrdersRefusal verify_sealed_orders(const seal::SecretKey& orders_key, std::span<const uint8_t> bytes,
                                   VerifiedOrders& out, std::string* why = nullptr);

struct GateOptions {
  double window_s = 60.0;        // |deputy clock - orders.utime| at most this
  uint32_t follow_sheriff = 0;   // 0: follow the first valid sheriff heard; else only this id
  double handover_s = 10.0;      // when following the first heard: another keyed sheriff may take
                                 // over once the followed one has been silent this long (0: never)
                                 // or at once after the followed one's "leaving" orders
  double conflict_hold_s = 10.0;  // "two sheriffs" stays reported this long after the last rival
  std::string state_path;        // the counters' state file ("" = not persisted)
  size_t max_senders = 64;       // counters kept (the lowest is forgotten beyond)
  void validate() const;         // throws std::invalid_argument naming the field
};

struct GateVerdict {
  OrdersRefusal refusal = OrdersRefusal::None;
  bool other_host = false;  // valid, but addressed to another deputy: ignore, not a refusal
  bool first = false;       // the first refusal of this reason from this sender: log it
  std::string why;          // names the sender and what was wrong
  std::string notice;       // something to say loudly (a sheriff change, a second sheriff)
  uint32_t sender = 0;
  uint64_t counter = 0;
  bot_procman::orders2_t orders;  // set when refusal == None and !other_host
  bool accepted() const { return refusal == OrdersRefusal::None && !other_host; }
};

// The keyed deputy's gate: everything between an LCM payload and Deputy::handle_orders.
class OrdersGate {
 public:
  // Loads the state file if it exists (throws std::runtime_error naming it and the line when
  // it is unreadable or malformed: a deputy must not forget what it accepted).
  OrdersGate(const seal::SecretKey& mission_key, std::string host, GateOptions options);

  // A PMD_ORDERS2_SEALED payload. now_utime: wall clock; now_ms: monotonic. Never throws.
  GateVerdict check(std::span<const uint8_t> bytes, int64_t now_utime, int64_t now_ms);
  // Plain PMD_ORDERS2 heard by a keyed deputy: always refused (Unauthenticated).
  GateVerdict refuse_plain(const bot_procman::orders2_t& orders);

  uint64_t refused(OrdersRefusal r) const { return refused_[static_cast<size_t>(r)]; }
  uint64_t accepted() const { return accepted_; }
  uint64_t state_write_errors() const { return state_write_errors_; }
  // "two sheriffs: following 'A' (id 1), refusing 'B' (id 2)" while a rival was heard within
  // conflict_hold_s; "" otherwise.
  std::string conflict(int64_t now_ms) const;
  uint32_t following() const { return follow_; }
  const std::string& following_name() const { return follow_name_; }
  const std::string& fingerprint() const { return fingerprint_; }
  const std::map<uint32_t, uint64_t>& counters() const { return last_; }

 private:
  GateVerdict refuse(GateVerdict v, OrdersRefusal r, std::string why, const std::string& who);
  void load_state();
  bool save_state(std::string* error);

  seal::SecretKey key_;
  std::string host_;
  GateOptions options_;
  std::string fingerprint_;
  std::map<uint32_t, uint64_t> last_;  // sender -> last accepted counter
  uint32_t follow_ = 0;
  std::string follow_name_;
  int64_t follow_heard_ms_ = 0;
  uint32_t rival_ = 0;
  std::string rival_name_;
  int64_t rival_heard_ms_ = -1;
  std::array<uint64_t, kOrdersRefusalCount> refused_{};
  uint64_t accepted_ = 0;
  uint64_t state_write_errors_ = 0;
  std::set<std::pair<OrdersRefusal, std::string>> logged_;
};

}  // namespace aerie::procman
