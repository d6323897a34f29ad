// Nothing but the door is reachable from the radio (issue 46 section 1; docs/security.md
// "Deployment: one door"), as scripts/air-netns.sh deploys it on both hosts, in namespaces the
// test creates and removes (also on failure): "nodes" (the air nodes, loopback only), "radio"
// (the air host's radio side, where only the air half runs, its LCM sockets opened in "nodes"
// with --lcm-netns), "ground" (the ground station's radio side, only the ground half) joined to
// "radio" by a veth pair, and "gnodes" (the ground's nodes, loopback only). From "ground",
// forged PILOT_CMD and PMD_ORDERS2 are sent as LCM would send them -- by multicast across the
// veth and by unicast to the air side's radio address, port 7667 -- and reach no air node;
// from "radio", the same towards the ground station's port 7668 reach no ground node (which
// the ground half would sign with the operator's key); only the doors' ports are open, and a
// forged datagram to the air's is refused and counted. The operator's real ABORT, from the
// ground's nodes through both halves, does reach the air nodes.
#include <aerie/pilot_cmd_t.hpp>
#include <aerie/process_status_t.hpp>
#include <arpa/inet.h>
#include <gtest/gtest.h>
#include <netinet/in.h>
#include <sys/socket.h>
#include <unistd.h>

#include <cerrno>
#include <chrono>
#include <cstring>
#include <map>

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

const std::string kAirUrl = "udpm://239.255.76.67:7667?ttl=0";
const std::string kGroundUrl = "udpm://239.255.76.68:7668?ttl=0";
const std::string kAirRadio = "10.214.0.1", kGroundRadio = "10.214.0.2";
constexpr int kDoorPort = 17200;

int64_t counter(const aerie::process_status_t& s, const std::string& name) {
  for (int i = 0; i < s.ncounters; ++i)
    if (s.counter_names[i] == name) return s.counter_values[i];
  return -1;
}

// An LCM "short message" datagram (LCM's UDP multicast protocol: magic "LC02", sequence
// number, channel, NUL, the encoded message): what a node's socket on port 7667 would take.
std::vector<uint8_t> lcm_datagram(const std::string& channel, const std::vector<uint8_t>& payload, uint32_t seq) {
  std::vector<uint8_t> d = {0x4c, 0x43, 0x30, 0x32};
  for (int i = 3; i >= 0; --i) d.push_back(static_cast<uint8_t>(seq >> (8 * i)));
  d.insert(d.end(), channel.begin(), channel.end());
  d.push_back(0);
  d.insert(d.end(), payload.begin(), payload.end());
  return d;
}

std::vector<uint8_t> encoded_abort() {
  aerie::pilot_cmd_t m{};
  m.utime = util::wall_utime();
  m.seq = 99;
  m.command = aerie::pilot_cmd_t::LAND;
  m.source = "intruder";
  std::vector<uint8_t> b(static_cast<size_t>(m.getEncodedSize()));
  m.encode(b.data(), 0, static_cast<int>(b.size()));
  return b;
}

// Sends `d` to addr:port from a connected UDP socket and says whether the host answered
// "port unreachable" (ECONNREFUSED on the next receive): nothing listens there.
bool port_closed(const std::string& addr, int port, const std::vector<uint8_t>& d) {
  const int fd = socket(AF_INET, SOCK_DGRAM, 0);
  sockaddr_in a{};
  a.sin_family = AF_INET;
  a.sin_port = htons(static_cast<uint16_t>(port));
  inet_pton(AF_INET, addr.c_str(), &a.sin_addr);
  connect(fd, reinterpret_cast<const sockaddr*>(&a), sizeof(a));
  timeval tv{0, 300000};
  setsockopt(fd, SOL_SOCKET, SO_RCVTIMEO, &tv, sizeof(tv));
  bool refused = false;
  for (int i = 0; i < 3 && !refused; ++i) {
    send(fd, d.data(), d.size(), 0);
    char b[16];
    refused = recv(fd, b, sizeof(b), 0) < 0 && errno == ECONNREFUSED;
  }
  close(fd);
  return refused;
}

void multicast(const std::string& group, int port, const std::vector<uint8_t>& d) {
  const int fd = socket(AF_INET, SOCK_DGRAM, 0);
  const unsigned char ttl = 1;
  setsockopt(fd, IPPROTO_IP, IP_MULTICAST_TTL, &ttl, sizeof(ttl));
  sockaddr_in a{};
  a.sin_family = AF_INET;
  a.sin_port = htons(static_cast<uint16_t>(port));
  inet_pton(AF_INET, group.c_str(), &a.sin_addr);
  sendto(fd, d.data(), d.size(), 0, reinterpret_cast<const sockaddr*>(&a), sizeof(a));
  close(fd);
}

}  // namespace

