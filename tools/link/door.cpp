#include "tools/link/door.hpp"

#include <algorithm>
#include <cmath>
#include <cstring>
#include <stdexcept>

namespace aerie::link {

Half half_from_name(const std::string& name) {
  if (name == "air") return Half::kAir;
  if (name == "ground") return Half::kGround;
  throw std::invalid_argument("--half must be air or ground, not '" + name + "'");
}
const char* half_name(Half h) { return h == Half::kAir ? "air" : "ground"; }
seal::Direction outgoing(Half h) { return h == Half::kAir ? seal::Direction::AirToGround : seal::Direction::GroundToAir; }
seal::Direction incoming(Half h) { return h == Half::kAir ? seal::Direction::GroundToAir : seal::Direction::AirToGround; }
const char* direction_key(seal::Direction d) {
  return d == seal::Direction::AirToGround ? "air_to_ground" : "ground_to_air";
}

namespace {
void put_u16(uint8_t* p, uint16_t v) {
  p[0] = static_cast<uint8_t>(v);
  p[1] = static_cast<uint8_t>(v >> 8);
}
void put_u32(uint8_t* p, uint32_t v) {
  for (int i = 0; i < 4; ++i) p[i] = static_cast<uint8_t>(v >> (8 * i));
}
uint16_t get_u16(const uint8_t* p) { return static_cast<uint16_t>(p[0] | (p[1] << 8)); }
uint32_t get_u32(const uint8_t* p) {
  uint32_t v = 0;
  for (int i = 3; i >= 0; --i) v = (v << 8) | p[i];
  return v;
}
constexpr size_t kInsecureHeader = 5;  // magic, version, flags, reserved, channel length
constexpr uint8_t kDirectionBit = 0x01;
}  // namespace

// --- rates -----------------------------------------------------------------------------------

void RateRule::validate() const {
  const auto check = [&](double v, const char* field) {
    if (!(v >= 0) || !std::isfinite(v))
      throw std::invalid_argument(std::string("rate rule '") + channels + "': " + field +
                                  " must be >= 0 and finite, got " + std::to_string(v));
  };
  if (channels.empty()) throw std::invalid_argument("rate rule: channels must name a regex, got \"\"");
  check(messages_per_s, "messages_per_s");
  check(message_burst, "message_burst");
  check(bytes_per_s, "bytes_per_s");
  check(byte_burst, "byte_burst");
  try {
    ChannelMatcher m(channels);
  } catch (const std::regex_error& e) {
    throw std::invalid_argument("rate rule: channels '" + channels + "' is not a regex: " + e.what());
  }
}

TokenBucket::TokenBucket(double rate_per_s, double burst) : rate_(rate_per_s), burst_(burst), tokens_(burst) {}

bool TokenBucket::take(double n, double now_s) {
  if (rate_ <= 0) return true;
  if (!started_) {
    started_ = true;
    last_s_ = now_s;
  }
  if (now_s > last_s_) {
    tokens_ = std::min(burst_, tokens_ + (now_s - last_s_) * rate_);
    last_s_ = now_s;
  }
  if (tokens_ < n) return false;
  tokens_ -= n;
  return true;
}

RateLimiter::RateLimiter(std::vector<RateRule> rules) : rules_(std::move(rules)) {
  for (const auto& r : rules_) {
    r.validate();
    matchers_.emplace_back(r.channels);
  }
}

bool RateLimiter::admit(const std::string& channel, size_t bytes, double now_s) {
  auto it = channels_.find(channel);
  if (it == channels_.end()) {
    Buckets b;
    for (size_t i = 0; i < rules_.size(); ++i) {
      if (!matchers_[i](channel)) continue;
      const RateRule& r = rules_[i];
      b.limited = true;
      b.messages = TokenBucket(r.messages_per_s, r.message_burst > 0 ? r.message_burst : std::max(1.0, r.messages_per_s));
      b.bytes = TokenBucket(r.bytes_per_s, r.byte_burst > 0 ? r.byte_burst : r.bytes_per_s);
      break;
    }
    if (!b.limited) return true;
    if (channels_.size() >= kMaxChannels) return false;
    it = channels_.emplace(channel, b).first;
  }
  Buckets& b = it->second;
  // A message too large for the byte bucket's depth could never pass: refused like a flood.
  const bool msg_ok = b.messages.take(1, now_s);
  return msg_ok && b.bytes.take(static_cast<double>(bytes), now_s);
}

void ReassemblyLimits::validate() const {
  if (max_message_bytes < 1 || max_message_bytes > (size_t{1} << 28))
    throw std::invalid_argument("reassembly: max_message_bytes must be in [1, 2^28], got " +
                                std::to_string(max_message_bytes));
  if (max_pending_bytes < max_message_bytes)
    throw std::invalid_argument("reassembly: max_pending_bytes (" + std::to_string(max_pending_bytes) +
                                ") must be >= max_message_bytes (" + std::to_string(max_message_bytes) + ")");
  if (max_pending_messages < 1 || max_pending_messages > 1024)
    throw std::invalid_argument("reassembly: max_pending_messages must be in [1, 1024], got " +
                                std::to_string(max_pending_messages));
  if (!(timeout_s > 0) || !std::isfinite(timeout_s))
    throw std::invalid_argument("reassembly: timeout_s must be > 0, got " + std::to_string(timeout_s));
  if (max_datagram_bytes < 512 || max_datagram_bytes > seal::kMaxDatagram)
    throw std::invalid_argument("max_datagram_bytes must be in [512, " + std::to_string(seal::kMaxDatagram) +
                                "], got " + std::to_string(max_datagram_bytes));
}

// --- sender ------------------------------------------------------------------------------------

DoorSender::DoorSender(const seal::SecretKey* key, seal::Direction direction, uint32_t sender, uint32_t epoch,
                       double now_s, seal::RekeyPolicy rekey, ReassemblyLimits limits)
    : direction_(direction), limits_(limits) {
  limits_.validate();
  if (key) sealer_.emplace(*key, direction, sender, epoch, now_s, rekey);
}

void DoorSender::emit(std::string_view channel, std::span<const uint8_t> frame, double now_s,
                      std::vector<uint8_t>& out) {
  if (sealer_) {
    sealer_->seal_into(channel, frame, now_s, out);
  } else {
    out.resize(kInsecureHeader + channel.size() + frame.size());
    out[0] = kInsecureMagic;
    out[1] = kInsecureVersion;
    out[2] = direction_ == seal::Direction::GroundToAir ? kDirectionBit : 0;
    out[3] = 0;
    out[4] = static_cast<uint8_t>(channel.size());
    std::memcpy(out.data() + kInsecureHeader, channel.data(), channel.size());
    if (!frame.empty()) std::memcpy(out.data() + kInsecureHeader + channel.size(), frame.data(), frame.size());
  }
  ++counters_.datagrams;
  counters_.bytes += out.size();
}

void DoorSender::sign_commands(const std::string& operator_channels, std::optional<seal::CommandSigner> signer) {
  operator_channels_ = ChannelMatcher(operator_channels);
  signer_.reset();
  if (signer) signer_.emplace(std::move(*signer));
}

bool DoorSender::emit_hello(std::span<const uint8_t> body, double now_s, std::vector<uint8_t>& out) {
  if (!sealer_) return false;
  frame_.resize(1 + body.size());
  frame_[0] = 2;
  if (!body.empty()) std::memcpy(frame_.data() + 1, body.data(), body.size());
  emit(kHelloChannel, frame_, now_s, out);
  ++counters_.hellos;
  return true;
}

bool DoorSender::hello(const seal::Session& session, double now_s, std::vector<uint8_t>& out) {
  return emit_hello(session, now_s, out);
}

bool DoorSender::hello_request(double now_s, std::vector<uint8_t>& out) { return emit_hello({}, now_s, out); }

bool DoorSender::send(std::string_view channel, std::span<const uint8_t> payload, double now_s,
                      std::vector<std::vector<uint8_t>>& out) {
  out.clear();
  return send(channel, payload, now_s, [&](std::span<const uint8_t> d) { out.emplace_back(d.begin(), d.end()); });
}

bool DoorSender::send(std::string_view channel, std::span<const uint8_t> payload, double now_s,
                      const DatagramSink& out) {
  if (!seal::valid_channel(channel))
    throw std::invalid_argument("door: channel '" + std::string(channel) + "' is not a valid channel name");
  if (sealer_ && operator_channels_(std::string(channel))) {
    if (!signer_) {
      ++counters_.unsigned_commands;
      return false;
    }
    if (!session_) {
      ++counters_.no_session;
      return false;
    }
    const std::vector<uint8_t> envelope = signer_->sign(*session_, channel, payload);
    ++counters_.signed_commands;
    return split(channel, envelope, now_s, out);
  }
  return split(channel, payload, now_s, out);
}

bool DoorSender::split(std::string_view channel, std::span<const uint8_t> payload, double now_s,
                       const DatagramSink& out) {
  if (payload.size() > limits_.max_message_bytes) {
    ++counters_.too_large;
    return false;
  }
  // The room for the frame in one datagram, whatever the channel's length (seal.hpp kMaxPayload).
  const size_t room = limits_.max_datagram_bytes - (seal::kMaxDatagram - seal::kMaxPayload);
  if (payload.size() + kWholeHeader <= room) {
    frame_.resize(kWholeHeader + payload.size());
    frame_[0] = 0;
    if (!payload.empty()) std::memcpy(frame_.data() + 1, payload.data(), payload.size());
    emit(channel, frame_, now_s, datagram_);
    out(datagram_);
  } else {
    const size_t chunk = room - kFragmentHeader;
    const size_t count = (payload.size() + chunk - 1) / chunk;
    if (count > 0xFFFF) {
      ++counters_.too_large;
      return false;
    }
    const uint32_t id = next_message_++;
    for (size_t i = 0; i < count; ++i) {
      const size_t off = i * chunk, n = std::min(chunk, payload.size() - off);
      frame_.resize(kFragmentHeader + n);
      frame_[0] = 1;
      put_u32(&frame_[1], id);
      put_u16(&frame_[5], static_cast<uint16_t>(i));
      put_u16(&frame_[7], static_cast<uint16_t>(count));
      put_u32(&frame_[9], static_cast<uint32_t>(payload.size()));
      put_u32(&frame_[13], static_cast<uint32_t>(off));
      std::memcpy(frame_.data() + kFragmentHeader, payload.data() + off, n);
      emit(channel, frame_, now_s, datagram_);
      ++counters_.fragments;
      out(datagram_);
    }
  }
  ++counters_.messages;
  return true;
}

// --- receiver ----------------------------------------------------------------------------------

DoorReceiver::DoorReceiver(const seal::SecretKey* key, seal::Direction direction, DoorPolicy policy,
                           seal::OpenerConfig opener, ReassemblyLimits limits)
    : direction_(direction),
      allowed_(policy.channels),
      operator_channels_(direction == seal::Direction::GroundToAir ? policy.operator_channels : std::string()),
      rates_(std::move(policy.rates)),
      limits_(limits) {
  limits_.validate();
  opener.direction = direction;
  if (key) opener_.emplace(*key, opener);
}

const ReceiverCounters& DoorReceiver::counters() const {
  if (opener_) counters_.opener = opener_->counters();
  return counters_;
}

int64_t DoorReceiver::peer_epoch() const {
  return opener_ && any_sender_ ? opener_->current_epoch(last_sender_) : -1;
}

bool DoorReceiver::refuse(uint64_t& counter, std::string why) {
  ++counter;
  why_ = std::move(why);
  return false;
}

std::optional<Delivered> DoorReceiver::receive(std::span<const uint8_t> d, double now_s) {
  ++counters_.datagrams;
  why_.clear();
  expire(now_s);
  if (opener_) {
    if (!d.empty() && d[0] == kInsecureMagic) {
      refuse(counters_.insecure_peer, "a datagram in the clear (an --insecure half) reached a secure half");
      return std::nullopt;
    }
    if (!opener_->open_into(d, now_s, opened_)) {
      why_ = std::string(seal::to_string(opened_.refusal)) + ": " + opened_.why;
      return std::nullopt;
    }
    last_sender_ = opened_.sender;
    any_sender_ = true;
    return on_frame(opened_.sender, opened_.channel, opened_.payload, now_s);
  }
  // Insecure: only frames in the clear of this direction.
  if (!d.empty() && d[0] == seal::kMagic) {
    refuse(counters_.secure_peer, "a sealed datagram reached an insecure half (it has no key)");
    return std::nullopt;
  }
  if (d.size() < kInsecureHeader + 1 + kWholeHeader || d[0] != kInsecureMagic || d[1] != kInsecureVersion ||
      d[3] != 0 || (d[2] & ~kDirectionBit) != 0) {
    refuse(counters_.malformed, "not an insecure door datagram (magic/version/size)");
    return std::nullopt;
  }
  const bool g2a = (d[2] & kDirectionBit) != 0;
  if (g2a != (direction_ == seal::Direction::GroundToAir)) {
    refuse(counters_.malformed, "a datagram of the other direction");
    return std::nullopt;
  }
  const size_t n = d[4];
  if (n == 0 || n > seal::kMaxChannel || kInsecureHeader + n + kWholeHeader > d.size()) {
    refuse(counters_.malformed, "channel length " + std::to_string(n) + " out of range");
    return std::nullopt;
  }
  const std::string_view channel(reinterpret_cast<const char*>(d.data() + kInsecureHeader), n);
  if (!seal::valid_channel(channel)) {
    refuse(counters_.malformed, "channel name not printable");
    return std::nullopt;
  }
  return on_frame(0, channel, d.subspan(kInsecureHeader + n), now_s);
}

std::optional<Delivered> DoorReceiver::on_frame(uint32_t sender, std::string_view channel_view,
                                                std::span<const uint8_t> f, double now_s) {
  std::string channel(channel_view);
  if (f.empty() || f[0] > 2) {
    refuse(counters_.malformed, "frame kind missing or unknown");
    return std::nullopt;
  }
  if (f[0] == 2) {
    on_hello(channel, f);
    return std::nullopt;
  }
  if (f[0] == 1) ++counters_.fragments;
  // The policy first: a channel that may not cross is never buffered.
  if (!allowed_(channel)) {
    refuse(counters_.not_allowed, channel + " may not cross " + direction_key(direction_));
    return std::nullopt;
  }
  if (f[0] == 0) {
    if (f.size() - kWholeHeader > limits_.max_message_bytes) {
      refuse(counters_.too_large, channel + ": message of " + std::to_string(f.size() - kWholeHeader) +
                                      " bytes over max_message_bytes");
      return std::nullopt;
    }
    return admit(std::move(channel), std::vector<uint8_t>(f.begin() + 1, f.end()), now_s);
  }

  if (f.size() < kFragmentHeader) {
    refuse(counters_.malformed, "fragment header truncated");
    return std::nullopt;
  }
  const uint32_t id = get_u32(&f[1]);
  const uint16_t index = get_u16(&f[5]), count = get_u16(&f[7]);
  const uint32_t total = get_u32(&f[9]), offset = get_u32(&f[13]);
  const size_t n = f.size() - kFragmentHeader;
  if (count < 2 || index >= count || total == 0 || offset > total || n > total - offset || n == 0) {
    refuse(counters_.malformed, "fragment " + std::to_string(index) + "/" + std::to_string(count) + " at " +
                                    std::to_string(offset) + "+" + std::to_string(n) + " of " + std::to_string(total));
    return std::nullopt;
  }
  if (total > limits_.max_message_bytes) {
    refuse(counters_.too_large, channel + ": message of " + std::to_string(total) + " bytes over max_message_bytes");
    return std::nullopt;
  }
  const uint64_t key = (uint64_t{sender} << 32) | id;
  auto it = pending_.find(key);
  if (it == pending_.end()) {
    // Room first: the oldest incomplete messages give way (counted).
    while (!pending_.empty() &&
           (pending_.size() >= limits_.max_pending_messages || pending_bytes_ + total > limits_.max_pending_bytes)) {
      auto oldest = std::min_element(pending_.begin(), pending_.end(),
                                     [](const auto& a, const auto& b) { return a.second.first_s < b.second.first_s; });
      drop(oldest);
    }
    Pending p;
    p.channel = channel;
    p.total = total;
    p.count = count;
    p.first_s = now_s;
    p.have.assign(count, false);
    p.data.resize(total);
    pending_bytes_ += total;
    it = pending_.emplace(key, std::move(p)).first;
  }
  Pending& p = it->second;
  if (p.channel != channel || p.total != total || p.count != count) {
    refuse(counters_.malformed, "fragment disagrees with its message's first fragment");
    return std::nullopt;
  }
  if (p.have[index]) {
    refuse(counters_.malformed, "fragment " + std::to_string(index) + " given twice");
    return std::nullopt;
  }
  p.have[index] = true;
  ++p.received;
  p.bytes += n;
  std::memcpy(p.data.data() + offset, &f[kFragmentHeader], n);
  if (p.received < p.count) return std::nullopt;
  if (p.bytes != p.total) {
    drop(it);
    why_ = "fragments do not add up to the message";
    return std::nullopt;
  }
  std::vector<uint8_t> data = std::move(p.data);
  pending_bytes_ -= p.total;
  pending_.erase(it);
  return admit(std::move(channel), std::move(data), now_s);
}

bool DoorReceiver::on_hello(const std::string& channel, std::span<const uint8_t> f) {
  // Sealed only, on the reserved channel: the air half's session down, a request for it up.
  if (opener_ && channel == kHelloChannel) {
    if (direction_ == seal::Direction::AirToGround && f.size() == 1 + seal::kSessionSize) {
      seal::Session s;
      std::memcpy(s.data(), f.data() + 1, s.size());
      peer_session_ = s;
      ++counters_.hellos;
      return true;
    }
    if (direction_ == seal::Direction::GroundToAir && f.size() == 1) {
      hello_wanted_ = true;
      ++counters_.hellos;
      return true;
    }
  }
  return refuse(counters_.malformed, "a hello that is not a sealed session announcement (down) or request (up)");
}

std::optional<Delivered> DoorReceiver::admit(std::string channel, std::vector<uint8_t> payload, double now_s) {
  // The operator's signature before the rates: a forged command spends none of the operator's budget.
  if (opener_ && operator_channels_(channel)) {
    if (!verifier_) {
      ++counters_.commands_refused[static_cast<size_t>(seal::CommandRefusal::Unsigned)];
      why_ = channel + ": an operator's command, and this half has no operator public key to check it";
      return std::nullopt;
    }
    std::span<const uint8_t> body;
    std::string why;
    const seal::CommandRefusal r = verifier_->verify(channel, payload, body, why);
    if (r != seal::CommandRefusal::None) {
      ++counters_.commands_refused[static_cast<size_t>(r)];
      if (r == seal::CommandRefusal::OtherSession) hello_wanted_ = true;  // the ground half missed a restart
      why_ = std::string(seal::to_string(r)) + ": " + why;
      return std::nullopt;
    }
    ++counters_.commands_verified;
    payload = std::vector<uint8_t>(body.begin(), body.end());
  }
  if (!rates_.admit(channel, payload.size(), now_s)) {
    refuse(counters_.rate_limited, channel + " over its rate limit");
    return std::nullopt;
  }
  ++counters_.delivered;
  counters_.bytes_delivered += payload.size();
  return Delivered{std::move(channel), std::move(payload)};
}

void DoorReceiver::drop(std::map<uint64_t, Pending>::iterator it) {
  pending_bytes_ -= it->second.total;
  pending_.erase(it);
  ++counters_.reassembly_dropped;
}

void DoorReceiver::expire(double now_s) {
  for (auto it = pending_.begin(); it != pending_.end();) {
    auto next = std::next(it);
    if (now_s - it->second.first_s > limits_.timeout_s) drop(it);
    it = next;
  }
}

}  // namespace aerie::link
