// The two halves of the door as processes (aerie-link --half air|ground) in a network
// namespace the test creates: the air half on the "air" LCM network, the ground half on the
// "ground" one, joined by sealed UDP on the namespace's loopback. Issue 46's "must not
// connect" matrix at the node level (no key, a key others can read, wrong key, secure against
// insecure, tampered / truncated / replayed datagrams injected with a raw UDP socket), the
// policy (PMD_* refused at the air half even from a valid ground half, a flood rate limited,
// PILOT_CMD ABORT crossing up), and rekeying while messages flow.
#include <aerie/pilot_cmd_t.hpp>
#include <aerie/process_status_t.hpp>
#include <arpa/inet.h>
#include <gtest/gtest.h>
#include <netinet/in.h>
#include <sys/socket.h>
#include <sys/stat.h>
#include <unistd.h>

#include <algorithm>
#include <chrono>
#include <fstream>
#include <functional>
#include <map>
#include <set>
#include <thread>

#include "common/bus/bus.hpp"
#include "common/seal/keys.hpp"
#include "common/seal/operator.hpp"
#include "common/util/time.hpp"
#include "procman/testbed.hpp"
#include "tests/support/test_support.hpp"

using namespace aerie;
using namespace std::chrono_literals;
namespace testbed = aerie::procman::testbed;

namespace {

const std::string kAir = "udpm://239.255.76.67:7667?ttl=0";
const std::string kGround = "udpm://239.255.76.68:7668?ttl=0";
const std::string kAirDoor = "127.0.0.1:17101", kGroundDoor = "127.0.0.1:17102", kTap = "127.0.0.1:17103";

std::string bin(const std::string& name) { return (test::binary_dir() / "bin" / name).string(); }

int64_t counter(const aerie::process_status_t& s, const std::string& name) {
  for (int i = 0; i < s.ncounters; ++i)
    if (s.counter_names[i] == name) return s.counter_values[i];
  return -1;
}

sockaddr_in endpoint(const std::string& text) {
  sockaddr_in a{};
  a.sin_family = AF_INET;
  const auto colon = text.rfind(':');
  inet_pton(AF_INET, text.substr(0, colon).c_str(), &a.sin_addr);
  a.sin_port = htons(static_cast<uint16_t>(std::stoi(text.substr(colon + 1))));
  return a;
}

// A raw UDP socket of the test (inside the namespace): an intruder, or a tap between the halves.
class RawUdp {
 public:
  explicit RawUdp(const std::string& bind_to = "") {
    fd_ = socket(AF_INET, SOCK_DGRAM, 0);
    if (!bind_to.empty()) {
      const sockaddr_in a = endpoint(bind_to);
      EXPECT_EQ(bind(fd_, reinterpret_cast<const sockaddr*>(&a), sizeof(a)), 0) << bind_to;
    }
    timeval tv{0, 100000};
    setsockopt(fd_, SOL_SOCKET, SO_RCVTIMEO, &tv, sizeof(tv));
  }
  ~RawUdp() { close(fd_); }
  void send(const std::string& to, const std::vector<uint8_t>& d) const {
    const sockaddr_in a = endpoint(to);
    sendto(fd_, d.data(), d.size(), 0, reinterpret_cast<const sockaddr*>(&a), sizeof(a));
  }
  std::optional<std::vector<uint8_t>> receive() const {
    std::vector<uint8_t> b(70000);
    const ssize_t n = recv(fd_, b.data(), b.size(), 0);
    if (n < 0) return std::nullopt;
    b.resize(static_cast<size_t>(n));
    return b;
  }

