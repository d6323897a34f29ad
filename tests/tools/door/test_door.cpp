// The door's two ends in process (tools/link/door.hpp, issue 46 sections 1, 2 and 4): sealed
// round trips whole and fragmented, the must-not-connect matrix (wrong key, secure against
// insecure both ways, a reflection, tampered, truncated and replayed datagrams), the
// per-channel policy of the shipped config (PMD_* never crosses, PILOT_CMD crosses up), rate
// limits with exact counts, bounded reassembly, and rekeying while messages flow (nothing
// lost, nothing duplicated).
#include <gtest/gtest.h>

#include <cstring>
#include <numeric>
#include <set>

#include "common/seal/operator.hpp"
#include "common/seal/seal.hpp"
#include "tests/support/test_support.hpp"
#include "tools/link/door.hpp"
#include "tools/link/link_config.hpp"

using namespace aerie;
using namespace aerie::link;
using seal::Direction;

namespace {

std::vector<uint8_t> bytes(size_t n, uint8_t seed) {
  std::vector<uint8_t> v(n);
  for (size_t i = 0; i < n; ++i) v[i] = static_cast<uint8_t>(seed + i * 31 + (i >> 8));
  return v;
}

std::vector<uint8_t> numbered(uint32_t i) {
  std::vector<uint8_t> v(12, 0);
  std::memcpy(v.data(), &i, 4);
  return v;
}

DoorPolicy anything() { return DoorPolicy{".*", {}, ""}; }

struct Pair {
  seal::SecretKey key = seal::SecretKey::generate();
  DoorSender tx;
  DoorReceiver rx;
  std::vector<std::vector<uint8_t>> out;
  explicit Pair(DoorPolicy policy = anything(), seal::RekeyPolicy rekey = {}, ReassemblyLimits limits = {},
                Direction d = Direction::GroundToAir)
      : tx(&key, d, 7, 0, 0.0, rekey, limits), rx(&key, d, std::move(policy), {}, limits) {}
  // The operator's role on this (ground -> air) pair: the receiver checks `operator_key`'s
  // signature for `session`, announced as the air half does; the sender signs.
  seal::Session session = seal::new_session();
  void with_operator(const seal::OperatorKey& operator_key, const std::string& channels = kDefaultOperatorChannels) {
    rx.require_operator(seal::CommandVerifier({operator_key.public_key()}, session));
    tx.sign_commands(channels, seal::CommandSigner(operator_key.clone()));
    tx.set_session(session);
  }
  // Sends one message and feeds every datagram to the receiver; what it delivered.
  std::vector<Delivered> cross(const std::string& channel, const std::vector<uint8_t>& payload, double t) {
    std::vector<Delivered> got;
    EXPECT_TRUE(tx.send(channel, payload, t, out));
    for (const auto& d : out)
      if (auto m = rx.receive(d, t)) got.push_back(std::move(*m));
    return got;
  }
};

}  // namespace

TEST(Door, SealedMessageCrossesWholeAndExact) {
  Pair p;
  const auto payload = bytes(1000, 3);
  const auto got = p.cross("PILOT_CMD", payload, 0.0);
  ASSERT_EQ(got.size(), 1u);
  EXPECT_EQ(got[0].channel, "PILOT_CMD");
  EXPECT_EQ(got[0].payload, payload);
  ASSERT_EQ(p.out.size(), 1u);
  EXPECT_EQ(p.out[0].size(), payload.size() + 1 + 9 + seal::kOverhead);  // frame kind + "PILOT_CMD"
  EXPECT_EQ(p.rx.counters().delivered, 1u);
  EXPECT_EQ(p.rx.counters().opener.opened, 1u);
  // The payload is not in the clear.
  const std::string wire(p.out[0].begin(), p.out[0].end());
  EXPECT_EQ(wire.find("PILOT_CMD"), std::string::npos);
}