TEST(OneDoor, NothingButTheDoorIsReachableFromTheRadio) {
  if (const auto why = testbed::namespaces_unavailable(); !why.empty()) GTEST_SKIP() << why;
  const auto dir = test::scratch_dir("one-door");
  // The ground station is deployed the same way: its nodes in "gnodes" (loopback only), its
  // half in "ground", which holds the link to the radio.
  testbed::NetNamespace nodes(testbed::unique_name("nodes")), radio(testbed::unique_name("radio")),
      ground(testbed::unique_name("ground")), gnodes(testbed::unique_name("gnodes"));
  testbed::join_with_veth(radio, ground, 214);
  // The ground station's own LCM stays on its loopback (ttl=0).
  testbed::run({"ip", "-n", gnodes.name(), "route", "add", "239.255.76.68/32", "dev", "lo"});
  const std::string key = (dir / "mission.key").string();
  seal::save_key(key, seal::SecretKey::generate());
  const std::string op_key = (dir / "operator.key").string();
  const seal::OperatorKey op = seal::OperatorKey::generate();
  op.save(op_key);
  op.public_key().save(op_key + ".pub");
  const std::string cfg = (test::source_dir() / "config/link.yaml").string();
  const std::string script = (test::source_dir() / "scripts/air-netns.sh").string();
  const std::string bin = (test::binary_dir() / "bin").string();
  const std::string door = std::to_string(kDoorPort);
  const std::vector<std::string> no_impairments = {"--delay-ms", "0", "--jitter-ms", "0", "--loss", "0",
                                                    "--bandwidth-kbps", "0"};

  // The air nodes: the test's own bus in "nodes" stands for the pilot and the deputy.
  std::unique_ptr<bus::Bus> air, gnd;
  std::vector<aerie::pilot_cmd_t> pilot;
  std::map<std::string, int> procman;
  std::optional<aerie::process_status_t> air_status;
  {
    testbed::EnterNamespace inside(nodes);
    air = std::make_unique<bus::Bus>(kAirUrl);
    air->subscribe<aerie::pilot_cmd_t>("PILOT_CMD", [&](const auto& m, const auto&) { pilot.push_back(m); });
    air->subscribe_raw("PMD_.*", [&](const uint8_t*, size_t, const bus::ReceiveInfo& i) { ++procman[i.channel]; });
    air->subscribe<aerie::process_status_t>("STATUS_LINK_AIR", [&](const auto& s, const auto&) { air_status = s; });
  }
  std::vector<aerie::pilot_cmd_t> ground_pilot;  // what the ground's own nodes hear
  {
    testbed::EnterNamespace inside(gnodes);
    gnd = std::make_unique<bus::Bus>(kGroundUrl);
    gnd->subscribe<aerie::pilot_cmd_t>("PILOT_CMD", [&](const auto& m, const auto&) { ground_pilot.push_back(m); });
  }
  std::vector<std::string> air_half = {"bash", script, "door", "--nodes-ns", nodes.name(), "--radio-ns", radio.name(),
                                       "--bin", bin, "--config", cfg, "--", "--key", key,
                                       "--listen", kAirRadio + ":" + door, "--peer", kGroundRadio + ":" + door,
                                       "--lcm-url", kAirUrl, "--operator-pub", op_key + ".pub"};
  air_half.insert(air_half.end(), no_impairments.begin(), no_impairments.end());
  testbed::Process air_door(air_half, (dir / "air-half.log").string());
  std::vector<std::string> ground_half = {"bash", script, "door", "--half", "ground", "--nodes-ns", gnodes.name(),
                                          "--radio-ns", ground.name(), "--bin", bin, "--config", cfg, "--", "--key", key,
                                          "--listen", kGroundRadio + ":" + door, "--peer", kAirRadio + ":" + door,
                                          "--lcm-url", kGroundUrl, "--operator-key", op_key};
  ground_half.insert(ground_half.end(), no_impairments.begin(), no_impairments.end());
  testbed::Process ground_door(ground_half, (dir / "ground-half.log").string());
  auto spin = [&](std::chrono::milliseconds d) {
    const auto until = std::chrono::steady_clock::now() + d;
    while (std::chrono::steady_clock::now() < until) air->handle(10);
  };
  const auto until = std::chrono::steady_clock::now() + 20s;
  while (!air_status && air_door.running() && std::chrono::steady_clock::now() < until) spin(50ms);
  ASSERT_TRUE(air_status) << air_door.log();
  EXPECT_EQ(air_status->message.rfind("SECURE", 0), 0u) << air_status->message;

  // The launcher's own check: the nodes' namespace has loopback only, and in the radio's
  // namespace only aerie-link listens.
  const std::string check = testbed::run({"bash", script, "check", "--nodes-ns", nodes.name(), "--radio-ns", radio.name()});
  EXPECT_NE(check.find("one door"), std::string::npos) << check;
  const std::string ground_check = testbed::run(
      {"bash", script, "check", "--half", "ground", "--nodes-ns", gnodes.name(), "--radio-ns", ground.name()});
  EXPECT_NE(ground_check.find("one door"), std::string::npos) << ground_check;

  // The attacks, from the ground namespace.
  const auto forged_pilot = lcm_datagram("PILOT_CMD", encoded_abort(), 1);
  const auto forged_orders = lcm_datagram("PMD_ORDERS2", std::vector<uint8_t>(64, 0), 2);
  bool pilot_port_closed = false, door_port_closed = true;
  {
    testbed::EnterNamespace inside(ground);
    for (int i = 0; i < 5; ++i) {
      multicast("239.255.76.67", 7667, forged_pilot);   // as a node would publish, ttl=1 across the veth
      multicast("239.255.76.67", 7667, forged_orders);
    }
    // Unicast to the air side's radio address: nothing listens on 7667 there (port unreachable).
    pilot_port_closed = port_closed(kAirRadio, 7667, forged_pilot);
    EXPECT_TRUE(port_closed(kAirRadio, 7667, forged_orders));
    // The door's port is open (no "unreachable"), and what it gets is refused.
    door_port_closed = port_closed(kAirRadio, kDoorPort, forged_pilot);
  }
  // And towards the ground station, from the radio: a command put on the ground's LCM would be
  // signed by the ground half with the operator's key. Nothing listens on 7668 there either.
  bool ground_port_closed = false;
  {
    testbed::EnterNamespace inside(radio);
    for (int i = 0; i < 5; ++i) multicast("239.255.76.68", 7668, forged_pilot);
    ground_port_closed = port_closed(kGroundRadio, 7668, forged_pilot);
  }
  EXPECT_TRUE(ground_port_closed) << "something listens on " << kGroundRadio << ":7668";
  EXPECT_TRUE(pilot_port_closed) << "something listens on " << kAirRadio << ":7667";
  EXPECT_FALSE(door_port_closed) << "the door does not listen on " << kAirRadio << ":" << kDoorPort;
  spin(500ms);
  gnd->handle(0);
  EXPECT_TRUE(ground_pilot.empty()) << "a forged PILOT_CMD reached a ground node";
  EXPECT_TRUE(pilot.empty()) << "a forged PILOT_CMD reached an air node";
  EXPECT_TRUE(procman.empty()) << "a forged PMD_ORDERS2 reached an air node";

  // The operator's ABORT through the ground half does reach the air nodes.
  for (int i = 1; i <= 100 && pilot.empty(); ++i) {
    aerie::pilot_cmd_t m{};
    m.utime = util::wall_utime();
    m.seq = i;
    m.command = aerie::pilot_cmd_t::ABORT;
    m.source = "operator";
    {
      testbed::EnterNamespace inside(gnodes);
      gnd->publish("PILOT_CMD", m);
    }
    spin(50ms);
  }
  ASSERT_EQ(pilot.size(), 1u) << air_door.log() << ground_door.log();
  EXPECT_EQ(pilot[0].source, "operator");
  EXPECT_EQ(pilot[0].command, aerie::pilot_cmd_t::ABORT);

  // The forged datagrams sent to the door were refused and counted (not a sealed datagram).
  air_status.reset();
  while (!air_status && std::chrono::steady_clock::now() < until + 10s) spin(50ms);
  ASSERT_TRUE(air_status);
  EXPECT_GE(counter(*air_status, "ground_to_air.refused.bad_version"), 1) << air_door.log();
  EXPECT_EQ(counter(*air_status, "ground_to_air.delivered"), 1);
  EXPECT_TRUE(procman.empty());

  // Control: the same forged datagrams do reach a node that joins LCM on the radio's side (the
  // deployment before issue 46), so the attacks above were well-formed.
  std::unique_ptr<bus::Bus> exposed;
  int exposed_heard = 0;
  {
    testbed::EnterNamespace inside(radio);
    exposed = std::make_unique<bus::Bus>(kAirUrl);
    exposed->subscribe<aerie::pilot_cmd_t>("PILOT_CMD", [&](const auto&, const auto&) { ++exposed_heard; });
  }
  {
    testbed::EnterNamespace inside(ground);
    multicast("239.255.76.67", 7667, forged_pilot);
    (void)port_closed(kAirRadio, 7667, forged_pilot);
  }
  for (int i = 0; i < 20 && exposed_heard < 2; ++i) exposed->handle(50);
  EXPECT_GE(exposed_heard, 2) << "multicast and unicast forged PILOT_CMD reach an exposed node";
}
