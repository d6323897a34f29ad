#include "common/mavlink/transport.hpp"

#include <arpa/inet.h>
#include <fcntl.h>
#include <netinet/in.h>
#include <sys/socket.h>
#include <termios.h>
#include <unistd.h>

#include <cerrno>
#include <cstring>
#include <deque>
#include <stdexcept>

namespace aerie::mavlink {

namespace {

std::vector<std::string> split(const std::string& s, char sep) {
  std::vector<std::string> parts;
  size_t start = 0;
  for (size_t i = 0; i <= s.size(); ++i)
    if (i == s.size() || s[i] == sep) {
      parts.push_back(s.substr(start, i - start));
      start = i + 1;
    }
  return parts;
}

int parse_int(const std::string& text, const std::string& spec, const std::string& what, int lo, int hi) {
  size_t used = 0;
  int v = 0;
  try {
    v = std::stoi(text, &used);
  } catch (const std::exception&) {
    used = 0;
  }
  if (used != text.size() || v < lo || v > hi)
    throw std::invalid_argument("endpoint '" + spec + "': " + what + " '" + text + "' is not a number in [" +
                                std::to_string(lo) + ", " + std::to_string(hi) + "]");
  return v;
}

sockaddr_in parse_address(const std::string& host, const std::string& port, const std::string& spec) {
  sockaddr_in a{};
  a.sin_family = AF_INET;
  a.sin_port = htons(static_cast<uint16_t>(parse_int(port, spec, "port", 0, 65535)));
  if (inet_pton(AF_INET, host.c_str(), &a.sin_addr) != 1)
    throw std::invalid_argument("endpoint '" + spec + "': '" + host + "' is not an IPv4 address");
  return a;
}

std::string sys_error(const std::string& spec, const std::string& what) {
  return "endpoint '" + spec + "': " + what + ": " + std::strerror(errno);
}

class SerialEndpoint final : public Endpoint {
 public:
  SerialEndpoint(const std::string& spec, const std::string& device, int baud, bool flow)
      : Endpoint(::open(device.c_str(), O_RDWR | O_NOCTTY | O_NONBLOCK | O_CLOEXEC), spec) {
    if (fd_ < 0) throw std::runtime_error(sys_error(spec, "cannot open " + device));
    termios tio{};
    if (::tcgetattr(fd_, &tio) != 0) {
      const std::string e = sys_error(spec, device + " is not a serial port");
      ::close(fd_);
      throw std::runtime_error(e);
    }
    ::cfmakeraw(&tio);  // 8 data bits, no parity, no echo, no line discipline
    tio.c_cflag |= CLOCAL | CREAD;
    tio.c_cflag &= ~CSTOPB;
    if (flow)
      tio.c_cflag |= CRTSCTS;
    else
      tio.c_cflag &= ~CRTSCTS;
    tio.c_cc[VMIN] = 0;
    tio.c_cc[VTIME] = 0;
    const speed_t speed = baud_constant(baud);
    ::cfsetispeed(&tio, speed);
    ::cfsetospeed(&tio, speed);
    if (::tcsetattr(fd_, TCSANOW, &tio) != 0) {
      const std::string e = sys_error(spec, "cannot configure " + device);
      ::close(fd_);
      throw std::runtime_error(e);
    }
    ::tcflush(fd_, TCIOFLUSH);
  }
  ~SerialEndpoint() override { ::close(fd_); }

  size_t read(std::vector<uint8_t>& out) override {
    uint8_t buf[4096];
    size_t total = 0;
    for (;;) {
      const ssize_t n = ::read(fd_, buf, sizeof buf);
      if (n > 0) {
        out.insert(out.end(), buf, buf + n);
        total += static_cast<size_t>(n);
        continue;
      }
      if (n < 0 && (errno == EAGAIN || errno == EWOULDBLOCK || errno == EINTR)) return total;
      if (n == 0) return total;  // a pty whose other end is gone reads EIO below, not 0
      throw std::runtime_error(sys_error(name_, "read failed"));
    }
  }
  bool write(std::span<const uint8_t> bytes) override {
    const ssize_t n = ::write(fd_, bytes.data(), bytes.size());
    return n == static_cast<ssize_t>(bytes.size());
  }
};

class UdpEndpoint final : public Endpoint {
 public:
  // listen: bind `local` and answer the last sender; connect: send to `peer`, read only from it.
  UdpEndpoint(const std::string& spec, const sockaddr_in& address, bool listen)
      : Endpoint(::socket(AF_INET, SOCK_DGRAM | SOCK_NONBLOCK | SOCK_CLOEXEC, 0), spec), listen_(listen) {
    if (fd_ < 0) throw std::runtime_error(sys_error(spec, "cannot create a UDP socket"));
    if (listen) {
      if (::bind(fd_, reinterpret_cast<const sockaddr*>(&address), sizeof address) != 0) {
        const std::string e = sys_error(spec, "cannot bind");
        ::close(fd_);
        throw std::runtime_error(e);
      }
    } else {
      peer_ = address;
      have_peer_ = true;
    }
  }
  ~UdpEndpoint() override { ::close(fd_); }

