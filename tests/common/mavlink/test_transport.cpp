// The byte transports: a serial port over a pseudo-terminal pair, UDP listen/connect on loopback,
// and the specs refused with a message that says what was expected.
#include <gtest/gtest.h>
#include <pty.h>
#include <termios.h>
#include <unistd.h>

#include <chrono>
#include <stdexcept>
#include <string>
#include <thread>
#include <vector>

#include "common/mavlink/transport.hpp"

namespace aerie::mavlink {
namespace {

// Reads from `e` until `n` bytes arrived or a second passed.
std::vector<uint8_t> read_n(Endpoint& e, size_t n) {
  std::vector<uint8_t> got;
  const auto until = std::chrono::steady_clock::now() + std::chrono::seconds(1);
  while (got.size() < n && std::chrono::steady_clock::now() < until) {
    if (e.read(got) == 0) std::this_thread::sleep_for(std::chrono::milliseconds(1));
  }
  return got;
}

TEST(SerialEndpoint, CarriesBytesBothWaysOverAPseudoTerminal) {
  int master = -1, slave = -1;
  char name[256];
  ASSERT_EQ(openpty(&master, &slave, name, nullptr, nullptr), 0);
  auto port = open_endpoint(std::string("serial:") + name + ":921600");

  const std::vector<uint8_t> frame = {0xFD, 0x09, 0x00, 0x0A, 0x0D, 0x11, 0x00, 0xFF};  // CR, LF kept as they are
  ASSERT_TRUE(port->write(frame));
  std::vector<uint8_t> at_master(frame.size());
  size_t got = 0;
  while (got < frame.size()) {
    const ssize_t n = ::read(master, at_master.data() + got, frame.size() - got);
    ASSERT_GT(n, 0);
    got += static_cast<size_t>(n);
  }
  EXPECT_EQ(at_master, frame);

  const std::vector<uint8_t> reply = {1, 2, 3, 0x0D, 0x0A, 0x00};
  ASSERT_EQ(::write(master, reply.data(), reply.size()), static_cast<ssize_t>(reply.size()));
  EXPECT_EQ(read_n(*port, reply.size()), reply);
  ::close(slave);
  ::close(master);
}

// The line settings read back (scripts/arm.sh leaves this out under qemu-user, whose termios
// translation reads the pty's speed back as 0; on the board it runs).
TEST(SerialEndpoint, ConfiguresTheLineRawAtItsBaudRate) {
  int master = -1, slave = -1;
  char name[256];
  ASSERT_EQ(openpty(&master, &slave, name, nullptr, nullptr), 0);
  auto port = open_endpoint(std::string("serial:") + name + ":921600:rtscts");
  termios tio{};
  ASSERT_EQ(tcgetattr(slave, &tio), 0);
  EXPECT_EQ(cfgetospeed(&tio), static_cast<speed_t>(B921600));
  EXPECT_EQ(tio.c_lflag & (ICANON | ECHO), 0u);  // raw: no line discipline mangles frames
  EXPECT_NE(tio.c_cflag & CRTSCTS, 0u);
  ::close(slave);
  ::close(master);
}

TEST(UdpEndpoint, ListenAnswersTheLastSenderAndConnectReadsOnlyItsPeer) {
  auto server = open_endpoint("udp-listen:127.0.0.1:47611");
  EXPECT_FALSE(server->write(std::vector<uint8_t>{1}));  // no peer has spoken yet
  auto client = open_endpoint("udp:127.0.0.1:47611");
  ASSERT_TRUE(client->write(std::vector<uint8_t>{7, 8, 9}));
  EXPECT_EQ(read_n(*server, 3), (std::vector<uint8_t>{7, 8, 9}));
  ASSERT_TRUE(server->write(std::vector<uint8_t>{4, 5}));
  EXPECT_EQ(read_n(*client, 2), (std::vector<uint8_t>{4, 5}));

  // A third party that sends to the client's port is not its peer: dropped and counted.
  const uint16_t client_port = client->local_port();
  ASSERT_NE(client_port, 0);
  auto stranger = open_endpoint("udp:127.0.0.1:" + std::to_string(client_port));
  ASSERT_TRUE(stranger->write(std::vector<uint8_t>{6, 6, 6}));
  ASSERT_TRUE(server->write(std::vector<uint8_t>{3}));
  EXPECT_EQ(read_n(*client, 1), (std::vector<uint8_t>{3}));  // the peer's byte only
  EXPECT_EQ(client->foreign_datagrams(), 1);
}

TEST(Endpoint, MalformedSpecsAreRefusedSayingWhatIsExpected) {
  const auto message = [](const std::string& spec) {
    try {
      open_endpoint(spec);
    } catch (const std::exception& e) {
      return std::string(e.what());
    }
    return std::string();
  };
  EXPECT_NE(message("tcp:1.2.3.4:5").find("expected serial:DEVICE:BAUD"), std::string::npos);
  EXPECT_NE(message("serial:/dev/null:12345").find("921600"), std::string::npos);
  EXPECT_NE(message("serial:/dev/null:abc").find("baud rate 'abc'"), std::string::npos);
  EXPECT_NE(message("udp:localhost:14550").find("not an IPv4 address"), std::string::npos);
  EXPECT_NE(message("udp:127.0.0.1:70000").find("port '70000'"), std::string::npos);
  EXPECT_NE(message("serial:/nonexistent/tty:57600").find("cannot open /nonexistent/tty"), std::string::npos);
  EXPECT_NE(message("serial:/dev/null:57600").find("is not a serial port"), std::string::npos);
  EXPECT_NE(message("serial:/dev/null:57600:xonxoff").find("rtscts"), std::string::npos);
}

}  // namespace
}  // namespace aerie::mavlink
