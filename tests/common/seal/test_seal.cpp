// The sealed door's cryptography (common/seal): round trips, the "must not connect" matrix,
// replay and ordering (WireGuard's counter self-test), rekeying, and mission key files.
#include <gtest/gtest.h>
#include <sys/stat.h>
#include <unistd.h>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <numeric>
#include <random>
#include <set>
#include <string>
#include <vector>

#include "common/seal/keys.hpp"
#include "common/seal/replay_window.hpp"
#include "common/seal/seal.hpp"
#include "common/seal/testing.hpp"

namespace {

using namespace aerie::seal;
namespace fs = std::filesystem;

SecretKey test_key(uint8_t fill = 0x42) {
  std::vector<uint8_t> bytes(SecretKey::kSize);
  std::iota(bytes.begin(), bytes.end(), fill);
  return SecretKey::from_bytes(bytes);
}

std::vector<uint8_t> bytes_of(const std::string& s) { return {s.begin(), s.end()}; }

std::vector<uint8_t> pattern(size_t n, uint32_t seed = 7) {
  std::vector<uint8_t> v(n);
  std::mt19937 rng(seed);
  for (auto& b : v) b = static_cast<uint8_t>(rng());
  return v;
}

OpenerConfig ground_config() { return OpenerConfig{.direction = Direction::AirToGround}; }

// Asserts that `d` is refused with `reason`, that nothing is delivered, and that the reason was
// counted exactly once more.
void expect_refused(Opener& opener, const std::vector<uint8_t>& d, Refusal reason, double now_s = 0) {
  const uint64_t before = opener.counters()[reason];
  const uint64_t opened = opener.counters().opened;
  const Opened o = opener.open(d, now_s);
  EXPECT_FALSE(o.ok());
  EXPECT_EQ(o.refusal, reason) << "got \"" << to_string(o.refusal) << "\": " << o.why;
  EXPECT_TRUE(o.channel.empty());
  EXPECT_TRUE(o.payload.empty());
  EXPECT_FALSE(o.why.empty());
  EXPECT_EQ(opener.counters()[reason], before + 1);
  EXPECT_EQ(opener.counters().opened, opened);
}

// --- round trips --------------------------------------------------------------------------------

TEST(Seal, RoundTripChannelAndPayload) {
  const SecretKey key = test_key();
  Sealer sealer(key, Direction::AirToGround, 7, 0, 0.0);
  Opener opener(key, ground_config());
  const auto payload = pattern(1000);
  const auto d = sealer.seal("VO_POSE", payload, 0.5);
  EXPECT_EQ(d.size(), kOverhead + 7 + payload.size());
  const Opened o = opener.open(d, 0.5);
  ASSERT_TRUE(o.ok()) << o.why;
  EXPECT_EQ(o.channel, "VO_POSE");
  EXPECT_EQ(o.payload, payload);
  EXPECT_EQ(o.sender, 7u);
  EXPECT_EQ(o.epoch, 0u);
  EXPECT_EQ(o.counter, 1u);
  EXPECT_EQ(opener.counters().opened, 1u);
  EXPECT_EQ(opener.counters().refused_total(), 0u);
  // The channel name and payload do not travel in the clear.
  const std::string wire(d.begin(), d.end());
  EXPECT_EQ(wire.find("VO_POSE"), std::string::npos);
}

TEST(Seal, CountersStartAtOneAndRise) {
  const SecretKey key = test_key();
  Sealer sealer(key, Direction::GroundToAir, 3, 5, 0.0);
  Opener opener(key, {.direction = Direction::GroundToAir, .min_epoch = 5});
  for (uint64_t i = 1; i <= 100; ++i) {
    EXPECT_EQ(sealer.next_counter(), i);
    const Opened o = opener.open(sealer.seal("PILOT_CMD", bytes_of("abort"), 1.0), 1.0);
    ASSERT_TRUE(o.ok()) << o.why;
    EXPECT_EQ(o.counter, i);
    EXPECT_EQ(o.epoch, 5u);
  }
  EXPECT_EQ(sealer.sealed(), 100u);
}

TEST(Seal, EmptyPayloadAndMaximumSizes) {
  const SecretKey key = test_key();
  Sealer sealer(key, Direction::AirToGround, 1, 0, 0.0);
  Opener opener(key, ground_config());
  {
    const auto d = sealer.seal("X", {}, 0);
    EXPECT_EQ(d.size(), kMinDatagram);
    const Opened o = opener.open(d, 0);
    ASSERT_TRUE(o.ok()) << o.why;
    EXPECT_EQ(o.channel, "X");
    EXPECT_TRUE(o.payload.empty());
  }
  {
    const std::string longest(kMaxChannel, 'C');
    const auto payload = pattern(kMaxPayload, 11);
    const auto d = sealer.seal(longest, payload, 0);
    EXPECT_EQ(d.size(), kMaxDatagram);
    const Opened o = opener.open(d, 0);
    ASSERT_TRUE(o.ok()) << o.why;
    EXPECT_EQ(o.channel, longest);
    EXPECT_EQ(o.payload, payload);
  }
}

TEST(Seal, OversizeAndBadChannelRefusedBySealer) {
  const SecretKey key = test_key();
  Sealer sealer(key, Direction::AirToGround, 1, 0, 0.0);
  const auto big = pattern(kMaxPayload + 1);
  try {
    (void)sealer.seal("CAM_STEREO", big, 0);
    FAIL() << "an oversize payload was sealed";
  } catch (const std::invalid_argument& e) {
    EXPECT_NE(std::string(e.what()).find("CAM_STEREO"), std::string::npos) << e.what();
    EXPECT_NE(std::string(e.what()).find(std::to_string(kMaxPayload)), std::string::npos) << e.what();
  }
  EXPECT_THROW(sealer.seal("", {}, 0), std::invalid_argument);
  EXPECT_THROW(sealer.seal(std::string(kMaxChannel + 1, 'C'), {}, 0), std::invalid_argument);
  EXPECT_THROW(sealer.seal("TWO WORDS", {}, 0), std::invalid_argument);
  EXPECT_THROW(sealer.seal(std::string("NUL\0X", 5), {}, 0), std::invalid_argument);
  EXPECT_EQ(sealer.next_counter(), 1u);  // nothing was sealed
}

TEST(Seal, OversizeRefusedByOpener) {
  const SecretKey key = test_key();
  Opener opener(key, ground_config());
  std::vector<uint8_t> d(kMaxDatagram + 1, 0);
  expect_refused(opener, d, Refusal::Oversize);
  // An authentic datagram whose payload is larger than kMaxPayload (a short channel name leaves room).
  std::vector<uint8_t> inner = {1, 'X'};
  const auto payload = pattern(kMaxPayload + 1);
  inner.insert(inner.end(), payload.begin(), payload.end());
  expect_refused(opener, for_tests::seal_plaintext(key, {}, inner), Refusal::Oversize);
}

TEST(Seal, SubkeysDifferPerEpochAndDirection) {
  const SecretKey key = test_key();
  std::set<std::string> seen;
  for (uint32_t e : {0u, 1u, 2u, 0xffffffffu})
    for (Direction d : {Direction::AirToGround, Direction::GroundToAir}) {
      const SecretKey k = derive_subkey(key, e, d);
      seen.insert(std::string(k.data(), k.data() + k.size()));
      EXPECT_FALSE(k.equals(key));
    }
  EXPECT_EQ(seen.size(), 8u);
  EXPECT_TRUE(derive_subkey(key, 3, Direction::GroundToAir).equals(derive_subkey(key, 3, Direction::GroundToAir)));
}

TEST(Seal, HeaderLayout) {
  const SecretKey key = test_key();
  Sealer sealer(key, Direction::GroundToAir, 0x01020304u, 0x0a0b0c0du, 0.0);
  const auto d = sealer.seal("TRACK_CMD", bytes_of("x"), 0);
  ASSERT_GE(d.size(), kHeaderSize);
  EXPECT_EQ(d[0], kMagic);
  EXPECT_EQ(d[1], kVersion);
  EXPECT_EQ(d[2], 0x01);  // ground->air
  EXPECT_EQ(d[3], 0x00);
  EXPECT_EQ((std::vector<uint8_t>(d.begin() + 4, d.begin() + 8)), (std::vector<uint8_t>{0x0d, 0x0c, 0x0b, 0x0a}));
  EXPECT_EQ((std::vector<uint8_t>(d.begin() + 8, d.begin() + 12)), (std::vector<uint8_t>{0x04, 0x03, 0x02, 0x01}));
  EXPECT_EQ((std::vector<uint8_t>(d.begin() + 12, d.begin() + 20)), (std::vector<uint8_t>{1, 0, 0, 0, 0, 0, 0, 0}));
  // Two sealers with the same key, sender and epoch (a restart) draw different salts: no nonce repeats.
  Sealer again(key, Direction::GroundToAir, 0x01020304u, 0x0a0b0c0du, 0.0);
  const auto d2 = again.seal("TRACK_CMD", bytes_of("x"), 0);
  EXPECT_NE((std::vector<uint8_t>(d.begin() + 20, d.begin() + 36)), (std::vector<uint8_t>(d2.begin() + 20, d2.begin() + 36)));
  EXPECT_NE(d, d2);
}

// --- must not connect ---------------------------------------------------------------------------

TEST(MustNotConnect, WrongKey) {
  Sealer sealer(test_key(1), Direction::AirToGround, 1, 0, 0.0);
  Opener opener(test_key(2), ground_config());
  for (int i = 0; i < 10; ++i) expect_refused(opener, sealer.seal("VO_POSE", pattern(100), 0), Refusal::AuthFailed);
  EXPECT_EQ(opener.counters().refused_total(), 10u);
  EXPECT_EQ(opener.current_epoch(1), -1);  // a refused datagram makes no sender known
}

TEST(MustNotConnect, NoKeyPlainDatagrams) {
  // An insecure sender (a plain LCM datagram, "LC02" magic) and random bytes of every size.
  Opener opener(test_key(), ground_config());
  std::vector<uint8_t> lcm = {'L', 'C', '0', '2', 0, 0, 0, 1};
  const auto body = bytes_of("VO_POSE");
  lcm.insert(lcm.end(), body.begin(), body.end());
  lcm.resize(200, 0);
  expect_refused(opener, lcm, Refusal::BadVersion);
  std::mt19937 rng(3);
  for (int i = 0; i < 200; ++i) {
    auto d = pattern(kMinDatagram + rng() % 2000, static_cast<uint32_t>(i));
    d[0] = kMagic;
    d[1] = kVersion;
    d[2] = 0;
    d[3] = 0;
    for (int b = 4; b < 8; ++b) d[b] = 0;  // epoch 0: the tag is what stops it
    expect_refused(opener, d, Refusal::AuthFailed);
  }
  EXPECT_EQ(opener.counters().opened, 0u);
}

TEST(MustNotConnect, Reflection) {
  // What the ground sends up, reflected back down to the ground, does not open there.
  const SecretKey key = test_key();
  Sealer up(key, Direction::GroundToAir, 2, 0, 0.0);
  Opener ground(key, ground_config());
  const auto d = up.seal("PILOT_CMD", bytes_of("land"), 0);
  expect_refused(ground, d, Refusal::WrongDirection);
  // With the direction bit flipped it claims to be air->ground, but the subkey differs.
  auto flipped = d;
  flipped[2] ^= 0x01;
  expect_refused(ground, flipped, Refusal::AuthFailed);
}

TEST(MustNotConnect, EveryHeaderByteFlipped) {
  const SecretKey key = test_key();
  Sealer sealer(key, Direction::AirToGround, 1, 0, 0.0);
  const auto d = sealer.seal("VO_POSE", pattern(64), 0);
  Opener opener(key, ground_config());
  const std::set<Refusal> allowed = {Refusal::BadVersion, Refusal::WrongDirection, Refusal::AuthFailed,
                                     Refusal::UnknownEpoch};
  for (size_t i = 0; i < kHeaderSize; ++i)
    for (uint8_t mask : {uint8_t{0x01}, uint8_t{0x80}, uint8_t{0xff}}) {
      auto t = d;
      t[i] ^= mask;
      const uint64_t refused = opener.counters().refused_total();
      const Opened o = opener.open(t, 0);
      EXPECT_FALSE(o.ok()) << "header byte " << i << " ^ " << int(mask) << " was accepted";
      EXPECT_TRUE(allowed.count(o.refusal)) << "byte " << i << ": " << to_string(o.refusal);
      EXPECT_EQ(opener.counters().refused_total(), refused + 1);
    }
  EXPECT_EQ(opener.counters().opened, 0u);
  // Bytes 0, 1 and 3 (three masks each) and the unknown flag bits of byte 2 (0x80, 0xff);
  // byte 2 ^ 0x01 is the other direction.
  EXPECT_EQ(opener.counters()[Refusal::BadVersion], 3u * 3u + 2u);
  EXPECT_EQ(opener.counters()[Refusal::WrongDirection], 1u);
  EXPECT_TRUE(opener.open(d, 0).ok());                        // the original still opens: nothing moved the window
}

TEST(MustNotConnect, EveryCiphertextAndTagByteFlipped) {
  const SecretKey key = test_key();
  Sealer sealer(key, Direction::AirToGround, 1, 0, 0.0);
  const auto d = sealer.seal("VO_POSE", pattern(100), 0);
  Opener opener(key, ground_config());
  for (size_t i = kHeaderSize; i < d.size(); ++i) {
    auto t = d;
    t[i] ^= static_cast<uint8_t>(1u << (i % 8));
    expect_refused(opener, t, Refusal::AuthFailed);
  }
  EXPECT_EQ(opener.counters()[Refusal::AuthFailed], d.size() - kHeaderSize);
  EXPECT_TRUE(opener.open(d, 0).ok());
}

TEST(MustNotConnect, EveryTruncation) {
  const SecretKey key = test_key();
  Sealer sealer(key, Direction::AirToGround, 1, 0, 0.0);
  const auto d = sealer.seal("VO_POSE", pattern(300), 0);
  Opener opener(key, ground_config());
  for (size_t n = 0; n < d.size(); ++n) {
    const std::vector<uint8_t> t(d.begin(), d.begin() + static_cast<std::ptrdiff_t>(n));
    expect_refused(opener, t, n < kMinDatagram ? Refusal::TooShort : Refusal::AuthFailed);
  }
  EXPECT_EQ(opener.counters()[Refusal::TooShort], kMinDatagram);
  EXPECT_EQ(opener.counters()[Refusal::AuthFailed], d.size() - kMinDatagram);
  EXPECT_EQ(opener.counters().opened, 0u);
  EXPECT_TRUE(opener.open(d, 0).ok());
}

TEST(MustNotConnect, WrongVersion) {
  const SecretKey key = test_key();
  Sealer sealer(key, Direction::AirToGround, 1, 0, 0.0);
  Opener opener(key, ground_config());
  auto d = sealer.seal("VO_POSE", pattern(10), 0);
  auto v2 = d;
  v2[1] = 2;
  expect_refused(opener, v2, Refusal::BadVersion);
  auto magic = d;
  magic[0] = 0xAF;
  expect_refused(opener, magic, Refusal::BadVersion);
  auto flags = d;
  flags[2] |= 0x02;
  expect_refused(opener, flags, Refusal::BadVersion);
}

TEST(MustNotConnect, EpochFarAheadAndExpired) {
  const SecretKey key = test_key();
  Opener opener(key, {.direction = Direction::AirToGround, .max_epochs_ahead = 4, .min_epoch = 10});
  // Below the floor: a recording of an older run.
  Sealer old(key, Direction::AirToGround, 1, 9, 0.0);
  expect_refused(opener, old.seal("VO_POSE", pattern(10), 0), Refusal::ExpiredEpoch);
  // Further ahead than max_epochs_ahead.
  Sealer ahead(key, Direction::AirToGround, 1, 15, 0.0);
  expect_refused(opener, ahead.seal("VO_POSE", pattern(10), 0), Refusal::UnknownEpoch);
  // Inside: accepted, and then the sender's epoch is the reference.
  Sealer ok(key, Direction::AirToGround, 1, 14, 0.0);
  ASSERT_TRUE(opener.open(ok.seal("VO_POSE", pattern(10), 0), 0).ok());
  EXPECT_EQ(opener.current_epoch(1), 14);
  Sealer far(key, Direction::AirToGround, 1, 19, 0.0);
  expect_refused(opener, far.seal("VO_POSE", pattern(10), 0), Refusal::UnknownEpoch);
  Sealer older(key, Direction::AirToGround, 1, 12, 0.0);  // two before the current one
  expect_refused(opener, older.seal("VO_POSE", pattern(10), 0), Refusal::ExpiredEpoch);
}

TEST(MustNotConnect, MalformedChannelInsideAnAuthenticDatagram) {
  const SecretKey key = test_key();
  Opener opener(key, ground_config());
  uint64_t counter = 1;
  auto sealed = [&](std::vector<uint8_t> inner) {
    for_tests::RawHeader h;
    h.counter = counter++;
    return for_tests::seal_plaintext(key, h, inner);
  };
  expect_refused(opener, sealed({0, 'A', 'B'}), Refusal::ChannelMalformed);            // empty name
  expect_refused(opener, sealed({5, 'A', 'B'}), Refusal::ChannelMalformed);            // past the end
  std::vector<uint8_t> long_name(1 + 64, 'A');
  long_name[0] = 64;
  expect_refused(opener, sealed(long_name), Refusal::ChannelMalformed);                // over kMaxChannel
  expect_refused(opener, sealed({2, 'A', ' ', 'x'}), Refusal::ChannelMalformed);       // a space
  expect_refused(opener, sealed({2, 'A', 0x80, 'x'}), Refusal::ChannelMalformed);      // not ASCII
  const Opened o = opener.open(sealed({2, 'O', 'K', 'x'}), 0);
  ASSERT_TRUE(o.ok()) << o.why;
  EXPECT_EQ(o.channel, "OK");
  EXPECT_EQ(o.payload, (std::vector<uint8_t>{'x'}));
}

TEST(MustNotConnect, TooManySenders) {
  const SecretKey key = test_key();
  Opener opener(key, {.direction = Direction::AirToGround, .max_senders = 3});
  for (uint32_t s = 1; s <= 3; ++s) {
    Sealer sealer(key, Direction::AirToGround, s, 0, 0.0);
    ASSERT_TRUE(opener.open(sealer.seal("A", {}, 0), 0).ok());
  }
  Sealer fourth(key, Direction::AirToGround, 4, 0, 0.0);
  expect_refused(opener, fourth.seal("A", {}, 0), Refusal::TooManySenders);
}

TEST(MustNotConnect, OpenerNeverThrowsOnRandomInput) {
  const SecretKey key = test_key();
  Opener opener(key, ground_config());
  std::mt19937 rng(5);
  uint64_t n = 0;
  for (int i = 0; i < 2000; ++i, ++n) {
    auto d = pattern(rng() % 300, static_cast<uint32_t>(i));
    if (i % 2 && d.size() >= 4) {
      d[0] = kMagic;
      d[1] = kVersion;
      d[2] &= 1;
      d[3] = 0;
    }
    EXPECT_NO_THROW(EXPECT_FALSE(opener.open(d, i).ok()));
  }
  EXPECT_EQ(opener.counters().refused_total(), n);
}

// --- replay and ordering ---------------------------------------------------------------------

TEST(Replay, CapturedDatagramReplayedLater) {
  const SecretKey key = test_key();
  Sealer sealer(key, Direction::AirToGround, 1, 0, 0.0);
  Opener opener(key, ground_config());
  const auto captured = sealer.seal("PILOT_CMD", bytes_of("abort"), 0);
  ASSERT_TRUE(opener.open(captured, 0).ok());
  for (int i = 0; i < 100; ++i) ASSERT_TRUE(opener.open(sealer.seal("VO_POSE", pattern(20), 1), 1).ok());
  expect_refused(opener, captured, Refusal::Replayed, 60);
  expect_refused(opener, captured, Refusal::Replayed, 240);
}

TEST(Replay, DuplicatesRefused) {
  const SecretKey key = test_key();
  Sealer sealer(key, Direction::AirToGround, 1, 0, 0.0);
  Opener opener(key, ground_config());
  const auto d = sealer.seal("VO_POSE", pattern(20), 0);
  ASSERT_TRUE(opener.open(d, 0).ok());
  for (int i = 0; i < 5; ++i) expect_refused(opener, d, Refusal::Replayed);
  EXPECT_EQ(opener.counters().opened, 1u);
}

TEST(Replay, ReorderingInsideTheWindowAcceptedOnce) {
  const SecretKey key = test_key();
  Sealer sealer(key, Direction::AirToGround, 1, 0, 0.0);
  Opener opener(key, ground_config());
  std::vector<std::vector<uint8_t>> sent;
  for (int i = 0; i < 1000; ++i) sent.push_back(sealer.seal("VO_POSE", bytes_of(std::to_string(i)), 0));
  std::vector<size_t> order(sent.size());
  std::iota(order.begin(), order.end(), 0);
  std::mt19937 rng(9);
  std::shuffle(order.begin(), order.end(), rng);
  std::set<std::string> delivered;
  for (const size_t i : order) {
    const Opened o = opener.open(sent[i], 0);
    ASSERT_TRUE(o.ok()) << o.why;
    delivered.insert(std::string(o.payload.begin(), o.payload.end()));
  }
  EXPECT_EQ(delivered.size(), 1000u);
  for (const size_t i : order) expect_refused(opener, sent[i], Refusal::Replayed);
}

TEST(Replay, LeftOfTheWindowRefused) {
  const SecretKey key = test_key();
  Sealer sealer(key, Direction::AirToGround, 1, 0, 0.0);
  Opener opener(key, ground_config());
  const auto first = sealer.seal("VO_POSE", {}, 0);  // counter 1, held back
  std::vector<uint8_t> last;
  for (uint64_t i = 2; i <= ReplayWindow::kWindowSize + 2; ++i) last = sealer.seal("VO_POSE", {}, 0);
  ASSERT_TRUE(opener.open(last, 0).ok());  // counter window + 2
  expect_refused(opener, first, Refusal::TooOld);
}

TEST(Replay, ForgedDatagramDoesNotMoveTheWindow) {
  // check() before the tag, commit() after: a forged far-ahead counter must not push the
  // genuine datagrams out of the window.
  const SecretKey key = test_key();
  Sealer sealer(key, Direction::AirToGround, 1, 0, 0.0);
  Opener opener(key, ground_config());
  const auto genuine = sealer.seal("VO_POSE", pattern(10), 0);
  auto forged = genuine;
  forged[12 + 7] = 0x10;  // counter 2^60 + 1
  expect_refused(opener, forged, Refusal::AuthFailed);
  EXPECT_TRUE(opener.open(genuine, 0).ok());
}

// WireGuard's drivers/net/wireguard/selftest/counter.c, case by case, on the same algorithm.
TEST(ReplayWindowTest, WireGuardCounterSelfTest) {
  constexpr uint64_t W = ReplayWindow::kWindowSize;
  constexpr uint64_t LIM = W + 1;  // T_LIM
  constexpr uint64_t R = ReplayWindow::kRejectAfter;
  ReplayWindow c;
  int n = 0;
  auto T = [&](uint64_t counter, bool expected) {
    ++n;
    EXPECT_EQ(c.accept(counter), expected) << "WireGuard counter self-test " << n << " (counter " << counter << ")";
  };
  T(0, true);
  T(1, true);
  T(1, false);
  T(9, true);
  T(8, true);
  T(7, true);
  T(7, false);
  T(LIM, true);
  T(LIM - 1, true);
  T(LIM - 1, false);
  T(LIM - 2, true);
  T(2, true);
  T(2, false);
  T(LIM + 16, true);
  T(3, false);
  T(LIM + 16, false);
  T(LIM * 4, true);
  T(LIM * 4 - (LIM - 1), true);
  T(10, false);
  T(LIM * 4 - LIM, false);
  T(LIM * 4 - (LIM + 1), false);
  T(LIM * 4 - (LIM - 2), true);
  T(LIM * 4 + 1 - LIM, false);
  T(0, false);
  T(R, false);
  T(R - 1, true);
  T(R, false);
  T(R - 1, false);
  T(R - 2, true);
  T(R + 1, false);
  T(R + 2, false);
  T(R - 2, false);
  T(R - 3, true);
  T(0, false);
  EXPECT_EQ(n, 34);

  c = ReplayWindow{};
  for (uint64_t i = 1; i <= W; ++i) T(i, true);
  T(0, true);
  T(0, false);

  c = ReplayWindow{};
  for (uint64_t i = 2; i <= W + 1; ++i) T(i, true);
  T(1, true);
  T(0, false);

  c = ReplayWindow{};
  for (uint64_t i = W + 1; i-- > 0;) T(i, true);

  c = ReplayWindow{};
  for (uint64_t i = W + 2; i-- > 1;) T(i, true);
  T(0, false);

  c = ReplayWindow{};
  for (uint64_t i = W + 1; i-- > 1;) T(i, true);
  T(W + 1, true);
  T(0, false);

  c = ReplayWindow{};
  for (uint64_t i = W + 1; i-- > 1;) T(i, true);
  T(0, true);
  T(W + 1, true);
}

TEST(ReplayWindowTest, CheckDoesNotCommit) {
  ReplayWindow c;
  EXPECT_EQ(c.check(5), ReplayWindow::Verdict::Fresh);
  EXPECT_EQ(c.check(5), ReplayWindow::Verdict::Fresh);
  c.commit(5);
  EXPECT_EQ(c.check(5), ReplayWindow::Verdict::Replayed);
  EXPECT_EQ(c.check(ReplayWindow::kRejectAfter), ReplayWindow::Verdict::Exhausted);
  c.commit(5 + ReplayWindow::kWindowSize + 10);
  EXPECT_EQ(c.check(4), ReplayWindow::Verdict::TooOld);
}

// --- rekeying ----------------------------------------------------------------------------------

TEST(Rekey, ByTimeAndByCount) {
  const SecretKey key = test_key();
  Sealer by_time(key, Direction::AirToGround, 1, 0, 0.0, {.seconds = 10.0});
  (void)by_time.seal("A", {}, 9.99);
  EXPECT_EQ(by_time.epoch(), 0u);
  (void)by_time.seal("A", {}, 10.0);
  EXPECT_EQ(by_time.epoch(), 1u);
  EXPECT_EQ(by_time.next_counter(), 2u);  // counter restarts at 1 in the new epoch
  (void)by_time.seal("A", {}, 19.9);
  EXPECT_EQ(by_time.epoch(), 1u);
  (void)by_time.seal("A", {}, 35.0);
  EXPECT_EQ(by_time.epoch(), 2u);

  Sealer by_count(key, Direction::AirToGround, 1, 0, 0.0, {.seconds = 1e9, .messages = 3});
  std::vector<uint32_t> epochs;
  for (int i = 0; i < 7; ++i) {
    (void)by_count.seal("A", {}, 0);
    epochs.push_back(by_count.epoch());
  }
  EXPECT_EQ(epochs, (std::vector<uint32_t>{0, 0, 0, 1, 1, 1, 2}));
  EXPECT_THROW((Sealer(key, Direction::AirToGround, 1, 0, 0.0, {.seconds = 0})), std::invalid_argument);
  EXPECT_THROW((Sealer(key, Direction::AirToGround, 1, 0, 0.0, {.messages = 0})), std::invalid_argument);
  Sealer last(key, Direction::AirToGround, 1, 0xffffffffu, 0.0);
  EXPECT_THROW(last.rekey(1.0), std::runtime_error);
}

TEST(Rekey, ReorderingAtTheBoundaryDeliveredExactlyOnce) {
  const SecretKey key = test_key();
  Sealer sealer(key, Direction::AirToGround, 1, 0, 0.0, {.seconds = 10.0});
  Opener opener(key, {.direction = Direction::AirToGround, .overlap_s = 3.0});
  // 100 messages at 10 Hz through three epoch changes (t = 10, 20, 30 s ...), each delivered
  // with a lag: neighbours swapped in pairs, so that epoch e+1's first datagram arrives before
  // epoch e's last.
  std::vector<std::pair<double, std::vector<uint8_t>>> sent;
  for (int i = 0; i < 100; ++i) {
    const double t = 5.0 + 0.1 * i;
    sent.emplace_back(t, sealer.seal("VO_POSE", bytes_of(std::to_string(i)), t));
  }
  EXPECT_EQ(sealer.epoch(), 1u);
  for (size_t i = 0; i + 1 < sent.size(); i += 2) std::swap(sent[i], sent[i + 1]);
  std::vector<int> got;
  for (const auto& [t, d] : sent) {
    const Opened o = opener.open(d, t + 0.2);
    ASSERT_TRUE(o.ok()) << o.why;
    got.push_back(std::stoi(std::string(o.payload.begin(), o.payload.end())));
  }
  std::sort(got.begin(), got.end());
  std::vector<int> all(100);
  std::iota(all.begin(), all.end(), 0);
  EXPECT_EQ(got, all);
  // Replaying everything once more: nothing delivered twice (epoch 0's within the overlap too).
  for (const auto& [t, d] : sent) {
    const Opened o = opener.open(d, 15.0);
    EXPECT_FALSE(o.ok());
    EXPECT_TRUE(o.refusal == Refusal::Replayed || o.refusal == Refusal::ExpiredEpoch) << to_string(o.refusal);
  }
  EXPECT_EQ(opener.counters().opened, 100u);
}

TEST(Rekey, OldEpochRefusedAfterTheOverlap) {
  const SecretKey key = test_key();
  Sealer sealer(key, Direction::AirToGround, 1, 0, 0.0, {.seconds = 10.0});
  Opener opener(key, {.direction = Direction::AirToGround, .overlap_s = 2.0});
  const auto late_a = sealer.seal("VO_POSE", bytes_of("a"), 9.0);  // epoch 0, held back
  const auto late_b = sealer.seal("VO_POSE", bytes_of("b"), 9.5);  // epoch 0, held back
  ASSERT_TRUE(opener.open(sealer.seal("VO_POSE", bytes_of("c"), 9.6), 9.6).ok());
  const auto next = sealer.seal("VO_POSE", bytes_of("d"), 10.0);  // epoch 1
  ASSERT_EQ(sealer.epoch(), 1u);
  ASSERT_TRUE(opener.open(next, 10.0).ok());
  EXPECT_EQ(opener.current_epoch(1), 1);
  EXPECT_TRUE(opener.open(late_a, 11.9).ok());                     // inside the overlap
  expect_refused(opener, late_b, Refusal::ExpiredEpoch, 12.1);    // after it
  // Two epochs on, epoch 1 is expired whatever the time.
  Sealer later(key, Direction::AirToGround, 1, 3, 0.0);
  ASSERT_TRUE(opener.open(later.seal("VO_POSE", {}, 30), 30).ok());
  expect_refused(opener, sealer.seal("VO_POSE", {}, 30.1 - 20), Refusal::ExpiredEpoch, 30.1);
}

TEST(Rekey, ConfigurationRefusedNamingTheField) {
  const SecretKey key = test_key();
  auto message = [&](OpenerConfig c) {
    try {
      Opener o(key, c);
    } catch (const std::invalid_argument& e) {
      return std::string(e.what());
    }
    return std::string();
  };
  EXPECT_NE(message({.overlap_s = -1}).find("overlap_s"), std::string::npos);
  EXPECT_NE(message({.max_epochs_ahead = 0}).find("max_epochs_ahead"), std::string::npos);
  EXPECT_NE(message({.max_senders = 0}).find("max_senders"), std::string::npos);
  EXPECT_EQ(message({}), "");
  Sealer sealer(key, Direction::AirToGround, 1, 0, 0.0);
  EXPECT_THROW(sealer.seal("A", {}, std::nan("")), std::invalid_argument);
  // A previous epoch with a NaN time is expired, not open forever.
  Sealer s2(key, Direction::AirToGround, 1, 0, 0.0, {.seconds = 1.0});
  Opener opener(key, ground_config());
  const auto old = s2.seal("A", {}, 0.5);
  ASSERT_TRUE(opener.open(s2.seal("A", {}, 1.5), 1.5).ok());
  expect_refused(opener, old, Refusal::ExpiredEpoch, std::nan(""));
}

// --- keys -------------------------------------------------------------------------------------

class KeyFiles : public ::testing::Test {
 protected:
  void SetUp() override {
    dir_ = fs::temp_directory_path() / ("aerie_test_seal_" + std::to_string(::getpid()) + "_" +
                                        ::testing::UnitTest::GetInstance()->current_test_info()->name());
    fs::remove_all(dir_);
    fs::create_directories(dir_);
  }
  void TearDown() override { fs::remove_all(dir_); }
  std::string path(const std::string& name) const { return (dir_ / name).string(); }
  fs::path dir_;
};

TEST_F(KeyFiles, SaveLoadRoundTripMode0600) {
  const SecretKey key = SecretKey::generate();
  save_key(path("mission.key"), key);
  struct stat st {};
  ASSERT_EQ(::stat(path("mission.key").c_str(), &st), 0);
  EXPECT_EQ(st.st_mode & 0777, 0600u);
  EXPECT_EQ(fs::file_size(path("mission.key")), 32u);
  EXPECT_TRUE(load_key(path("mission.key")).equals(key));
  EXPECT_THROW(save_key(path("mission.key"), SecretKey::generate()), std::runtime_error);  // no overwrite
  EXPECT_TRUE(load_key(path("mission.key")).equals(key));
}

TEST_F(KeyFiles, Mode0644RefusedNamingFileAndMode) {
  save_key(path("open.key"), SecretKey::generate());
  fs::permissions(path("open.key"), fs::perms::owner_read | fs::perms::owner_write | fs::perms::group_read |
                                         fs::perms::others_read);
  try {
    load_key(path("open.key"));
    FAIL() << "a key file of mode 0644 was read";
  } catch (const std::runtime_error& e) {
    const std::string what = e.what();
    EXPECT_NE(what.find(path("open.key")), std::string::npos) << what;
    EXPECT_NE(what.find("0644"), std::string::npos) << what;
  }
}

TEST_F(KeyFiles, WrongSizeRefused) {
  for (const size_t n : {size_t{0}, size_t{31}, size_t{33}, size_t{64}}) {
    const std::string p = path("k" + std::to_string(n));
    { std::ofstream(p, std::ios::binary) << std::string(n, 'k'); }
    fs::permissions(p, fs::perms::owner_read | fs::perms::owner_write);
    try {
      load_key(p);
      FAIL() << n << " bytes were read as a key";
    } catch (const std::runtime_error& e) {
      const std::string what = e.what();
      EXPECT_NE(what.find(p), std::string::npos) << what;
      EXPECT_NE(what.find("expected 32"), std::string::npos) << what;
    }
  }
  EXPECT_THROW(load_key(path("missing")), std::runtime_error);
  EXPECT_THROW(SecretKey::from_bytes(std::vector<uint8_t>(31)), std::invalid_argument);
}

TEST(Keys, FingerprintStableAndDistinct) {
  const SecretKey a = test_key(1), b = test_key(2);
  const std::string fa = fingerprint(a);
  EXPECT_EQ(fa, fingerprint(a.clone()));
  EXPECT_NE(fa, fingerprint(b));
  ASSERT_EQ(fa.size(), 19u);  // xxxx:xxxx:xxxx:xxxx
  for (size_t i = 0; i < fa.size(); ++i) {
    if (i % 5 == 4) {
      EXPECT_EQ(fa[i], ':');
    } else {
      EXPECT_TRUE(std::isxdigit(static_cast<unsigned char>(fa[i]))) << fa;
    }
  }
  // Known values, from Python's hashlib.blake2b(key, digest_size=16, person=b"aerie-fp"): both
  // halves (and any other tool) must agree on them.
  EXPECT_EQ(fingerprint(test_key(0x42)), "6802:ce61:8b34:d3e1");
  EXPECT_EQ(fingerprint(SecretKey{}), "f8e7:c0a7:04e6:b65e");
}

TEST(Keys, MovedFromKeyIsZeroed) {
  SecretKey a = test_key(5);
  const SecretKey copy = a.clone();
  SecretKey b = std::move(a);
  EXPECT_TRUE(b.equals(copy));
  EXPECT_TRUE(a.equals(SecretKey{}));  // NOLINT(bugprone-use-after-move): the move zeroes it
}

}  // namespace