 private:
  int fd_ = -1;
};

class DoorNode : public ::testing::Test {
 protected:
  void SetUp() override {
    if (const auto why = testbed::namespaces_unavailable(); !why.empty()) GTEST_SKIP() << why;
    ns_ = std::make_unique<testbed::NetNamespace>(testbed::unique_name("door"));
    dir_ = test::scratch_dir("door");
    write_operator_key();
    key_ = write_key("mission.key");
    other_key_ = write_key("other.key");
    config_ = write_config("link.yaml", "");
    testbed::EnterNamespace inside(*ns_);
    air_ = std::make_unique<bus::Bus>(kAir);
    ground_ = std::make_unique<bus::Bus>(kGround);
    air_->subscribe<aerie::process_status_t>("STATUS_LINK_AIR", [this](const auto& s, const auto&) { air_status_ = s; });
    ground_->subscribe<aerie::process_status_t>("STATUS_LINK_GROUND",
                                                [this](const auto& s, const auto&) { ground_status_ = s; });
    air_->subscribe<aerie::pilot_cmd_t>("PILOT_CMD", [this](const auto& m, const bus::ReceiveInfo& i) {
      pilot_on_air_.push_back(m);
      pilot_delay_ms_.push_back(static_cast<double>(i.recv_utime - m.utime) / 1000.0);
    }, 10000);
    air_->subscribe_raw("PMD_.*|FLC_PARAMS", [this](const uint8_t*, size_t, const bus::ReceiveInfo& i) {
      ++on_air_[i.channel];
    }, 10000);
    ground_->subscribe<aerie::process_status_t>("STATUS_LINK_AIR",
                                                [this](const auto& s, const auto&) { air_status_on_ground_ = s; });
    ground_->subscribe_raw("VO_POSE", [this](const uint8_t*, size_t, const bus::ReceiveInfo& i) { ++on_ground_[i.channel]; });
  }
  void TearDown() override {
    while (!halves_.empty()) halves_.pop_back();
    air_.reset();
    ground_.reset();
  }

  // The operator's key pair, as aerie-keys operator writes it.
  void write_operator_key() {
    operator_key_ = (dir_ / "operator.key").string();
    operator_pub_ = operator_key_ + ".pub";
    const seal::OperatorKey k = seal::OperatorKey::generate();
    k.save(operator_key_);
    k.public_key().save(operator_pub_);
  }
  std::string write_key(const std::string& name) {
    const auto path = (dir_ / name).string();
    seal::save_key(path, seal::SecretKey::generate());
    return path;
  }
  // The shipped config/link.yaml without impairments (exact counts), with `extra` appended.
  std::string write_config(const std::string& name, const std::string& extra) {
    const auto path = dir_ / name;
    std::ifstream in(test::source_dir() / "config/link.yaml");
    std::string text((std::istreambuf_iterator<char>(in)), std::istreambuf_iterator<char>());
    std::ofstream(path) << text << "\n" << extra;
    return path.string();
  }

  testbed::Process& start(const std::string& half, std::vector<std::string> args, const std::string& config = "",
                          const std::string& peer = "", const std::string& delay_ms = "0") {
    auto argv = ns_->exec_prefix();
    const bool air = half == "air";
    argv.insert(argv.end(), {bin("aerie-link"), "--half", half, "--config", config.empty() ? config_ : config,
                             "--listen", air ? kAirDoor : kGroundDoor, "--peer",
                             !peer.empty() ? peer : air ? kGroundDoor : kAirDoor,
                             "--lcm-url", air ? kAir : kGround, "--delay-ms", delay_ms, "--jitter-ms", "0", "--loss", "0",
                             "--bandwidth-kbps", "0", "--log-level", "debug"});
    argv.insert(argv.end(), args.begin(), args.end());
    // A keyed half gets the operator's role too: the ground half signs, the air half checks.
    if (operator_role_ && std::find(args.begin(), args.end(), "--key") != args.end() &&
        std::find(args.begin(), args.end(), "--insecure") == args.end())
      argv.insert(argv.end(), {air ? "--operator-pub" : "--operator-key", air ? operator_pub_ : operator_key_});
    halves_.push_back(std::make_unique<testbed::Process>(argv, (dir_ / (half + std::to_string(halves_.size()) + ".log")).string()));
    return *halves_.back();
  }
  // Both halves' first status (they are up).
  void wait_up() {
    const auto until = std::chrono::steady_clock::now() + 20s;
    while ((!air_status_ || !ground_status_) && std::chrono::steady_clock::now() < until) spin(50ms);
    ASSERT_TRUE(air_status_ && ground_status_) << logs();
    // A keyed ground half signs the operator's commands once it knows the air half's session.
    spin_until([&] { return ground_status_->message.find("waiting for the air half") == std::string::npos; }, 5s);
  }
  void spin(std::chrono::milliseconds d) {
    testbed::EnterNamespace inside(*ns_);
    const auto until = std::chrono::steady_clock::now() + d;
    while (std::chrono::steady_clock::now() < until) {
      air_->handle(5);
      ground_->handle(5);
    }
  }
  // Spins until `done` or the timeout.
  bool spin_until(const std::function<bool()>& done, std::chrono::milliseconds timeout = 10s) {
    const auto until = std::chrono::steady_clock::now() + timeout;
    while (!done() && std::chrono::steady_clock::now() < until) spin(20ms);
    return done();
  }
  // The next status of both halves (counters settled after `spin`).
  void fresh_status() {
    air_status_.reset();
    ground_status_.reset();
    spin_until([&] { return air_status_ && ground_status_; });
  }
  void publish_abort(int64_t seq) {
    aerie::pilot_cmd_t m{};
    m.utime = util::wall_utime();
    m.seq = seq;
    m.command = aerie::pilot_cmd_t::ABORT;
    m.source = "operator";
    testbed::EnterNamespace inside(*ns_);
    ground_->publish("PILOT_CMD", m);
  }
  void publish_raw(bool on_air, const std::string& channel, size_t size = 64) {
    std::vector<uint8_t> d(size, 0x5A);
    testbed::EnterNamespace inside(*ns_);
    (on_air ? *air_ : *ground_).publish_raw(channel, d.data(), d.size());
  }
  std::string logs() const {
    std::string s;
    for (const auto& h : halves_) s += "--- " + h->log_path() + ":\n" + h->log() + "\n";
    return s;
  }

