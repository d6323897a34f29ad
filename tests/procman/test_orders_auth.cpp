// Keyed procman (procman/orders_auth.hpp; issue 46 section 3): the gate between a keyed
// deputy and its orders, and a real Deputy driven through it.
#include "procman/orders_auth.hpp"

#include <gtest/gtest.h>
#include <sodium.h>
#include <sys/stat.h>

#include <chrono>
#include <filesystem>
#include <fstream>

#include "common/seal/seal.hpp"
#include "tests/procman/deputy_harness.hpp"
#include "tests/support/test_support.hpp"

using namespace aerie;
using namespace aerie::procman;

namespace {

constexpr int64_t kNow = 1'780'000'000'000'000;  // a wall clock, microseconds
constexpr int64_t kSecond = 1'000'000;

bot_procman::orders2_t orders_for(const std::string& host, const std::string& sheriff, int64_t utime,
                                  std::vector<procman::test::CmdSpec> cmds = {}) {
  auto o = procman::test::make_orders(host, cmds);
  o.utime = utime;
  o.sheriff_name = sheriff;
  return o;
}

struct Fixture : ::testing::Test {
  seal::SecretKey key = seal::SecretKey::generate();
  GateOptions options() const {
    GateOptions o;
    o.window_s = 60;
    return o;
  }
};

using OrdersAuth = Fixture;

}  // namespace

