#include "tools/link/door_node.hpp"

#include <aerie/link_stats_t.hpp>
#include <arpa/inet.h>
#include <fcntl.h>
#include <poll.h>
#include <spdlog/spdlog.h>
#include <sys/socket.h>
#include <unistd.h>

#include <algorithm>
#include <cerrno>
#include <chrono>
#include <cstring>
#include <random>
#include <stdexcept>

#include "common/util/time.hpp"
#include "tools/latency/stats.hpp"

namespace aerie::link {
namespace {

int64_t mono_us() {
  return std::chrono::duration_cast<std::chrono::microseconds>(std::chrono::steady_clock::now().time_since_epoch())
      .count();
}

// "authentication failed" -> "authentication_failed" (a status counter's name).
std::string counter_name(const char* reason) {
  std::string s(reason);
  std::replace(s.begin(), s.end(), ' ', '_');
  return s;
}

uint32_t random_sender() {
  std::random_device rd;
  uint32_t s = 0;
  while (s == 0) s = rd();
  return s;
}

}  // namespace

sockaddr_in parse_endpoint(const std::string& text, const std::string& what) {
  const auto colon = text.rfind(':');
  sockaddr_in a{};
  a.sin_family = AF_INET;
  if (colon == std::string::npos || colon == 0 || colon + 1 == text.size())
    throw std::invalid_argument(what + ": expected ADDR:PORT (IPv4), got '" + text + "'");
  const std::string host = text.substr(0, colon), port = text.substr(colon + 1);
  if (inet_pton(AF_INET, host.c_str(), &a.sin_addr) != 1)
    throw std::invalid_argument(what + ": '" + host + "' is not a numeric IPv4 address (in '" + text + "')");
  char* end = nullptr;
  const long p = std::strtol(port.c_str(), &end, 10);
  if (*end != '\0' || p < 0 || p > 65535)
    throw std::invalid_argument(what + ": port '" + port + "' is not in [0, 65535] (in '" + text + "')");
  a.sin_port = htons(static_cast<uint16_t>(p));
  return a;
}

UdpSocket::UdpSocket(const std::string& listen) {
  const sockaddr_in a = parse_endpoint(listen, "--listen");
  fd_ = ::socket(AF_INET, SOCK_DGRAM | SOCK_NONBLOCK | SOCK_CLOEXEC, 0);
  if (fd_ < 0) throw std::runtime_error(std::string("door: socket(): ") + std::strerror(errno));
  // Room for a burst of image fragments while the loop is busy.
  // Room for a burst of image fragments while the loop is busy (a raw stereo pair is 12
  // datagrams of 64 kB): past net.core.rmem_max when privileged (SO_RCVBUFFORCE).
  const int size = 8 << 20;
  if (setsockopt(fd_, SOL_SOCKET, SO_RCVBUFFORCE, &size, sizeof(size)) != 0)
    setsockopt(fd_, SOL_SOCKET, SO_RCVBUF, &size, sizeof(size));
  if (setsockopt(fd_, SOL_SOCKET, SO_SNDBUFFORCE, &size, sizeof(size)) != 0)
    setsockopt(fd_, SOL_SOCKET, SO_SNDBUF, &size, sizeof(size));
  if (::bind(fd_, reinterpret_cast<const sockaddr*>(&a), sizeof(a)) != 0) {
    const std::string why = std::strerror(errno);
    ::close(fd_);
    throw std::runtime_error("door: cannot listen on " + listen + ": " + why);
  }
}

UdpSocket::~UdpSocket() {
  if (fd_ >= 0) ::close(fd_);
}

uint16_t UdpSocket::port() const {
  sockaddr_in a{};
  socklen_t n = sizeof(a);
  getsockname(fd_, reinterpret_cast<sockaddr*>(&a), &n);
  return ntohs(a.sin_port);
}

namespace {
DirectionConfig outgoing_config(const LinkConfig& c, Half h) {
  DirectionConfig d = h == Half::kAir ? c.air_to_ground : c.ground_to_air;
  if (d.channels.empty()) d.channels = "$^";
  return d;
}
seal::OpenerConfig opener_config(const LinkConfig& c) {
  seal::OpenerConfig o;
  o.overlap_s = c.rekey_overlap_s;
  o.max_senders = 64;  // each restart of the far half is a new sender (a random id)
  return o;
}
}  // namespace

DoorHalf::DoorHalf(bus::Bus& bus, UdpSocket& socket, const LinkConfig& config, HalfOptions options,
                   const seal::SecretKey* key, CommandKeys commands)
    : Node(bus, options.half == Half::kAir ? "link-air" : "link-ground", config.stats_period_s),
      socket_(socket),
      config_(config),
      options_(options),
      key_(key),
      fingerprint_(key ? seal::fingerprint(*key) : std::string("none")),
      peer_(parse_endpoint(options.peer, "--peer")),
      relay_(outgoing_config(config, options.half)),
      sender_(key, outgoing(options.half), options.sender ? options.sender : random_sender(), options.first_epoch,
              mono_us() * 1e-6, config.rekey, config.reassembly),
      receiver_(key, incoming(options.half), config.policy(incoming(options.half)), opener_config(config),
                config.reassembly),
      out_channels_(relay_.model().config().channels),
      buffer_(seal::kMaxDatagram + 1) {
  const std::string out = relay_.model().config().channels;
  if (out != "$^")
    subscribe_raw(out, [this](const uint8_t* data, size_t size, const bus::ReceiveInfo& info) {
      // The half's own status crosses (STATUS_.*): the operator compares both halves' fingerprints.
      if (info.channel == config_.stats_channel) return;
      if (echo_.is_echo(EchoFilter::key(info.channel, data, size))) return;
      if (!seal::valid_channel(info.channel)) return;
      relay_.take(info.channel, data, size, info.recv_utime, mono_us());
    }, 10000);
  if (key_ && options_.half == Half::kAir) {
    session_ = seal::new_session();
    if (!commands.operators.empty()) {
      roles_ = "operators";
      for (const auto& op : commands.operators) roles_ += " " + op.fingerprint();
      receiver_.require_operator(seal::CommandVerifier(std::move(commands.operators), session_));
    } else if (!config_.operator_channels.empty()) {
      throw std::invalid_argument(
          "the air half accepts the operator's commands (ground_to_air.operator_channels: " +
          config_.operator_channels +
          ") only with the operator's public key: give --operator-pub FILE.pub (aerie-keys operator --out FILE), or set "
          "ground_to_air.operator_channels: \"\" to accept no command");
    } else {
      roles_ = "no operator commands";
    }
  } else if (key_) {
    roles_ = commands.operator_key ? "operator key " + commands.operator_key->public_key().fingerprint()
                                   : std::string("no operator key: telemetry only, commands refused");
    std::optional<seal::CommandSigner> signer;
    if (commands.operator_key) signer.emplace(std::move(*commands.operator_key));
    sender_.sign_commands(config_.operator_channels, std::move(signer));
  }
  next_stats_us_ = mono_us() + static_cast<int64_t>(config_.stats_period_s * 1e6);
  send_hello();
  refresh_status();
}

void DoorHalf::send_hello() {
  if (!key_) return;
  // At most 10 a second, whatever asks: a flood of requests gets no flood of answers.
  const int64_t now = mono_us();
  if (last_hello_us_ != 0 && now - last_hello_us_ < 100'000) return;
  last_hello_us_ = now;
  datagrams_.resize(1);
  const bool made = options_.half == Half::kAir ? sender_.hello(session_, now_s(), datagrams_[0])
                                                : sender_.hello_request(now_s(), datagrams_[0]);
  if (made && ::sendto(socket_.fd(), datagrams_[0].data(), datagrams_[0].size(), 0,
                       reinterpret_cast<const sockaddr*>(&peer_), sizeof(peer_)) < 0)
    ++send_errors_;
}

double DoorHalf::now_s() const { return static_cast<double>(mono_us()) * 1e-6; }

std::string DoorHalf::status_line() const {
  const char* dir = direction_key(outgoing(options_.half));
  if (!key_)
    return std::string("INSECURE: no key (--insecure), datagrams in the clear and unauthenticated; ") + half_name(options_.half) +
           " half, sends " + dir;
  std::string s = "SECURE key " + fingerprint_ + " epoch " + std::to_string(sender_.epoch());
  const int64_t pe = receiver_.peer_epoch();
  s += " peer epoch " + (pe < 0 ? std::string("-") : std::to_string(pe));
  s += std::string("; ") + half_name(options_.half) + " half, sends " + dir + "; " + roles_;
  if (options_.half == Half::kGround && sender_.has_session()) s += " (air session known)";
  else if (options_.half == Half::kGround) s += " (waiting for the air half's hello)";
  if (!last_refusal_.empty()) s += "; last refusal: " + last_refusal_;
  return s;
}

void DoorHalf::refresh_status() {
  auto& st = status();
  const std::string out = direction_key(outgoing(options_.half));
  const std::string in = direction_key(incoming(options_.half));
  const auto& s = sender_.counters();
  const auto& c = relay_.model().counters();
  st.set(out + ".taken", c.received);
  st.set(out + ".sent", static_cast<int64_t>(s.messages));
  st.set(out + ".datagrams", static_cast<int64_t>(s.datagrams));
  st.set(out + ".fragments", static_cast<int64_t>(s.fragments));
  st.set(out + ".bytes", static_cast<int64_t>(s.bytes));
  st.set(out + ".too_large", static_cast<int64_t>(s.too_large));
  st.set(out + ".signed_commands", static_cast<int64_t>(s.signed_commands));
  st.set(out + ".unsigned_commands", static_cast<int64_t>(s.unsigned_commands));
  st.set(out + ".no_session", static_cast<int64_t>(s.no_session));
  st.set(out + ".hellos", static_cast<int64_t>(s.hellos));
  st.set(out + ".send_errors", static_cast<int64_t>(send_errors_));
  st.set(out + ".dropped_loss", c.dropped_loss);
  st.set(out + ".dropped_queue", c.dropped_queue);
  const auto& r = receiver_.counters();
  st.set(in + ".received", static_cast<int64_t>(r.datagrams));
  st.set(in + ".fragments", static_cast<int64_t>(r.fragments));
  st.set(in + ".delivered", static_cast<int64_t>(r.delivered));
  st.set(in + ".not_allowed", static_cast<int64_t>(r.not_allowed));
  st.set(in + ".rate_limited", static_cast<int64_t>(r.rate_limited));
  st.set(in + ".insecure_peer", static_cast<int64_t>(r.insecure_peer));
  st.set(in + ".secure_peer", static_cast<int64_t>(r.secure_peer));
  st.set(in + ".malformed", static_cast<int64_t>(r.malformed));
  st.set(in + ".reassembly_dropped", static_cast<int64_t>(r.reassembly_dropped));
  st.set(in + ".oversize", static_cast<int64_t>(oversize_in_));
  st.set(in + ".too_large", static_cast<int64_t>(r.too_large));
  st.set(in + ".hellos", static_cast<int64_t>(r.hellos));
  st.set(in + ".commands_verified", static_cast<int64_t>(r.commands_verified));
  for (size_t i = 1; i < seal::kCommandRefusalCount; ++i)
    st.set(in + ".commands_refused." + counter_name(seal::to_string(static_cast<seal::CommandRefusal>(i))),
           static_cast<int64_t>(r.commands_refused[i]));
  st.set(in + ".opened", static_cast<int64_t>(r.opener.opened));
  for (size_t i = 1; i < seal::kRefusalCount; ++i)
    st.set(in + ".refused." + counter_name(seal::to_string(static_cast<seal::Refusal>(i))),
           static_cast<int64_t>(r.opener.refused[i]));
  st.set("epoch", sender_.epoch());
  st.set("peer_epoch", receiver_.peer_epoch());
  st.set("secure", key_ ? 1 : 0);
  if (key_) st.ok(status_line());
  else st.warn(status_line());  // every period: an insecure door is never quietly OK
}

int DoorHalf::receive_datagrams() {
  int n = 0;
  while (n < 4096) {  // then back to the loop: LCM and the timers get their turn under a flood
    const ssize_t got = ::recv(socket_.fd(), buffer_.data(), buffer_.size(), MSG_TRUNC);
    if (got < 0) break;  // EAGAIN: nothing more
    ++n;
    if (static_cast<size_t>(got) > seal::kMaxDatagram) {
      ++oversize_in_;
      continue;
    }
    auto m = receiver_.receive(std::span<const uint8_t>(buffer_.data(), static_cast<size_t>(got)), now_s());
    if (!m) {
      if (!receiver_.why().empty()) {
        if (last_refusal_ != receiver_.why()) spdlog::debug("door: refused: {}", receiver_.why());
        last_refusal_ = receiver_.why();
      }
      continue;
    }
    // What this half publishes may match its own outgoing channels: not an echo back.
    if (out_channels_(m->channel)) echo_.sent(EchoFilter::key(m->channel, m->payload.data(), m->payload.size()), mono_us());
    bus().publish_raw(m->channel, m->payload.data(), m->payload.size());
  }
  return n;
}

void DoorHalf::send_due(int64_t now_us) {
  const double t = static_cast<double>(now_us) * 1e-6;
  if (options_.half == Half::kAir && receiver_.take_hello_request()) send_hello();
  if (const auto& session = receiver_.peer_session()) sender_.set_session(*session);
  else if (options_.half == Half::kGround) send_hello();  // ask for it
  for (auto& p : relay_.due(now_us)) {
    // Each datagram leaves as soon as it is sealed (the far half opens it while this one seals the next).
    const bool sent = sender_.send(p.channel, p.data, t, [this](std::span<const uint8_t> d) {
      if (::sendto(socket_.fd(), d.data(), d.size(), 0, reinterpret_cast<const sockaddr*>(&peer_), sizeof(peer_)) < 0)
        ++send_errors_;
    });
    if (!sent) continue;  // too large, or a command that cannot be signed: counted
    delays_ms_.push_back(static_cast<double>(util::wall_utime() - p.recv_wall_utime) / 1000.0);
  }
}

void DoorHalf::publish_stats(int64_t now_us) {
  aerie::link_stats_t s;
  s.utime = util::wall_utime();
  s.seq = stats_seq_++;
  s.period_s = config_.stats_period_s;
  const auto& c = relay_.model().counters();
  aerie::link_direction_stats_t d;
  d.name = relay_.model().config().name;
  d.received = c.received;
  d.delivered = c.delivered;
  d.bytes_delivered = c.bytes_delivered;
  d.dropped_loss = c.dropped_loss;
  d.dropped_queue = c.dropped_queue;
  d.dropped_other = c.dropped_other + static_cast<int64_t>(sender_.counters().too_large);
  d.reencoded = c.reencoded;
  d.queue_depth = relay_.model().queue_depth();
  d.queue_bytes = relay_.model().queue_bytes();
  const auto delay = latency::summarize(std::move(delays_ms_));
  d.delay_p50_ms = delay.median;
  d.delay_p90_ms = delay.p90;
  d.delay_p99_ms = delay.p99;
  d.delay_max_ms = delay.max;
  d.throughput_bps = static_cast<double>(c.bytes_delivered - bytes_at_period_start_) * 8.0 / config_.stats_period_s;
  bytes_at_period_start_ = c.bytes_delivered;
  delays_ms_.clear();
  s.directions.push_back(std::move(d));
  s.ndirections = 1;
  const bool on = options_.half == Half::kAir ? config_.stats_on_air : config_.stats_on_ground;
  if (on) bus().publish(config_.stats_channel, s);
  (void)now_us;
}

void DoorHalf::tick(int64_t) {
  // The node's clock is monotonic here (the impairments' and the sealer's), not the wall's.
  const int64_t now = mono_us();
  send_due(now);
  receiver_.expire(static_cast<double>(now) * 1e-6);
  if (now - last_refresh_us_ >= 200'000) {
    refresh_status();
    last_refresh_us_ = now;
  }
  if (now >= next_stats_us_) {
    publish_stats(now);
    if (options_.half == Half::kAir) send_hello();  // once a period, unasked
    const int64_t period = static_cast<int64_t>(config_.stats_period_s * 1e6);
    next_stats_us_ += period;
    if (next_stats_us_ < now) next_stats_us_ = now + period;
  }
}

void DoorHalf::run() {
  bus::install_stop_handlers();
  while (!bus::stop_requested()) {
    const int64_t now = mono_us();
    int64_t wake = std::min(next_stats_us_, now + 50'000);
    if (const int64_t t = relay_.model().next_event_us(); t >= 0) wake = std::min(wake, t);
    pollfd fds[2] = {{bus().fileno(), POLLIN, 0}, {socket_.fd(), POLLIN, 0}};
    const int64_t wait_us = std::max<int64_t>(0, wake - now);
    const timespec ts{static_cast<time_t>(wait_us / 1000000), static_cast<long>((wait_us % 1000000) * 1000)};
    ppoll(fds, 2, &ts, nullptr);
    if (fds[0].revents & POLLIN)
      for (int n = 0; n < 1000 && bus().handle(0) > 0; ++n) {
      }
    if (fds[1].revents & POLLIN) receive_datagrams();
    try {
      tick(util::wall_utime());
    } catch (const std::exception& e) {
      status().count("loop_errors");
      spdlog::error("{}", e.what());
    }
    status().tick();
  }
  refresh_status();
  status().publish_now();
  const auto& s = sender_.counters();
  const auto& r = receiver_.counters();
  spdlog::info("{} half: sent {} messages in {} datagrams; received {} datagrams, delivered {}, not allowed {}, "
               "rate limited {}, refused {} (seal), insecure peer {}, secure peer {}",
               half_name(options_.half), s.messages, s.datagrams, r.datagrams, r.delivered, r.not_allowed,
               r.rate_limited, r.opener.refused_total(), r.insecure_peer, r.secure_peer);
}

}  // namespace aerie::link