  std::unique_ptr<testbed::NetNamespace> ns_;
  std::filesystem::path dir_;
  std::string key_, other_key_, config_, operator_key_, operator_pub_;
  bool operator_role_ = true;  // start() gives keyed halves the operator's keys
  std::unique_ptr<bus::Bus> air_, ground_;
  std::optional<aerie::process_status_t> air_status_, ground_status_, air_status_on_ground_;
  std::vector<aerie::pilot_cmd_t> pilot_on_air_;
  std::vector<double> pilot_delay_ms_;
  std::map<std::string, int> on_air_, on_ground_;
  std::vector<std::unique_ptr<testbed::Process>> halves_;
};

}  // namespace

TEST_F(DoorNode, WithoutAKeyAHalfRefusesToStartAndAKeyOthersCanReadIsRefused) {
  auto& no_key = start("air", {});
  ASSERT_EQ(no_key.wait(10s).value_or(-1), 2) << no_key.log();
  EXPECT_NE(no_key.log().find("refusing to start the air half without a key"), std::string::npos) << no_key.log();
  chmod(other_key_.c_str(), 0644);
  auto& readable = start("ground", {"--key", other_key_});
  ASSERT_EQ(readable.wait(10s).value_or(-1), 1) << readable.log();
  EXPECT_NE(readable.log().find(other_key_), std::string::npos) << readable.log();  // names the file
  auto& both = start("ground", {"--key", key_, "--insecure"});
  ASSERT_EQ(both.wait(10s).value_or(-1), 1) << both.log();
  EXPECT_NE(both.log().find("exclude each other"), std::string::npos) << both.log();
  // A keyed air half without the operator's public key would obey no command (or anyone's):
  // it refuses to start, naming the option; a ground half without an operator key only watches.
  operator_role_ = false;
  auto& no_operator = start("air", {"--key", key_});
  ASSERT_EQ(no_operator.wait(10s).value_or(-1), 1) << no_operator.log();
  EXPECT_NE(no_operator.log().find("--operator-pub"), std::string::npos) << no_operator.log();
  auto& wrong_half = start("air", {"--key", key_, "--operator-key", operator_key_});
  ASSERT_EQ(wrong_half.wait(10s).value_or(-1), 1) << wrong_half.log();
  EXPECT_NE(wrong_half.log().find("is the ground half's"), std::string::npos) << wrong_half.log();
}