TEST(Door, AStereoFrameIsFragmentedAndReassembledExactly) {
  Pair p(anything(), {}, {}, Direction::AirToGround);
  const auto frame = bytes(752 * 480 * 2 + 100, 9);  // a raw stereo_image_t's size
  const auto got = p.cross("CAM_STEREO", frame, 0.0);
  ASSERT_EQ(got.size(), 1u);
  EXPECT_EQ(got[0].payload, frame);
  const size_t room = seal::kMaxPayload - kFragmentHeader;
  EXPECT_EQ(p.out.size(), (frame.size() + room - 1) / room);
  EXPECT_EQ(p.tx.counters().fragments, p.out.size());
  EXPECT_EQ(p.rx.counters().fragments, p.out.size());
  for (const auto& d : p.out) EXPECT_LE(d.size(), seal::kMaxDatagram);
  // Fragments in reverse order reassemble too.
  ASSERT_TRUE(p.tx.send("CAM_STEREO", frame, 0.1, p.out));
  std::optional<Delivered> last;
  for (auto it = p.out.rbegin(); it != p.out.rend(); ++it) {
    auto m = p.rx.receive(*it, 0.1);
    if (m) last = std::move(m);
  }
  ASSERT_TRUE(last);
  EXPECT_EQ(last->payload, frame);
  EXPECT_EQ(p.rx.counters().delivered, 2u);
}

TEST(Door, SmallDatagramsForARadioMtu) {
  ReassemblyLimits mtu;
  mtu.max_datagram_bytes = 1400;
  Pair p(anything(), {}, mtu);
  const auto payload = bytes(10000, 1);
  const auto got = p.cross("MAP_RESPONSE", payload, 0);
  ASSERT_EQ(got.size(), 1u);
  EXPECT_EQ(got[0].payload, payload);
  for (const auto& d : p.out) EXPECT_LE(d.size(), 1400u);
  EXPECT_GE(p.out.size(), 8u);
}

TEST(Door, InsecureRoundTripInTheClear) {
  DoorSender tx(nullptr, Direction::GroundToAir, 1, 0, 0);
  DoorReceiver rx(nullptr, Direction::GroundToAir, anything());
  std::vector<std::vector<uint8_t>> out;
  ASSERT_TRUE(tx.send("TRACK_CMD", bytes(100, 2), 0, out));
  ASSERT_EQ(out.size(), 1u);
  EXPECT_EQ(out[0][0], kInsecureMagic);
  auto m = rx.receive(out[0], 0);
  ASSERT_TRUE(m);
  EXPECT_EQ(m->payload, bytes(100, 2));
  EXPECT_FALSE(tx.secure());
}

// --- must not connect ---------------------------------------------------------------------------

TEST(DoorMustNotConnect, WrongKeyNothingCrossesAuthFailedCounted) {
  const auto k1 = seal::SecretKey::generate(), k2 = seal::SecretKey::generate();
  DoorSender tx(&k1, Direction::GroundToAir, 1, 0, 0);
  DoorReceiver rx(&k2, Direction::GroundToAir, anything());
  std::vector<std::vector<uint8_t>> out;
  for (int i = 0; i < 5; ++i) {
    ASSERT_TRUE(tx.send("PILOT_CMD", bytes(40, 1), 0, out));
    EXPECT_FALSE(rx.receive(out[0], 0));
  }
  EXPECT_EQ(rx.counters().opener[seal::Refusal::AuthFailed], 5u);
  EXPECT_EQ(rx.counters().delivered, 0u);
  EXPECT_NE(rx.why().find("authentication failed"), std::string::npos) << rx.why();
}

TEST(DoorMustNotConnect, SecureAndInsecureHalvesRefuseEachOther) {
  const auto k = seal::SecretKey::generate();
  std::vector<std::vector<uint8_t>> out;
  // An insecure sender against a secure receiver.
  DoorSender clear(nullptr, Direction::GroundToAir, 1, 0, 0);
  DoorReceiver secure(&k, Direction::GroundToAir, anything());
  for (int i = 0; i < 3; ++i) {
    ASSERT_TRUE(clear.send("PILOT_CMD", bytes(40, 1), 0, out));
    EXPECT_FALSE(secure.receive(out[0], 0));
  }
  EXPECT_EQ(secure.counters().insecure_peer, 3u);
  EXPECT_EQ(secure.counters().delivered, 0u);
  // A secure sender against an insecure receiver.
  DoorSender sealed(&k, Direction::GroundToAir, 1, 0, 0);
  DoorReceiver open(nullptr, Direction::GroundToAir, anything());
  for (int i = 0; i < 4; ++i) {
    ASSERT_TRUE(sealed.send("PILOT_CMD", bytes(40, 1), 0, out));
    EXPECT_FALSE(open.receive(out[0], 0));
  }
  EXPECT_EQ(open.counters().secure_peer, 4u);
  EXPECT_EQ(open.counters().delivered, 0u);
}