TEST_F(OrdersAuth, ValidOrdersRoundTripThroughTheGate) {
  OrdersSigner sheriff(key, 7);
  OrdersGate gate(key, "air", options());
  procman::test::CmdSpec c;
  c.exec = "sleep 10";
  c.name = "sleeper";
  const auto sealed = sheriff.sign(orders_for("air", "ground-sheriff", kNow, {c}), kNow);
  EXPECT_EQ(sealed.size(), kSealedOrdersHeader + orders_for("air", "ground-sheriff", kNow, {c}).getEncodedSize() +
                               kSealedOrdersTag);
  const auto v = gate.check(sealed, kNow + 200'000, 1000);
  ASSERT_TRUE(v.accepted()) << v.why;
  EXPECT_EQ(v.sender, 7u);
  EXPECT_EQ(v.counter, static_cast<uint64_t>(kNow));
  ASSERT_EQ(v.orders.cmds.size(), 1u);
  EXPECT_EQ(v.orders.cmds[0].cmd.exec_str, "sleep 10");
  EXPECT_EQ(v.orders.sheriff_name, "ground-sheriff");
  EXPECT_EQ(gate.following(), 7u);
  EXPECT_NE(v.notice.find("following sheriff 'ground-sheriff' (id 7)"), std::string::npos) << v.notice;
  EXPECT_NE(v.notice.find(seal::fingerprint(key)), std::string::npos) << v.notice;
  EXPECT_EQ(gate.accepted(), 1u);
}

TEST_F(OrdersAuth, CounterRisesEvenWhenTheClockGoesBack) {
  OrdersSigner s(key, 1);
  const auto o = orders_for("air", "s", kNow);
  s.sign(o, kNow);
  EXPECT_EQ(s.last_counter(), static_cast<uint64_t>(kNow));
  s.sign(o, kNow);  // same microsecond
  EXPECT_EQ(s.last_counter(), static_cast<uint64_t>(kNow) + 1);
  s.sign(o, kNow - 3600 * kSecond);  // clock stepped back an hour
  EXPECT_EQ(s.last_counter(), static_cast<uint64_t>(kNow) + 2);
  EXPECT_THROW(OrdersSigner(key, 0), std::invalid_argument);
}

TEST_F(OrdersAuth, PlainOrdersAreRefusedAndCounted) {
  OrdersGate gate(key, "air", options());
  const auto v = gate.refuse_plain(orders_for("air", "rogue", kNow));
  EXPECT_EQ(v.refusal, OrdersRefusal::Unauthenticated);
  EXPECT_TRUE(v.first);
  EXPECT_NE(v.why.find("sheriff 'rogue'"), std::string::npos) << v.why;
  EXPECT_NE(v.why.find("PMD_ORDERS2_SEALED"), std::string::npos) << v.why;
  const auto again = gate.refuse_plain(orders_for("air", "rogue", kNow));
  EXPECT_FALSE(again.first);  // said once per reason and sender
  EXPECT_TRUE(gate.refuse_plain(orders_for("air", "other", kNow)).first);
  EXPECT_EQ(gate.refused(OrdersRefusal::Unauthenticated), 3u);
  EXPECT_STREQ(counter_name(OrdersRefusal::Unauthenticated), "orders_unauthenticated");
  EXPECT_EQ(gate.accepted(), 0u);
}

TEST_F(OrdersAuth, WrongKeyTamperedAndTruncatedOrdersAreRefused) {
  const seal::SecretKey other = seal::SecretKey::generate();
  OrdersGate gate(key, "air", options());
  OrdersSigner rogue(other, 7);
  const auto wrong = rogue.sign(orders_for("air", "s", kNow), kNow);
  auto v = gate.check(wrong, kNow, 1);
  EXPECT_EQ(v.refusal, OrdersRefusal::AuthFailed);
  EXPECT_NE(v.why.find("claimed sender id 7"), std::string::npos) << v.why;

  OrdersSigner good(key, 7);
  auto sealed = good.sign(orders_for("air", "s", kNow), kNow);
  for (size_t at : {size_t{5}, size_t{9}, size_t{40}, sealed.size() - 1}) {  // sender, counter, body, tag
    auto t = sealed;
    t[at] ^= 0x01;
    EXPECT_EQ(gate.check(t, kNow, 1).refusal, OrdersRefusal::AuthFailed) << "byte " << at;
  }
  auto truncated = sealed;
  truncated.resize(20);
  EXPECT_EQ(gate.check(truncated, kNow, 1).refusal, OrdersRefusal::Malformed);
  auto version = sealed;
  version[1] = 2;
  EXPECT_EQ(gate.check(version, kNow, 1).refusal, OrdersRefusal::Malformed);
  auto flags = sealed;
  flags[2] = 0x02;  // an unknown flag
  EXPECT_EQ(gate.check(flags, kNow, 1).refusal, OrdersRefusal::Malformed);
  auto leaving = sealed;
  leaving[2] = kSealedOrdersLeaving;  // a known flag, but set after the tag was made
  EXPECT_EQ(gate.check(leaving, kNow, 1).refusal, OrdersRefusal::AuthFailed);
  // An authentic tag over a body that is not orders2_t: refused as malformed, not decoded.
  std::vector<uint8_t> junk(kSealedOrdersHeader + 12, 0x41);
  junk[0] = kSealedOrdersMagic;
  junk[1] = kSealedOrdersVersion;
  junk[2] = junk[3] = 0;
  junk[4] = 7;
  junk.resize(junk.size() + kSealedOrdersTag);
  const seal::SecretKey k = derive_orders_key(key);
  crypto_auth_hmacsha512256(junk.data() + junk.size() - kSealedOrdersTag, junk.data(),
                            junk.size() - kSealedOrdersTag, k.data());
  v = gate.check(junk, kNow, 1);
  EXPECT_EQ(v.refusal, OrdersRefusal::Malformed);
  EXPECT_NE(v.why.find("orders2_t"), std::string::npos) << v.why;

  EXPECT_EQ(gate.refused(OrdersRefusal::AuthFailed), 6u);
  EXPECT_EQ(gate.refused(OrdersRefusal::Malformed), 4u);
  EXPECT_EQ(gate.accepted(), 0u);
  EXPECT_TRUE(gate.check(sealed, kNow, 1).accepted());  // the genuine one still passes
}

TEST_F(OrdersAuth, TheLinksSealCannotPassForOrdersNorTheReverse) {
  // Domain separation: procman's subkey differs from the link's for every direction.
  const seal::SecretKey mine = derive_orders_key(key);
  for (auto d : {seal::Direction::AirToGround, seal::Direction::GroundToAir})
    EXPECT_FALSE(mine.equals(seal::derive_subkey(key, 0, d)));
  OrdersSigner s(key, 3);
  const auto sealed = s.sign(orders_for("air", "s", kNow), kNow);
  seal::Opener opener(key, {.direction = seal::Direction::GroundToAir});
  EXPECT_FALSE(opener.open(sealed, 0.0).ok());
}

TEST_F(OrdersAuth, ReplayedOrdersAreRefused) {
  OrdersSigner s(key, 7);
  OrdersGate gate(key, "air", options());
  const auto first = s.sign(orders_for("air", "s", kNow), kNow);
  const auto second = s.sign(orders_for("air", "s", kNow), kNow + kSecond);
  ASSERT_TRUE(gate.check(first, kNow, 1).accepted());
  auto v = gate.check(first, kNow, 2);  // the same message again
  EXPECT_EQ(v.refusal, OrdersRefusal::Replayed);
  EXPECT_NE(v.why.find("counter " + std::to_string(kNow) + " is not above the last accepted " + std::to_string(kNow)),
            std::string::npos)
      << v.why;
  ASSERT_TRUE(gate.check(second, kNow + kSecond, 3).accepted());
  EXPECT_EQ(gate.check(first, kNow + kSecond, 4).refusal, OrdersRefusal::Replayed);  // an older one
  EXPECT_EQ(gate.check(second, kNow + kSecond, 5).refusal, OrdersRefusal::Replayed);
  EXPECT_EQ(gate.refused(OrdersRefusal::Replayed), 3u);
  EXPECT_EQ(gate.accepted(), 2u);
}

TEST_F(OrdersAuth, OrdersFromTheFutureAndStaleOrdersAreRefused) {
  OrdersSigner s(key, 7);
  OrdersGate gate(key, "air", options());
  const int64_t ten_years = int64_t{10} * 365 * 24 * 3600 * kSecond;
  auto v = gate.check(s.sign(orders_for("air", "s", kNow + ten_years), kNow + ten_years), kNow, 1);
  EXPECT_EQ(v.refusal, OrdersRefusal::FromFuture);
  EXPECT_NE(v.why.find("ahead of this deputy's clock (limit 60.0 s)"), std::string::npos) << v.why;
  v = gate.check(s.sign(orders_for("air", "s", kNow - 600 * kSecond), kNow), kNow, 2);
  EXPECT_EQ(v.refusal, OrdersRefusal::TooOld);
  EXPECT_NE(v.why.find("they are 600.0 s old (limit 60.0 s)"), std::string::npos) << v.why;
  // INT64_MIN / INT64_MAX stamps: refused, no overflow.
  EXPECT_EQ(gate.check(s.sign(orders_for("air", "s", INT64_MIN), kNow), kNow, 3).refusal, OrdersRefusal::TooOld);
  EXPECT_EQ(gate.check(s.sign(orders_for("air", "s", INT64_MAX), kNow), kNow, 4).refusal, OrdersRefusal::FromFuture);
  // Within the window both ways: accepted.
  EXPECT_TRUE(gate.check(s.sign(orders_for("air", "s", kNow + 59 * kSecond), kNow), kNow, 5).accepted());
  EXPECT_TRUE(gate.check(s.sign(orders_for("air", "s", kNow - 59 * kSecond), kNow), kNow, 6).accepted());
  EXPECT_EQ(gate.refused(OrdersRefusal::FromFuture), 2u);
  EXPECT_EQ(gate.refused(OrdersRefusal::TooOld), 2u);
}

TEST_F(OrdersAuth, ReplayAfterADeputyRestartIsRefused) {
  const auto dir = aerie::test::scratch_dir("state");
  const std::string state = (dir / "deputy-air.counters").string();
  GateOptions o = options();
  o.state_path = state;
  OrdersSigner s(key, 7);
  const auto recorded = s.sign(orders_for("air", "s", kNow), kNow);
  {
    OrdersGate gate(key, "air", o);
    ASSERT_TRUE(gate.check(recorded, kNow, 1).accepted());
  }
  struct stat st {};
  ASSERT_EQ(stat(state.c_str(), &st), 0);
  EXPECT_EQ(st.st_mode & 0777, 0600u);
  OrdersGate restarted(key, "air", o);  // the deputy restarted: a fresh gate, the same state file
  EXPECT_EQ(restarted.counters().at(7), static_cast<uint64_t>(kNow));
  const auto v = restarted.check(recorded, kNow + 5 * kSecond, 2);  // inside the time window
  EXPECT_EQ(v.refusal, OrdersRefusal::Replayed) << v.why;
  // The sheriff's next orders still pass.
  EXPECT_TRUE(restarted.check(s.sign(orders_for("air", "s", kNow + 5 * kSecond), kNow + 5 * kSecond),
                              kNow + 5 * kSecond, 3)
                  .accepted());
  // Without the state file the same replay would have passed: the file is what refuses it.
  OrdersGate amnesiac(key, "air", options());
  EXPECT_TRUE(amnesiac.check(recorded, kNow + 5 * kSecond, 2).accepted());
}

TEST_F(OrdersAuth, CorruptOrForeignWritableStateFileRefusesToStart) {
  const auto dir = aerie::test::scratch_dir("state");
  GateOptions o = options();
  o.state_path = (dir / "bad.counters").string();
  std::ofstream(o.state_path) << "# aerie-deputy order counters v1\n7 12\nseven 13\n";
  chmod(o.state_path.c_str(), 0600);
  try {
    OrdersGate gate(key, "air", o);
    FAIL() << "a corrupt state file was accepted";
  } catch (const std::runtime_error& e) {
    EXPECT_NE(std::string(e.what()).find(o.state_path + ":3: expected '<sender id> <counter>'"), std::string::npos)
        << e.what();
  }
  std::ofstream(o.state_path, std::ios::trunc) << "# aerie-deputy order counters v1\n7 12\n";
  chmod(o.state_path.c_str(), 0666);
  try {
    OrdersGate gate(key, "air", o);
    FAIL() << "a state file writable by others was accepted";
  } catch (const std::runtime_error& e) {
    EXPECT_NE(std::string(e.what()).find("writable by others"), std::string::npos) << e.what();
  }
  chmod(o.state_path.c_str(), 0600);
  OrdersGate gate(key, "air", o);
  EXPECT_EQ(gate.counters().at(7), 12u);
}

TEST_F(OrdersAuth, ARogueKeyedSheriffIsNoticedAndNotObeyed) {
  OrdersSigner real(key, 100), rogue(key, 200);
  OrdersGate gate(key, "air", options());
  ASSERT_TRUE(gate.check(real.sign(orders_for("air", "real", kNow), kNow), kNow, 1000).accepted());
  auto v = gate.check(rogue.sign(orders_for("air", "rogue", kNow), kNow), kNow, 1500);
  EXPECT_EQ(v.refusal, OrdersRefusal::OtherSheriff);
  EXPECT_NE(v.why.find("this deputy follows sheriff 'real' (id 100)"), std::string::npos) << v.why;
  EXPECT_NE(v.notice.find("two sheriffs: following sheriff 'real' (id 100), refusing sheriff 'rogue' (id 200)"),
            std::string::npos)
      << v.notice;
  EXPECT_EQ(gate.conflict(1500), "two sheriffs: following sheriff 'real' (id 100), refusing sheriff 'rogue' (id 200)");
  // The real one goes on being obeyed while the rogue keeps sending (said once, counted each time).
  for (int i = 1; i <= 5; ++i) {
    EXPECT_TRUE(gate.check(real.sign(orders_for("air", "real", kNow), kNow + i), kNow, 1500 + i * 1000).accepted());
    const auto r = gate.check(rogue.sign(orders_for("air", "rogue", kNow), kNow + i), kNow, 1600 + i * 1000);
    EXPECT_EQ(r.refusal, OrdersRefusal::OtherSheriff);
    EXPECT_TRUE(r.notice.empty());
  }
  EXPECT_EQ(gate.refused(OrdersRefusal::OtherSheriff), 6u);
  EXPECT_EQ(gate.following(), 100u);
  EXPECT_FALSE(gate.conflict(6600 + 9000).empty());
  EXPECT_TRUE(gate.conflict(6600 + 10'100).empty());  // conflict_hold_s after the rival's last orders
}

TEST_F(OrdersAuth, APinnedSheriffIdIsTheOnlyOneObeyed) {
  GateOptions o = options();
  o.follow_sheriff = 100;
  OrdersGate gate(key, "air", o);
  OrdersSigner real(key, 100), other(key, 200);
  auto v = gate.check(other.sign(orders_for("air", "other", kNow), kNow), kNow, 1000);  // heard first
  EXPECT_EQ(v.refusal, OrdersRefusal::OtherSheriff);
  EXPECT_NE(v.why.find("follows sheriff id 100 (--sheriff-id)"), std::string::npos) << v.why;
  // ... and never takes over, however long the pinned one is silent.
  EXPECT_EQ(gate.check(other.sign(orders_for("air", "other", kNow), kNow), kNow, 1000 + 3'600'000).refusal,
            OrdersRefusal::OtherSheriff);
  v = gate.check(real.sign(orders_for("air", "real", kNow), kNow), kNow, 1000 + 3'600'001);
  ASSERT_TRUE(v.accepted()) << v.why;
  EXPECT_NE(v.notice.find("following sheriff 'real' (id 100) (--sheriff-id"), std::string::npos) << v.notice;
}

TEST_F(OrdersAuth, AnotherSheriffTakesOverOnlyAfterTheFollowedOneFellSilent) {
  OrdersGate gate(key, "air", options());  // handover_s 10
  OrdersSigner first(key, 1), second(key, 2);
  ASSERT_TRUE(gate.check(first.sign(orders_for("air", "first", kNow), kNow), kNow, 1000).accepted());
  EXPECT_EQ(gate.check(second.sign(orders_for("air", "second", kNow), kNow), kNow, 10'900).refusal,
            OrdersRefusal::OtherSheriff);  // 9.9 s of silence
  const auto v = gate.check(second.sign(orders_for("air", "second", kNow), kNow + 1), kNow, 11'000);
  ASSERT_TRUE(v.accepted()) << v.why;
  EXPECT_NE(v.notice.find("taking orders from sheriff 'second' (id 2): sheriff 'first' (id 1) has been silent for 10.0 s"),
            std::string::npos)
      << v.notice;
  EXPECT_EQ(gate.following(), 2u);
  EXPECT_EQ(gate.check(first.sign(orders_for("air", "first", kNow), kNow), kNow, 11'500).refusal,
            OrdersRefusal::OtherSheriff);
}

TEST_F(OrdersAuth, AfterTheFollowedSheriffLeftTheNextIsFollowedAtOnce) {
  OrdersGate gate(key, "air", options());
  OrdersSigner first(key, 1), second(key, 2), third(key, 3);
  ASSERT_TRUE(gate.check(first.sign(orders_for("air", "first", kNow), kNow), kNow, 1000).accepted());
  // A rival's "leaving" orders do not release the followed sheriff.
  EXPECT_EQ(gate.check(third.sign(orders_for("air", "third", kNow), kNow, true), kNow, 1100).refusal,
            OrdersRefusal::OtherSheriff);
  const auto bye = first.sign(orders_for("air", "first", kNow), kNow + 1, /*leaving=*/true);
  auto v = gate.check(bye, kNow, 1200);
  ASSERT_TRUE(v.accepted()) << v.why;  // its last orders are obeyed
  EXPECT_NE(v.notice.find("sheriff 'first' (id 1) left"), std::string::npos) << v.notice;
  EXPECT_EQ(gate.following(), 0u);
  EXPECT_TRUE(gate.conflict(1200).empty());
  // Its goodbye sent twice: the second is obeyed too, but does not make it followed again.
  v = gate.check(first.sign(orders_for("air", "first", kNow), kNow + 2, true), kNow, 1250);
  ASSERT_TRUE(v.accepted()) << v.why;
  EXPECT_TRUE(v.notice.empty()) << v.notice;
  EXPECT_EQ(gate.following(), 0u);
  v = gate.check(second.sign(orders_for("air", "second", kNow), kNow), kNow, 1300);  // 0.1 s later
  ASSERT_TRUE(v.accepted()) << v.why;
  EXPECT_EQ(gate.following(), 2u);
  EXPECT_EQ(gate.check(bye, kNow, 1400).refusal, OrdersRefusal::Replayed);  // a replayed goodbye
  EXPECT_EQ(gate.following(), 2u);
  // Pinned: a goodbye does not unpin.
  GateOptions o = options();
  o.follow_sheriff = 1;
  OrdersGate pinned(key, "air", o);
  ASSERT_TRUE(pinned.check(first.sign(orders_for("air", "first", kNow), kNow, true), kNow, 1000).accepted());
  EXPECT_EQ(pinned.following(), 1u);
  EXPECT_EQ(pinned.check(second.sign(orders_for("air", "second", kNow), kNow), kNow, 1100).refusal,
            OrdersRefusal::OtherSheriff);
}

TEST_F(OrdersAuth, OrdersForAnotherDeputyAreIgnoredNotRefused) {
  OrdersSigner s(key, 7);
  OrdersGate gate(key, "air", options());
  const auto v = gate.check(s.sign(orders_for("ground", "s", kNow), kNow), kNow, 1);
  EXPECT_TRUE(v.other_host);
  EXPECT_FALSE(v.accepted());
  EXPECT_EQ(v.refusal, OrdersRefusal::None);
  EXPECT_EQ(gate.following(), 0u);
  EXPECT_TRUE(gate.counters().empty());
}

TEST_F(OrdersAuth, GateOptionsAreValidated) {
  GateOptions o;
  o.window_s = 0;
  EXPECT_THROW(OrdersGate(key, "air", o), std::invalid_argument);
  o = GateOptions{};
  o.handover_s = -1;
  EXPECT_THROW(OrdersGate(key, "air", o), std::invalid_argument);
}

// A real deputy behind the gate: its sheriff starts and stops a command; refused orders do nothing.
TEST_F(OrdersAuth, KeyedDeputyObeysItsSheriffOnly) {
  const auto dir = aerie::test::scratch_dir("deputy");
  const std::string marker = (dir / "ran").string(), rogue_marker = (dir / "rogue").string();
  procman::test::DeputyHarness h;
  OrdersGate gate(key, h.deputy.name(), options());
  OrdersSigner sheriff(key, 11), rogue_keyed(key, 12), wrong_key(seal::SecretKey::generate(), 11);
  auto deliver = [&](const std::vector<uint8_t>& bytes) {
    const auto now_ms = std::chrono::duration_cast<std::chrono::milliseconds>(
                            std::chrono::steady_clock::now().time_since_epoch())
                            .count();
    const auto v = gate.check(bytes, util::wall_utime(), now_ms);
    if (v.accepted()) h.deputy.handle_orders(v.orders, util::wall_utime());
    return v;
  };
  auto orders = [&](const std::string& sheriff_name, std::vector<procman::test::CmdSpec> cmds) {
    return orders_for(h.deputy.name(), sheriff_name, util::wall_utime(), std::move(cmds));
  };
  procman::test::CmdSpec c;
  c.id = 42;
  c.name = "worker";
  c.exec = "sh -c 'touch " + marker + "; exec sleep 1000'";
  c.runid = 1;
  procman::test::CmdSpec evil;
  evil.id = 43;
  evil.name = "evil";
  evil.exec = "sh -c 'touch " + rogue_marker + "; exec sleep 1000'";

  ASSERT_TRUE(deliver(sheriff.sign(orders("real", {c}), util::wall_utime())).accepted());
  ASSERT_TRUE(h.run_until([&] { return h.cmd(42) && h.cmd(42)->pid != 0 && std::filesystem::exists(marker); }));
  const auto recorded_start = sheriff.sign(orders("real", {c}), util::wall_utime());
  ASSERT_TRUE(deliver(recorded_start).accepted());

  // Refused: a rogue keyed sheriff, the wrong key, plain orders, a replay. None start `evil`
  // nor stop `worker` (each omits it).
  EXPECT_EQ(deliver(rogue_keyed.sign(orders("rogue", {evil}), util::wall_utime())).refusal, OrdersRefusal::OtherSheriff);
  EXPECT_EQ(deliver(wrong_key.sign(orders("real", {evil}), util::wall_utime())).refusal, OrdersRefusal::AuthFailed);
  EXPECT_EQ(gate.refuse_plain(orders("real", {evil})).refusal, OrdersRefusal::Unauthenticated);
  h.run_for(300);
  EXPECT_FALSE(std::filesystem::exists(rogue_marker));
  ASSERT_NE(h.cmd(42), nullptr);
  EXPECT_NE(h.cmd(42)->pid, 0);
  EXPECT_EQ(h.cmd(43), nullptr);

  // The sheriff stops it; the recorded start, replayed, does not start it again.
  c.force_quit = true;
  ASSERT_TRUE(deliver(sheriff.sign(orders("real", {c}), util::wall_utime())).accepted());
  ASSERT_TRUE(h.run_until([&] { return h.cmd(42)->pid == 0; }));
  std::filesystem::remove(marker);
  EXPECT_EQ(deliver(recorded_start).refusal, OrdersRefusal::Replayed);
  h.run_for(300);
  EXPECT_EQ(h.cmd(42)->pid, 0);
  EXPECT_FALSE(std::filesystem::exists(marker));
  EXPECT_EQ(gate.accepted(), 3u);
}