TEST_F(DoorNode, SecureHalvesCarryTheOperatorsAbortUpAndTelemetryDownAndShowTheSameFingerprint) {
  start("air", {"--key", key_});
  start("ground", {"--key", key_});
  wait_up();
  int64_t seq = 0;
  ASSERT_TRUE(spin_until([&] {
    publish_abort(++seq);
    publish_raw(true, "VO_POSE");
    return !pilot_on_air_.empty() && on_ground_["VO_POSE"] > 0;
  })) << logs();
  EXPECT_EQ(pilot_on_air_[0].command, aerie::pilot_cmd_t::ABORT);
  EXPECT_EQ(pilot_on_air_[0].source, "operator");
  fresh_status();
  const std::string fp = seal::fingerprint(seal::load_key(key_));
  EXPECT_EQ(air_status_->message.rfind("SECURE key " + fp, 0), 0u) << air_status_->message;
  EXPECT_EQ(ground_status_->message.rfind("SECURE key " + fp, 0), 0u) << ground_status_->message;
  EXPECT_EQ(air_status_->health, aerie::process_status_t::OK);
  // The operator sees both halves' fingerprints on the ground (the air half's status crosses).
  ASSERT_TRUE(air_status_on_ground_) << logs();
  EXPECT_EQ(air_status_on_ground_->message.rfind("SECURE key " + fp, 0), 0u) << air_status_on_ground_->message;
  EXPECT_EQ(counter(*air_status_, "secure"), 1);
  EXPECT_GE(counter(*air_status_, "ground_to_air.delivered"), 1);
  EXPECT_EQ(counter(*air_status_, "ground_to_air.refused.authentication_failed"), 0);
  EXPECT_GE(counter(*ground_status_, "air_to_ground.delivered"), 1);
  // The key itself is in no log.
  const auto raw = seal::load_key(key_);
  std::string hex;
  for (size_t i = 0; i < 8; ++i) {
    char b[3];
    snprintf(b, sizeof(b), "%02x", raw.data()[i]);
    hex += b;
  }
  EXPECT_EQ(logs().find(hex), std::string::npos);
}

TEST_F(DoorNode, WrongKeyNothingCrossesAndTheReasonIsCounted) {
  start("air", {"--key", key_});
  start("ground", {"--key", other_key_});
  wait_up();
  for (int i = 1; i <= 20; ++i) {
    publish_abort(i);
    publish_raw(true, "VO_POSE");
    publish_raw(false, "MAP_RESPONSE");
    spin(50ms);
  }
  fresh_status();
  // Under the suite's load the last commands may still be on their way when a status is sent:
  // the next statuses (bounded) until all 20 are counted.
  spin_until([&] { return counter(*ground_status_, "ground_to_air.no_session") >= 20; });
  EXPECT_TRUE(pilot_on_air_.empty());
  EXPECT_EQ(on_ground_["VO_POSE"], 0);
  // The ground half never opened the air half's hello: it holds the operator's commands back.
  EXPECT_EQ(counter(*ground_status_, "ground_to_air.no_session"), 20) << logs();
  EXPECT_GE(counter(*air_status_, "ground_to_air.refused.authentication_failed"), 15) << logs();
  EXPECT_EQ(counter(*air_status_, "ground_to_air.delivered"), 0);
  EXPECT_GE(counter(*ground_status_, "air_to_ground.refused.authentication_failed"), 15);
  EXPECT_NE(air_status_->message, ground_status_->message.substr(0, air_status_->message.size()));  // fingerprints differ
}

TEST_F(DoorNode, ASecureHalfAndAnInsecureHalfDoNotConnect) {
  start("air", {"--key", key_});
  start("ground", {"--insecure"});
  wait_up();
  for (int i = 1; i <= 20; ++i) {
    publish_abort(i);
    publish_raw(true, "VO_POSE");
    spin(50ms);
  }
  fresh_status();
  EXPECT_TRUE(pilot_on_air_.empty());
  EXPECT_EQ(on_ground_["VO_POSE"], 0);
  EXPECT_GE(counter(*air_status_, "ground_to_air.insecure_peer"), 15) << logs();
  EXPECT_GE(counter(*ground_status_, "air_to_ground.secure_peer"), 15) << logs();
  // The insecure half says so in every status.
  EXPECT_EQ(ground_status_->health, aerie::process_status_t::WARN);
  EXPECT_EQ(ground_status_->message.rfind("INSECURE", 0), 0u) << ground_status_->message;
  EXPECT_EQ(counter(*ground_status_, "secure"), 0);
  fresh_status();
  EXPECT_EQ(ground_status_->message.rfind("INSECURE", 0), 0u);
}