TEST(DoorMustNotConnect, TamperedTruncatedReplayedAndReflectedAreRefusedAndCounted) {
  Pair p;
  ASSERT_TRUE(p.tx.send("PILOT_CMD", bytes(60, 5), 0, p.out));
  const auto good = p.out[0];
  // Every header byte and a body byte flipped: refused (bad version for magic/version/flags,
  // wrong direction for the direction bit, otherwise the tag).
  uint64_t refused = 0;
  for (size_t i : {size_t{0}, size_t{1}, size_t{2}, size_t{4}, size_t{8}, size_t{12}, size_t{20}, size_t{40}}) {
    auto bad = good;
    bad[i] ^= 0x01;
    EXPECT_FALSE(p.rx.receive(bad, 0)) << "byte " << i;
    ++refused;
  }
  const auto& c = p.rx.counters().opener;
  EXPECT_EQ(c.refused_total(), refused);
  EXPECT_EQ(c[seal::Refusal::BadVersion], 2u);      // magic, version
  EXPECT_EQ(c[seal::Refusal::WrongDirection], 1u);  // the direction bit
  EXPECT_EQ(c[seal::Refusal::AuthFailed], 5u);      // epoch, sender, counter, salt, body
  // Truncated: below the minimum, and cut inside the tag.
  EXPECT_FALSE(p.rx.receive(std::span<const uint8_t>(good.data(), 20), 0));
  EXPECT_FALSE(p.rx.receive(std::span<const uint8_t>(good.data(), good.size() - 1), 0));
  EXPECT_EQ(p.rx.counters().opener[seal::Refusal::TooShort], 1u);
  EXPECT_EQ(p.rx.counters().opener[seal::Refusal::AuthFailed], 6u);
  // The genuine datagram still opens once, then its replay is refused.
  EXPECT_TRUE(p.rx.receive(good, 0));
  EXPECT_FALSE(p.rx.receive(good, 100));
  EXPECT_EQ(p.rx.counters().opener[seal::Refusal::Replayed], 1u);
  EXPECT_EQ(p.rx.counters().delivered, 1u);
  // A ground->air datagram reflected to the ground half (which opens air->ground).
  DoorReceiver ground(&p.key, Direction::AirToGround, anything());
  EXPECT_FALSE(ground.receive(good, 0));
  EXPECT_EQ(ground.counters().opener[seal::Refusal::WrongDirection], 1u);
}

TEST(DoorMustNotConnect, ADatagramOfAnEpochTwoBackIsRefusedAsExpired) {
  seal::RekeyPolicy every10;
  every10.messages = 10;
  Pair p(anything(), every10);
  std::vector<std::vector<uint8_t>> captured;
  for (uint32_t i = 0; i < 25; ++i) {
    ASSERT_TRUE(p.tx.send("PILOT_CMD", numbered(i), i * 0.01, p.out));
    if (i == 0) captured = p.out;  // epoch 0
    ASSERT_TRUE(p.rx.receive(p.out[0], i * 0.01));
  }
  EXPECT_EQ(p.tx.epoch(), 2u);
  EXPECT_FALSE(p.rx.receive(captured[0], 1.0));
  EXPECT_EQ(p.rx.counters().opener[seal::Refusal::ExpiredEpoch], 1u);
}

// --- policy ----------------------------------------------------------------------------------

