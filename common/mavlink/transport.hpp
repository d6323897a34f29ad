#pragma once
// Byte transports to a MAVLink peer (docs/mavlink.md, "Endpoints"), named by one spec string;
// the bridge (air/mavlink) and the simulator's autopilot (common/sim/autopilot) both use them:
//
//   serial:/dev/ttyAMA0:921600        a UART (termios, raw, 8N1), e.g. a Pixhawk's TELEM2
//   serial:/dev/ttyAMA0:921600:rtscts the same with hardware flow control
//   udp-listen:0.0.0.0:14540          wait for a peer (SITL, a radio modem, QGroundControl) and
//                                     answer the address it last sent from
//   udp:127.0.0.1:14550               send to a fixed peer (QGroundControl's default port); only
//                                     datagrams from that address are read
//
// Reads and writes never block: the node polls every endpoint's fd.
#include <cstddef>
#include <cstdint>
#include <memory>
#include <span>
#include <string>
#include <utility>
#include <vector>

namespace aerie::mavlink {

class Endpoint {
 public:
  virtual ~Endpoint() = default;
  // Appends what is available now; returns how many bytes (0 = nothing). Throws
  // std::runtime_error naming the endpoint when it has failed for good (a serial port unplugged).
  virtual size_t read(std::vector<uint8_t>& out) = 0;
  // Sends the bytes (one frame); false when they could not all go out now (counted by the caller).
  virtual bool write(std::span<const uint8_t> bytes) = 0;
  int fd() const { return fd_; }
  const std::string& name() const { return name_; }
  // Bytes refused by the endpoint itself (a UDP datagram from an address other than the peer's).
  int64_t foreign_datagrams() const { return foreign_; }
  // The local UDP port (0 for a serial port).
  uint16_t local_port() const;

 protected:
  Endpoint(int fd, std::string name) : fd_(fd), name_(std::move(name)) {}
  int fd_;
  std::string name_;
  int64_t foreign_ = 0;
};

// Two endpoints joined in memory (no fd: fd() is -1): what one writes, the other reads, in
// order and whole. For flights in one process (the lock-step benches) and tests.
std::pair<std::unique_ptr<Endpoint>, std::unique_ptr<Endpoint>> memory_pipe(const std::string& name);

// Opens the endpoint a spec names. Throws std::invalid_argument for a malformed spec (naming
// what was expected) and std::runtime_error when the device or socket cannot be opened.
std::unique_ptr<Endpoint> open_endpoint(const std::string& spec);

// The termios speed constant of a baud rate; throws std::invalid_argument for a rate termios has not.
unsigned baud_constant(int baud);

}  // namespace aerie::mavlink