TEST_F(DoorNode, InjectedTamperedTruncatedAndReplayedDatagramsAreRefusedAndCounted) {
  // The ground half sends to the test's tap, which forwards to the air half: the test holds
  // genuine sealed datagrams.
  start("air", {"--key", key_});
  start("ground", {"--key", key_}, "", kTap);
  wait_up();
  std::optional<RawUdp> tap;
  {
    testbed::EnterNamespace inside(*ns_);
    tap.emplace(kTap);
  }
  // Two genuine datagrams (counters 1 and 2 of the ground half).
  std::vector<std::vector<uint8_t>> captured;
  for (int i = 1; i <= 100 && captured.size() < 2; ++i) {
    publish_abort(i);
    spin(20ms);
    while (auto d = tap->receive()) captured.push_back(*d);
  }
  ASSERT_GE(captured.size(), 2u) << logs();
  const auto first = captured[0], second = captured[1];
  std::optional<RawUdp> in_ns;  // an intruder's socket, inside the namespace
  {
    testbed::EnterNamespace inside(*ns_);
    in_ns.emplace();
  }
  // Genuine: crosses once.
  in_ns->send(kAirDoor, first);
  ASSERT_TRUE(spin_until([&] { return pilot_on_air_.size() == 1; }, 5s)) << logs();
  // Replayed three times: refused by the window (before the tag is even checked).
  for (int i = 0; i < 3; ++i) in_ns->send(kAirDoor, first);
  // Tampered: the counter of the first (a fresh counter, so the tag is checked), the tag of the
  // second; truncated: below the minimum, and the second cut inside its tag; garbage with the magic.
  auto tampered = first;
  tampered[12] ^= 0x40;
  in_ns->send(kAirDoor, tampered);
  tampered = second;
  tampered.back() ^= 0x01;
  in_ns->send(kAirDoor, tampered);
  in_ns->send(kAirDoor, std::vector<uint8_t>(second.begin(), second.begin() + 20));
  in_ns->send(kAirDoor, std::vector<uint8_t>(second.begin(), second.end() - 1));
  in_ns->send(kAirDoor, std::vector<uint8_t>(100, 0xAE));
  spin(300ms);
  EXPECT_EQ(pilot_on_air_.size(), 1u);
  // A forged datagram never moves the window: the genuine second one still opens.
  in_ns->send(kAirDoor, second);
  ASSERT_TRUE(spin_until([&] { return pilot_on_air_.size() == 2; }, 5s)) << logs();
  spin(300ms);
  fresh_status();
  EXPECT_EQ(pilot_on_air_.size(), 2u);
  EXPECT_EQ(counter(*air_status_, "ground_to_air.refused.replayed"), 3) << logs();
  EXPECT_EQ(counter(*air_status_, "ground_to_air.refused.authentication_failed"), 3);
  EXPECT_EQ(counter(*air_status_, "ground_to_air.refused.too_short"), 1);
  EXPECT_EQ(counter(*air_status_, "ground_to_air.refused.bad_version"), 1);
  EXPECT_EQ(counter(*air_status_, "ground_to_air.delivered"), 2);
  EXPECT_EQ(counter(*air_status_, "ground_to_air.received"), 10);
}

TEST_F(DoorNode, ProcmanOrdersFromAValidGroundHalfAreRefusedAtTheAirHalf) {
  // A compromised (or misconfigured) ground half sends PMD_ORDERS2; the air half's shipped
  // policy drops them and counts them.
  const std::string loose = write_config("loose.yaml", "");
  {
    std::ifstream in(loose);
    std::string text((std::istreambuf_iterator<char>(in)), std::istreambuf_iterator<char>());
    const std::string from = "channels: \"PILOT_CMD|TRACK_CMD|FLC_PARAMS|MAP_CMD|MAP_QUERY|MAP_RESPONSE\"";
    const auto at = text.find(from);
    ASSERT_NE(at, std::string::npos);
    text.replace(at, from.size(), "channels: \"PILOT_CMD|TRACK_CMD|FLC_PARAMS|MAP_CMD|MAP_QUERY|MAP_RESPONSE|PMD_.*\"");
    std::ofstream(loose) << text;
  }
  start("air", {"--key", key_});
  start("ground", {"--key", key_}, loose);
  wait_up();
  for (int i = 1; i <= 10; ++i) {
    publish_raw(false, "PMD_ORDERS2");
    publish_raw(false, "PMD_DISCOVER");
    spin(30ms);
  }
  publish_abort(1);
  ASSERT_TRUE(spin_until([&] { return !pilot_on_air_.empty(); }, 5s)) << logs();
  fresh_status();
  EXPECT_EQ(on_air_["PMD_ORDERS2"], 0);
  EXPECT_EQ(on_air_["PMD_DISCOVER"], 0);
  EXPECT_EQ(counter(*ground_status_, "ground_to_air.sent"), 21) << logs();
  EXPECT_EQ(counter(*air_status_, "ground_to_air.not_allowed"), 20);
  EXPECT_EQ(counter(*air_status_, "ground_to_air.delivered"), 1);
}