TEST(DoorPolicy, AChannelNotAllowedIsDroppedAndCountedBeforeReassembly) {
  Pair p(DoorPolicy{"PILOT_CMD|TRACK_CMD", {}, ""});
  EXPECT_EQ(p.cross("PILOT_CMD", bytes(10, 1), 0).size(), 1u);
  EXPECT_TRUE(p.cross("CTRL_CMD", bytes(10, 1), 0).empty());
  EXPECT_TRUE(p.cross("PMD_ORDERS2", bytes(200000, 1), 0).empty());  // fragmented: never buffered
  const auto& c = p.rx.counters();
  EXPECT_EQ(c.delivered, 1u);
  EXPECT_EQ(c.not_allowed, 1u + (200000 + seal::kMaxPayload - kFragmentHeader - 1) / (seal::kMaxPayload - kFragmentHeader));
  EXPECT_EQ(c.reassembly_dropped, 0u);
}

TEST(DoorPolicy, TheShippedConfigLetsNoProcmanChannelCrossAndCarriesTheOperatorsCommandsUp) {
  const LinkConfig cfg = load_link_config(util::Config::load((test::source_dir() / "config/link.yaml").string()));
  for (Direction d : {Direction::AirToGround, Direction::GroundToAir}) {
    Pair p(cfg.policy(d), {}, {}, d);
    for (const char* c : {"PMD_ORDERS2", "PMD_INFO2", "PMD_PRINTF", "PMD_DISCOVER", "PMD_ORDERS"})
      EXPECT_TRUE(p.cross(c, bytes(30, 1), 0).empty()) << c << " crossed " << direction_key(d);
    EXPECT_EQ(p.rx.counters().not_allowed, 5u);
  }
  Pair up(cfg.policy(Direction::GroundToAir));
  up.with_operator(seal::OperatorKey::generate(), cfg.operator_channels);
  for (const char* c : {"PILOT_CMD", "TRACK_CMD", "FLC_PARAMS", "MAP_CMD", "MAP_QUERY", "MAP_RESPONSE"})
    EXPECT_EQ(up.cross(c, bytes(30, 1), 0).size(), 1u) << c << " does not cross ground->air";
  // The operator's commands went up signed; the map's data did not need it.
  EXPECT_EQ(up.tx.counters().signed_commands, 4u);
  EXPECT_EQ(up.rx.counters().commands_verified, 4u);
  Pair down(cfg.policy(Direction::AirToGround), {}, {}, Direction::AirToGround);
  EXPECT_TRUE(down.cross("PILOT_CMD", bytes(30, 1), 0).empty());  // commands go up only
  EXPECT_EQ(down.cross("VO_POSE", bytes(30, 1), 0).size(), 1u);
}

TEST(DoorPolicy, AFloodIsRateLimitedWithExactCounts) {
  // 20 messages/s, bucket 40: a burst of 100 at once lets 40 through; 1 s later 20 more.
  Pair p(DoorPolicy{".*", {RateRule{"PILOT_CMD", 20, 40, 0, 0}}, ""});
  int through = 0;
  for (int i = 0; i < 100; ++i) through += static_cast<int>(p.cross("PILOT_CMD", bytes(16, 1), 0.0).size());
  EXPECT_EQ(through, 40);
  EXPECT_EQ(p.rx.counters().rate_limited, 60u);
  for (int i = 0; i < 100; ++i) through += static_cast<int>(p.cross("PILOT_CMD", bytes(16, 1), 1.0).size());
  EXPECT_EQ(through, 60);
  EXPECT_EQ(p.rx.counters().rate_limited, 140u);
  // Another channel has its own bucket (and no rule: no limit).
  for (int i = 0; i < 100; ++i) through += static_cast<int>(p.cross("TRACK_CMD", bytes(16, 1), 1.0).size());
  EXPECT_EQ(through, 160);
}

TEST(DoorPolicy, BytesPerSecondLimitsLargeMessages) {
  Pair p(DoorPolicy{".*", {RateRule{"MAP_CMD", 0, 0, 10000, 10000}}, ""});
  int through = 0;
  for (int i = 0; i < 10; ++i) through += static_cast<int>(p.cross("MAP_CMD", bytes(3000, 1), 0.0).size());
  EXPECT_EQ(through, 3);  // 3 x 3000 <= 10000
  EXPECT_EQ(p.rx.counters().rate_limited, 7u);
}