  size_t read(std::vector<uint8_t>& out) override {
    uint8_t buf[65536];
    size_t total = 0;
    for (;;) {
      sockaddr_in from{};
      socklen_t len = sizeof from;
      const ssize_t n = ::recvfrom(fd_, buf, sizeof buf, 0, reinterpret_cast<sockaddr*>(&from), &len);
      if (n < 0) {
        if (errno == EAGAIN || errno == EWOULDBLOCK || errno == EINTR || errno == ECONNREFUSED) return total;
        throw std::runtime_error(sys_error(name_, "receive failed"));
      }
      if (listen_) {
        peer_ = from;  // answer whoever spoke last, as mavlink-router's UDP server does
        have_peer_ = true;
      } else if (from.sin_addr.s_addr != peer_.sin_addr.s_addr || from.sin_port != peer_.sin_port) {
        ++foreign_;
        continue;
      }
      out.insert(out.end(), buf, buf + n);
      total += static_cast<size_t>(n);
    }
  }
  bool write(std::span<const uint8_t> bytes) override {
    if (!have_peer_) return false;
    const ssize_t n = ::sendto(fd_, bytes.data(), bytes.size(), 0, reinterpret_cast<const sockaddr*>(&peer_), sizeof peer_);
    return n == static_cast<ssize_t>(bytes.size());
  }

 private:
  bool listen_;
  bool have_peer_ = false;
  sockaddr_in peer_{};
};

class MemoryEndpoint final : public Endpoint {
 public:
  using Queue = std::deque<uint8_t>;
  MemoryEndpoint(std::string name, std::shared_ptr<Queue> in, std::shared_ptr<Queue> out)
      : Endpoint(-1, std::move(name)), in_(std::move(in)), out_(std::move(out)) {}
  size_t read(std::vector<uint8_t>& out) override {
    const size_t n = in_->size();
    out.insert(out.end(), in_->begin(), in_->end());
    in_->clear();
    return n;
  }
  bool write(std::span<const uint8_t> bytes) override {
    out_->insert(out_->end(), bytes.begin(), bytes.end());
    return true;
  }

 private:
  std::shared_ptr<Queue> in_, out_;
};

}  // namespace

std::pair<std::unique_ptr<Endpoint>, std::unique_ptr<Endpoint>> memory_pipe(const std::string& name) {
  auto a_to_b = std::make_shared<MemoryEndpoint::Queue>(), b_to_a = std::make_shared<MemoryEndpoint::Queue>();
  return {std::make_unique<MemoryEndpoint>(name + ":a", b_to_a, a_to_b),
          std::make_unique<MemoryEndpoint>(name + ":b", a_to_b, b_to_a)};
}

uint16_t Endpoint::local_port() const {
  sockaddr_in a{};
  socklen_t len = sizeof a;
  if (::getsockname(fd_, reinterpret_cast<sockaddr*>(&a), &len) != 0 || a.sin_family != AF_INET) return 0;
  return ntohs(a.sin_port);
}

unsigned baud_constant(int baud) {
  switch (baud) {
    case 9600: return B9600;
    case 19200: return B19200;
    case 38400: return B38400;
    case 57600: return B57600;
    case 115200: return B115200;
    case 230400: return B230400;
    case 460800: return B460800;
    case 500000: return B500000;
    case 921600: return B921600;
    case 1000000: return B1000000;
    case 1500000: return B1500000;
    case 2000000: return B2000000;
    case 3000000: return B3000000;
    default:
      throw std::invalid_argument("baud rate " + std::to_string(baud) +
                                  " is not one of 9600 ... 3000000 (921600 for a Pixhawk's TELEM2)");
  }
}

std::unique_ptr<Endpoint> open_endpoint(const std::string& spec) {
  const auto parts = split(spec, ':');
  const std::string& kind = parts[0];
  if (kind == "serial" && (parts.size() == 3 || parts.size() == 4)) {
    const int baud = parse_int(parts[2], spec, "baud rate", 1, 4000000);
    baud_constant(baud);  // refused before the device is touched
    bool flow = false;
    if (parts.size() == 4) {
      if (parts[3] != "rtscts") throw std::invalid_argument("endpoint '" + spec + "': flow control must be 'rtscts'");
      flow = true;
    }
    return std::make_unique<SerialEndpoint>(spec, parts[1], baud, flow);
  }
  if ((kind == "udp-listen" || kind == "udp") && parts.size() == 3)
    return std::make_unique<UdpEndpoint>(spec, parse_address(parts[1], parts[2], spec), kind == "udp-listen");
  throw std::invalid_argument("endpoint '" + spec +
                              "': expected serial:DEVICE:BAUD[:rtscts], udp-listen:ADDRESS:PORT or udp:ADDRESS:PORT");
}

}  // namespace aerie::mavlink