TEST_F(DoorNode, AFloodOfAbortsIsRateLimitedAtTheAirHalf) {
  start("air", {"--key", key_});
  start("ground", {"--key", key_});
  wait_up();
  publish_abort(0);
  ASSERT_TRUE(spin_until([&] { return !pilot_on_air_.empty(); }, 5s)) << logs();
  pilot_on_air_.clear();
  const auto t0 = std::chrono::steady_clock::now();
  for (int i = 1; i <= 300; ++i) {
    publish_abort(i);
    if (i % 50 == 0) spin(5ms);
  }
  const double elapsed = std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
  spin(500ms);
  fresh_status();
  const int64_t sent = counter(*ground_status_, "ground_to_air.sent");
  const int64_t delivered = counter(*air_status_, "ground_to_air.delivered");
  const int64_t limited = counter(*air_status_, "ground_to_air.rate_limited");
  // PILOT_CMD: 20 per second, bucket of 40 (config/link.yaml); the first ABORT took one.
  EXPECT_LE(delivered, 40 + static_cast<int64_t>(20 * (elapsed + 0.6)) + 1) << elapsed << " s";
  EXPECT_GE(limited, 200) << logs();
  EXPECT_EQ(delivered + limited, sent);  // every datagram accounted for
  EXPECT_EQ(static_cast<int64_t>(pilot_on_air_.size()) + 1, delivered);
}

TEST_F(DoorNode, RekeyingWhileMessagesFlowDeliversEachMessageOnce) {
  const std::string fast = write_config("fast.yaml", "");
  {
    std::ifstream in(fast);
    std::string text((std::istreambuf_iterator<char>(in)), std::istreambuf_iterator<char>());
    const std::string from = "  seconds: 120\n";
    text.replace(text.find(from), from.size(), "  seconds: 0.4\n");
    std::ofstream(fast) << text;
  }
  start("air", {"--key", key_}, fast);
  start("ground", {"--key", key_}, fast);
  wait_up();
  const int n = 150;
  for (int i = 0; i < n; ++i) {
    publish_raw(false, "FLC_PARAMS", 100);
    spin(20ms);  // 50 Hz for 3 s: about 7 epochs
  }
  spin(500ms);
  fresh_status();
  EXPECT_EQ(on_air_["FLC_PARAMS"], n) << logs();
  EXPECT_EQ(counter(*air_status_, "ground_to_air.delivered"), n);
  EXPECT_EQ(counter(*air_status_, "ground_to_air.refused.expired_epoch"), 0);
  EXPECT_GE(counter(*ground_status_, "epoch"), 5);
  EXPECT_EQ(counter(*air_status_, "peer_epoch"), counter(*ground_status_, "epoch"));
  EXPECT_NE(air_status_->message.find("peer epoch " + std::to_string(counter(*ground_status_, "epoch"))), std::string::npos)
      << air_status_->message;
}

TEST_F(DoorNode, TheImpairmentsApplyOnTheSendingSideBeforeSealing) {
  // 30 ms on both directions (the command line sets both): what crosses up waits at the
  // ground half, then is sealed, sent and opened at once.
  start("air", {"--key", key_}, "", "", "30");
  start("ground", {"--key", key_}, "", "", "30");
  wait_up();
  for (int i = 1; i <= 20; ++i) {
    publish_abort(i);
    spin(60ms);
  }
  spin(300ms);
  ASSERT_EQ(pilot_on_air_.size(), 20u) << logs();
  std::vector<double> d = pilot_delay_ms_;
  std::sort(d.begin(), d.end());
  EXPECT_GE(d.front(), 30.0);
  EXPECT_LT(d[d.size() / 2], 45.0) << "30 ms + the door on a loaded machine";
  fresh_status();
  EXPECT_EQ(counter(*air_status_, "ground_to_air.refused.authentication_failed"), 0);
}