// --- reassembly bounds ----------------------------------------------------------------------------

TEST(DoorReassembly, TooLargeIsRefusedAtTheSenderAndIncompleteMessagesAreBounded) {
  ReassemblyLimits lim;
  lim.max_message_bytes = 300000;
  lim.max_pending_bytes = 600000;
  lim.max_pending_messages = 2;
  lim.timeout_s = 1.0;
  Pair p(anything(), {}, lim);
  EXPECT_FALSE(p.tx.send("CAM_LEFT", bytes(300001, 1), 0, p.out));
  EXPECT_EQ(p.tx.counters().too_large, 1u);
  // Three messages' first fragments only: the oldest gives way to the third.
  for (int m = 0; m < 3; ++m) {
    ASSERT_TRUE(p.tx.send("CAM_LEFT", bytes(200000, static_cast<uint8_t>(m)), m * 0.1, p.out));
    EXPECT_FALSE(p.rx.receive(p.out[0], m * 0.1));
  }
  EXPECT_EQ(p.rx.counters().reassembly_dropped, 1u);
  // Past the timeout the two incomplete ones go too.
  p.rx.expire(5.0);
  EXPECT_EQ(p.rx.counters().reassembly_dropped, 3u);
  // And a complete message still crosses.
  EXPECT_EQ(p.cross("CAM_LEFT", bytes(200000, 7), 5.0).size(), 1u);
}

// --- rekeying in flight ---------------------------------------------------------------------------

TEST(DoorRekey, RekeyingWhileMessagesFlowLosesAndDuplicatesNothing) {
  // Rekey every 10 s of (simulated) time and every 500 messages; 20 Hz for 60 s plus a burst;
  // each message's last datagram arrives one message late (reordered across epoch switches).
  seal::RekeyPolicy rk;
  rk.seconds = 10;
  rk.messages = 500;
  Pair p(anything(), rk);
  std::set<uint32_t> seen;
  uint64_t duplicates = 0;
  std::vector<uint8_t> held;
  auto deliver = [&](const std::vector<uint8_t>& d, double t) {
    if (auto m = p.rx.receive(d, t)) {
      uint32_t i = 0;
      std::memcpy(&i, m->payload.data(), 4);
      if (!seen.insert(i).second) ++duplicates;
    }
  };
  const uint32_t n = 1200 + 1000;
  for (uint32_t i = 0; i < n; ++i) {
    const double t = i < 1200 ? i * 0.05 : 60.0 + (i - 1200) * 0.001;
    ASSERT_TRUE(p.tx.send("TRACK_CMD", numbered(i), t, p.out));
    // Pairs (1,2), (3,4), ... swapped: the switch at message 500 (and at 10 s, message 200)
    // falls inside a pair, so the old epoch's last datagram comes after the new epoch's first.
    if (i == 0) {
      deliver(p.out[0], t);
    } else if (held.empty()) {
      held = p.out[0];
    } else {
      deliver(p.out[0], t);
      deliver(held, t);
      held.clear();
    }
  }
  if (!held.empty()) deliver(held, 61.0);
  EXPECT_EQ(seen.size(), n);
  EXPECT_EQ(duplicates, 0u);
  EXPECT_EQ(p.rx.counters().delivered, n);
  EXPECT_EQ(p.rx.counters().opener.refused_total(), 0u);
  // 60 s / 10 s and then the burst's 1000 messages / 500: at least 7 epochs.
  EXPECT_GE(p.tx.epoch(), 7u);
  EXPECT_EQ(p.rx.peer_epoch(), static_cast<int64_t>(p.tx.epoch()));
}

// --- configuration --------------------------------------------------------------------------------

TEST(DoorConfig, ReadsRatesRekeyAndDoorKeys) {
  const auto cfg = load_link_config(util::Config::parse(R"(
rekey: {seconds: 10, messages: 1000, overlap_s: 2}
door: {max_message_bytes: 1000000, max_pending_bytes: 4000000, max_pending_messages: 4, reassembly_timeout_s: 0.5, max_datagram_bytes: 1400}
ground_to_air:
  channels: "PILOT_CMD"
  rate:
    - {channels: "PILOT_CMD", messages_per_s: 5, message_burst: 10, bytes_per_s: 1000, byte_burst: 2000}
air_to_ground:
  rate: []
)", "link.yaml"));
  EXPECT_DOUBLE_EQ(cfg.rekey.seconds, 10);
  EXPECT_EQ(cfg.rekey.messages, 1000u);
  EXPECT_DOUBLE_EQ(cfg.rekey_overlap_s, 2);
  EXPECT_EQ(cfg.reassembly.max_message_bytes, 1000000u);
  EXPECT_EQ(cfg.reassembly.max_pending_messages, 4u);
  EXPECT_EQ(cfg.reassembly.max_datagram_bytes, 1400u);
  EXPECT_DOUBLE_EQ(cfg.reassembly.timeout_s, 0.5);
  ASSERT_EQ(cfg.ground_to_air_rates.size(), 1u);
  EXPECT_EQ(cfg.ground_to_air_rates[0].channels, "PILOT_CMD");
  EXPECT_DOUBLE_EQ(cfg.ground_to_air_rates[0].message_burst, 10);
  EXPECT_DOUBLE_EQ(cfg.ground_to_air_rates[0].byte_burst, 2000);
  EXPECT_TRUE(cfg.air_to_ground_rates.empty());
  EXPECT_EQ(cfg.policy(Direction::GroundToAir).channels, "PILOT_CMD");
}

TEST(DoorConfig, UnknownKeysAndBadValuesAreRefusedNamingFileKeyAndLine) {
  auto refusal = [](const std::string& yaml) {
    try {
      load_link_config(util::Config::parse(yaml, "bad.yaml"));
    } catch (const std::exception& e) {
      return std::string(e.what());
    }
    return std::string("accepted");
  };
  std::string e = refusal("air_to_ground:\n  chanels: \"X\"\n");
  EXPECT_NE(e.find("bad.yaml"), std::string::npos) << e;
  EXPECT_NE(e.find("air_to_ground.chanels"), std::string::npos) << e;
  EXPECT_NE(e.find("line 2"), std::string::npos) << e;
  e = refusal("rekey: {seconds: 10, every: 3}\n");
  EXPECT_NE(e.find("rekey.every"), std::string::npos) << e;
  e = refusal("rekey: {seconds: -1}\n");
  EXPECT_NE(e.find("bad.yaml: rekey: "), std::string::npos) << e;
  e = refusal("ground_to_air:\n  rate:\n    - {channels: PILOT_CMD, messages_per_sec: 5}\n");
  EXPECT_NE(e.find("ground_to_air.rate[0]: unknown key 'messages_per_sec' (line 3)"), std::string::npos) << e;
  e = refusal("ground_to_air:\n  rate:\n    - {channels: PILOT_CMD, messages_per_s: -5}\n");
  EXPECT_NE(e.find("messages_per_s must be >= 0"), std::string::npos) << e;
  e = refusal("ground_to_air: {rate: {channels: X}}\n");
  EXPECT_NE(e.find("expected a list"), std::string::npos) << e;
  e = refusal("door: {max_datagram_bytes: 100}\n");
  EXPECT_NE(e.find("bad.yaml: door: max_datagram_bytes"), std::string::npos) << e;
  e = refusal("stats: {period: 1}\n");
  EXPECT_NE(e.find("stats.period"), std::string::npos) << e;
}

// --- the operator's role (common/seal/operator.hpp) ----------------------------------------------

namespace {
size_t refused(const DoorReceiver& rx, seal::CommandRefusal r) {
  return rx.counters().commands_refused[static_cast<size_t>(r)];
}
}  // namespace

TEST(DoorOperator, TheGroundHalfLearnsTheSessionFromTheAirHalfsHelloAndItsCommandsAreObeyed) {
  const seal::SecretKey key = seal::SecretKey::generate();
  const seal::OperatorKey op = seal::OperatorKey::generate();
  const seal::Session session = seal::new_session();
  DoorPolicy up_policy{"PILOT_CMD|VO_POSE", {}, "PILOT_CMD"};
  DoorSender air_tx(&key, Direction::AirToGround, 1, 0, 0.0);
  DoorReceiver ground_rx(&key, Direction::AirToGround, anything());
  DoorSender ground_tx(&key, Direction::GroundToAir, 2, 0, 0.0);
  DoorReceiver air_rx(&key, Direction::GroundToAir, up_policy);
  air_rx.require_operator(seal::CommandVerifier({op.public_key()}, session));
  ground_tx.sign_commands("PILOT_CMD", seal::CommandSigner(op.clone()));
  std::vector<std::vector<uint8_t>> out;

  // Before the hello the ground half has no session: the command is held back and counted.
  EXPECT_FALSE(ground_tx.send("PILOT_CMD", bytes(20, 1), 0.0, out));
  EXPECT_EQ(ground_tx.counters().no_session, 1u);
  std::vector<uint8_t> hello;
  ASSERT_TRUE(air_tx.hello(session, 0.0, hello));
  EXPECT_FALSE(ground_rx.receive(hello, 0.0));  // not a message: nothing is published
  ASSERT_TRUE(ground_rx.peer_session());
  EXPECT_EQ(*ground_rx.peer_session(), session);
  EXPECT_EQ(ground_rx.counters().hellos, 1u);
  ground_tx.set_session(*ground_rx.peer_session());

  ASSERT_TRUE(ground_tx.send("PILOT_CMD", bytes(20, 1), 0.1, out));
  auto m = air_rx.receive(out[0], 0.1);
  ASSERT_TRUE(m) << air_rx.why();
  EXPECT_EQ(m->payload, bytes(20, 1));  // the envelope is gone
  // Not an operator's channel: crosses with the mission key alone.
  ASSERT_TRUE(ground_tx.send("VO_POSE", bytes(20, 2), 0.2, out));
  EXPECT_TRUE(air_rx.receive(out[0], 0.2));
  EXPECT_EQ(air_rx.counters().commands_verified, 1u);
  // A hello is the air half's only: one sent up is refused as malformed.
  ASSERT_TRUE(ground_tx.hello(session, 0.3, hello));
  EXPECT_FALSE(air_rx.receive(hello, 0.3));
  EXPECT_EQ(air_rx.counters().malformed, 1u);
  // An insecure sender makes no hello.
  DoorSender clear(nullptr, Direction::AirToGround, 1, 0, 0.0);
  EXPECT_FALSE(clear.hello(session, 0.0, hello));
}

TEST(DoorOperator, AMissionKeyHolderWithoutTheOperatorsKeyCannotCommand) {
  // The intruder holds the mission key (a stolen telemetry station, the vehicle itself): its
  // datagrams open, but its commands are refused by reason and nothing is published.
  Pair p(DoorPolicy{".*", {}, kDefaultOperatorChannels});
  const seal::OperatorKey op = seal::OperatorKey::generate();
  p.with_operator(op);
  DoorSender intruder(&p.key, Direction::GroundToAir, 99, 0, 0.0);
  std::vector<std::vector<uint8_t>> out;
  const auto cmd = bytes(24, 5);

  // 1. A bare command.
  ASSERT_TRUE(intruder.send("PILOT_CMD", cmd, 0.0, out));
  EXPECT_FALSE(p.rx.receive(out[0], 0.0));
  EXPECT_EQ(refused(p.rx, seal::CommandRefusal::Unsigned), 1u);
  // 2. Signed with a key of its own.
  intruder.sign_commands("PILOT_CMD", seal::CommandSigner(seal::OperatorKey::generate()));
  intruder.set_session(p.session);
  ASSERT_TRUE(intruder.send("PILOT_CMD", cmd, 0.1, out));
  EXPECT_FALSE(p.rx.receive(out[0], 0.1));
  EXPECT_EQ(refused(p.rx, seal::CommandRefusal::BadSignature), 1u);
  // 3. The operator's genuine command, captured (the intruder opens it with the mission key)
  //    and re-sealed as its own datagram: the seal is fresh, the command is a replay.
  ASSERT_TRUE(p.tx.send("PILOT_CMD", cmd, 0.2, out));
  seal::Opener tap(p.key, {.direction = Direction::GroundToAir});
  const seal::Opened captured = tap.open(out[0], 0.2);
  ASSERT_TRUE(captured);
  ASSERT_TRUE(p.rx.receive(out[0], 0.2));  // the genuine one is obeyed, once
  seal::Sealer resealer(p.key, Direction::GroundToAir, 98, 0, 0.0);
  EXPECT_FALSE(p.rx.receive(resealer.seal("PILOT_CMD", captured.payload, 0.3), 0.3));
  EXPECT_EQ(refused(p.rx, seal::CommandRefusal::Replayed), 1u);
  // 4. ... and replayed to the air half after it restarted (a new session).
  DoorPolicy commands{".*", {}, kDefaultOperatorChannels};
  DoorReceiver restarted_air(&p.key, Direction::GroundToAir, commands);
  restarted_air.require_operator(seal::CommandVerifier({op.public_key()}, seal::new_session()));
  EXPECT_FALSE(restarted_air.receive(resealer.seal("PILOT_CMD", captured.payload, 0.4), 0.4));
  EXPECT_EQ(refused(restarted_air, seal::CommandRefusal::OtherSession), 1u);
  // 5. Moved to another operator's channel.
  EXPECT_FALSE(p.rx.receive(resealer.seal("TRACK_CMD", captured.payload, 0.5), 0.5));
  EXPECT_EQ(refused(p.rx, seal::CommandRefusal::BadSignature), 2u);
  EXPECT_EQ(p.rx.counters().delivered, 1u);  // the operator's one command, nothing else
  EXPECT_EQ(p.rx.counters().commands_verified, 1u);
}

TEST(DoorOperator, ASecureHalfWithoutOperatorKeysNeitherSendsNorObeysCommands) {
  // The ground half without --operator-key (a station that only watches) refuses to send them;
  // an air half that has no operator's public key refuses them (fail closed).
  const seal::SecretKey key = seal::SecretKey::generate();
  DoorSender watcher(&key, Direction::GroundToAir, 3, 0, 0.0);
  watcher.sign_commands(kDefaultOperatorChannels, std::nullopt);
  std::vector<std::vector<uint8_t>> out;
  EXPECT_FALSE(watcher.send("PILOT_CMD", bytes(10, 1), 0.0, out));
  EXPECT_EQ(watcher.counters().unsigned_commands, 1u);
  EXPECT_TRUE(watcher.send("MAP_RESPONSE", bytes(10, 1), 0.0, out));  // data, not a command

  DoorReceiver air(&key, Direction::GroundToAir, DoorPolicy{".*", {}, kDefaultOperatorChannels});
  DoorSender plain(&key, Direction::GroundToAir, 4, 0, 0.0);
  ASSERT_TRUE(plain.send("TRACK_CMD", bytes(10, 1), 0.0, out));
  EXPECT_FALSE(air.receive(out[0], 0.0));
  EXPECT_EQ(refused(air, seal::CommandRefusal::Unsigned), 1u);
  EXPECT_NE(air.why().find("no operator public key"), std::string::npos) << air.why();
}

TEST(DoorReassembly, AWholeMessageOverTheReceiversLimitIsRefusedAndCounted) {
  // A sender with a looser limit than the receiver's: the receiver's own bound holds.
  ReassemblyLimits tight;
  tight.max_message_bytes = 1000;
  tight.max_pending_bytes = 1000;
  const seal::SecretKey key = seal::SecretKey::generate();
  DoorSender tx(&key, Direction::AirToGround, 1, 0, 0.0);
  DoorReceiver rx(&key, Direction::AirToGround, anything(), {}, tight);
  std::vector<std::vector<uint8_t>> out;
  ASSERT_TRUE(tx.send("VO_POSE", bytes(1001, 1), 0.0, out));
  ASSERT_EQ(out.size(), 1u);
  EXPECT_FALSE(rx.receive(out[0], 0.0));
  ASSERT_TRUE(tx.send("VO_POSE", bytes(1000, 1), 0.0, out));
  EXPECT_TRUE(rx.receive(out[0], 0.0));
  EXPECT_EQ(rx.counters().too_large, 1u);
  EXPECT_EQ(rx.counters().delivered, 1u);
}
