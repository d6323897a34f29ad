#include "common/seal/seal.hpp"

#include <sodium.h>

#include <cmath>
#include <cstring>
#include <limits>
#include <stdexcept>

#include "common/seal/testing.hpp"

namespace aerie::seal {

static_assert(crypto_aead_xchacha20poly1305_ietf_ABYTES == kTagSize);
static_assert(crypto_aead_xchacha20poly1305_ietf_NPUBBYTES == kSaltSize + 8);
static_assert(crypto_aead_xchacha20poly1305_ietf_KEYBYTES == SecretKey::kSize);
static_assert(crypto_kdf_BYTES_MAX >= SecretKey::kSize && crypto_kdf_BYTES_MIN <= SecretKey::kSize);
static_assert(kMaxPayload + kMaxChannel + kOverhead == kMaxDatagram);

namespace {

constexpr char kKdfContext[crypto_kdf_CONTEXTBYTES + 1] = "aerielnk";
constexpr uint8_t kDirectionBit = 0x01;

void put_u32(uint8_t* p, uint32_t v) {
  for (int i = 0; i < 4; ++i) p[i] = static_cast<uint8_t>(v >> (8 * i));
}
void put_u64(uint8_t* p, uint64_t v) {
  for (int i = 0; i < 8; ++i) p[i] = static_cast<uint8_t>(v >> (8 * i));
}
uint32_t get_u32(const uint8_t* p) {
  uint32_t v = 0;
  for (int i = 3; i >= 0; --i) v = (v << 8) | p[i];
  return v;
}
uint64_t get_u64(const uint8_t* p) {
  uint64_t v = 0;
  for (int i = 7; i >= 0; --i) v = (v << 8) | p[i];
  return v;
}

void write_header(uint8_t* h, Direction direction, uint32_t epoch, uint32_t sender, uint64_t counter,
                  const uint8_t* salt) {
  h[0] = kMagic;
  h[1] = kVersion;
  h[2] = direction == Direction::GroundToAir ? kDirectionBit : 0;
  h[3] = 0;
  put_u32(h + 4, epoch);
  put_u32(h + 8, sender);
  put_u64(h + 12, counter);
  std::memcpy(h + 20, salt, kSaltSize);
}

// nonce = salt (header bytes 20..35) || counter (header bytes 12..19)
void nonce_of(const uint8_t* header, uint8_t* nonce) {
  std::memcpy(nonce, header + 20, kSaltSize);
  std::memcpy(nonce + kSaltSize, header + 12, 8);
}

// Encrypts out[kHeaderSize, kHeaderSize + plain_size) in place and appends the tag; the header
// must be written already.
void encrypt_in_place(const SecretKey& subkey, std::vector<uint8_t>& out, size_t plain_size) {
  uint8_t nonce[crypto_aead_xchacha20poly1305_ietf_NPUBBYTES];
  nonce_of(out.data(), nonce);
  unsigned long long clen = 0;
  crypto_aead_xchacha20poly1305_ietf_encrypt(out.data() + kHeaderSize, &clen, out.data() + kHeaderSize, plain_size,
                                             out.data(), kHeaderSize, nullptr, nonce, subkey.data());
}

}  // namespace

const char* to_string(Direction d) { return d == Direction::AirToGround ? "air->ground" : "ground->air"; }

bool valid_channel(std::string_view channel) {
  if (channel.empty() || channel.size() > kMaxChannel) return false;
  for (const char c : channel)
    if (c < 0x21 || c > 0x7e) return false;
  return true;
}

SecretKey derive_subkey(const SecretKey& mission_key, uint32_t epoch, Direction direction) {
  init_sodium();
  SecretKey subkey;
  const uint64_t id = (uint64_t{epoch} << 1) | static_cast<uint64_t>(direction);
  crypto_kdf_derive_from_key(subkey.data(), subkey.size(), id, kKdfContext, mission_key.data());
  return subkey;
}

// --- Sealer ---------------------------------------------------------------------------------------

void RekeyPolicy::validate() const {
  if (!(seconds > 0) || !std::isfinite(seconds))
    throw std::invalid_argument("rekey policy: seconds must be positive and finite, got " + std::to_string(seconds));
  if (messages < 1 || messages >= ReplayWindow::kRejectAfter)
    throw std::invalid_argument("rekey policy: messages must be in [1, 2^64 - 8194), got " +
                                std::to_string(messages));
}

Sealer::Sealer(const SecretKey& mission_key, Direction direction, uint32_t sender, uint32_t epoch, double now_s,
               RekeyPolicy policy)
    : mission_(mission_key.clone()), direction_(direction), sender_(sender), policy_(policy) {
  policy_.validate();
  if (!std::isfinite(now_s)) throw std::invalid_argument("Sealer: now_s must be finite");
  start_epoch(epoch, now_s);
}

void Sealer::start_epoch(uint32_t epoch, double now_s) {
  init_sodium();
  epoch_ = epoch;
  epoch_start_s_ = now_s;
  counter_ = 1;
  subkey_ = derive_subkey(mission_, epoch_, direction_);
  randombytes_buf(salt_.data(), salt_.size());
}

void Sealer::rekey(double now_s) {
  if (epoch_ == std::numeric_limits<uint32_t>::max())
    throw std::runtime_error("Sealer: the last key epoch (2^32 - 1) is used up; generate a new mission key");
  start_epoch(epoch_ + 1, now_s);
}

std::vector<uint8_t> Sealer::seal(std::string_view channel, std::span<const uint8_t> payload, double now_s) {
  std::vector<uint8_t> out;
  seal_into(channel, payload, now_s, out);
  return out;
}

void Sealer::seal_into(std::string_view channel, std::span<const uint8_t> payload, double now_s,
                       std::vector<uint8_t>& out) {
  if (!valid_channel(channel))
    throw std::invalid_argument("seal: channel name \"" + std::string(channel.substr(0, kMaxChannel)) +
                                "\" must be 1.." + std::to_string(kMaxChannel) +
                                " printable ASCII characters without spaces (" + std::to_string(channel.size()) +
                                " bytes)");
  if (payload.size() > kMaxPayload)
    throw std::invalid_argument("seal: payload of " + std::string(channel) + " holds " +
                                std::to_string(payload.size()) + " bytes, more than the " +
                                std::to_string(kMaxPayload) + " a datagram carries");
  if (!std::isfinite(now_s)) throw std::invalid_argument("seal: now_s must be finite");
  if (now_s - epoch_start_s_ >= policy_.seconds || counter_ > policy_.messages) rekey(now_s);

  const size_t plain_size = 1 + channel.size() + payload.size();
  out.resize(kHeaderSize + plain_size + kTagSize);
  write_header(out.data(), direction_, epoch_, sender_, counter_, salt_.data());
  uint8_t* p = out.data() + kHeaderSize;
  p[0] = static_cast<uint8_t>(channel.size());
  std::memcpy(p + 1, channel.data(), channel.size());
  if (!payload.empty()) std::memcpy(p + 1 + channel.size(), payload.data(), payload.size());
  encrypt_in_place(subkey_, out, plain_size);
  ++counter_;
  ++sealed_;
}

namespace for_tests {

std::vector<uint8_t> seal_plaintext(const SecretKey& mission_key, const RawHeader& header,
                                    std::span<const uint8_t> inner_plaintext) {
  const SecretKey subkey = derive_subkey(mission_key, header.epoch, header.direction);
  std::vector<uint8_t> out(kHeaderSize + inner_plaintext.size() + kTagSize);
  write_header(out.data(), header.direction, header.epoch, header.sender, header.counter, header.salt.data());
  if (!inner_plaintext.empty())
    std::memcpy(out.data() + kHeaderSize, inner_plaintext.data(), inner_plaintext.size());
  encrypt_in_place(subkey, out, inner_plaintext.size());
  return out;
}

}  // namespace for_tests

// --- Opener ---------------------------------------------------------------------------------------

const char* to_string(Refusal r) {
  switch (r) {
    case Refusal::None: return "opened";
    case Refusal::TooShort: return "too short";
    case Refusal::Oversize: return "oversize";
    case Refusal::BadVersion: return "bad version";
    case Refusal::WrongDirection: return "wrong direction";
    case Refusal::UnknownEpoch: return "unknown epoch";
    case Refusal::ExpiredEpoch: return "expired epoch";
    case Refusal::TooManySenders: return "too many senders";
    case Refusal::Replayed: return "replayed";
    case Refusal::TooOld: return "too old";
    case Refusal::CounterExhausted: return "counter exhausted";
    case Refusal::AuthFailed: return "authentication failed";
    case Refusal::ChannelMalformed: return "channel malformed";
    case Refusal::kCount: break;
  }
  return "unknown refusal";
}

uint64_t OpenerCounters::refused_total() const {
  uint64_t n = 0;
  for (const uint64_t c : refused) n += c;
  return n;
}

void OpenerConfig::validate() const {
  if (!(overlap_s >= 0) || !std::isfinite(overlap_s))
    throw std::invalid_argument("opener config: overlap_s must be >= 0 and finite, got " + std::to_string(overlap_s));
  if (max_epochs_ahead < 1)
    throw std::invalid_argument("opener config: max_epochs_ahead must be >= 1 (a sender's next epoch), got 0");
  if (max_senders < 1 || max_senders > 4096)
    throw std::invalid_argument("opener config: max_senders must be in [1, 4096], got " + std::to_string(max_senders));
}

Opener::Opener(const SecretKey& mission_key, OpenerConfig config) : mission_(mission_key.clone()), config_(config) {
  config_.validate();
  init_sodium();
  senders_.reserve(config_.max_senders);
}

int64_t Opener::current_epoch(uint32_t sender) const {
  for (const auto& s : senders_)
    if (s.sender == sender) return s.epoch;
  return -1;
}

const SecretKey& Opener::subkey(uint32_t epoch) {
  for (auto& k : keys_)
    if (k.valid && k.epoch == epoch) return k.key;
  CachedKey& slot = keys_[next_key_slot_];
  next_key_slot_ = (next_key_slot_ + 1) % keys_.size();
  slot.key = derive_subkey(mission_, epoch, config_.direction);
  slot.epoch = epoch;
  slot.valid = true;
  return slot.key;
}

bool Opener::refuse(Opened& out, Refusal r, std::string why) {
  out.refusal = r;
  out.why = std::move(why);
  out.channel.clear();
  out.payload.clear();
  ++counters_.refused[static_cast<size_t>(r)];
  return false;
}

Opened Opener::open(std::span<const uint8_t> datagram, double now_s) {
  Opened out;
  (void)open_into(datagram, now_s, out);
  return out;
}

bool Opener::open_into(std::span<const uint8_t> d, double now_s, Opened& out) {
  out.refusal = Refusal::None;
  out.why.clear();
  out.sender = out.epoch = 0;
  out.counter = 0;
  if (d.size() < kMinDatagram)
    return refuse(out, Refusal::TooShort,
                  std::to_string(d.size()) + " bytes, a sealed datagram has at least " + std::to_string(kMinDatagram));
  if (d.size() > kMaxDatagram)
    return refuse(out, Refusal::Oversize,
                  std::to_string(d.size()) + " bytes, a sealed datagram has at most " + std::to_string(kMaxDatagram));
  const uint8_t* h = d.data();
  if (h[0] != kMagic || h[1] != kVersion || (h[2] & ~kDirectionBit) != 0 || h[3] != 0)
    return refuse(out, Refusal::BadVersion, "not a version 1 sealed datagram (magic/version/flags bytes)");
  const Direction direction = (h[2] & kDirectionBit) ? Direction::GroundToAir : Direction::AirToGround;
  out.epoch = get_u32(h + 4);
  out.sender = get_u32(h + 8);
  out.counter = get_u64(h + 12);
  if (direction != config_.direction)
    return refuse(out, Refusal::WrongDirection,
                  std::string(to_string(direction)) + " datagram, this side opens " + to_string(config_.direction));

  // Which stream: the sender's current epoch, its previous one (during the overlap), or a new one.
  SenderState* state = nullptr;
  for (auto& s : senders_)
    if (s.sender == out.sender) state = &s;
  const uint64_t e = out.epoch;
  const uint64_t base = state ? state->epoch : config_.min_epoch;
  ReplayWindow* window = nullptr;  // null: an epoch ahead of the current one (a fresh window)
  if (state == nullptr && senders_.size() >= config_.max_senders)
    return refuse(out, Refusal::TooManySenders,
                  "sender " + std::to_string(out.sender) + " is new and " + std::to_string(senders_.size()) +
                      " senders are known already");
  if (e > base + config_.max_epochs_ahead)
    return refuse(out, Refusal::UnknownEpoch,
                  "epoch " + std::to_string(e) + " is more than " + std::to_string(config_.max_epochs_ahead) +
                      " ahead of " + std::to_string(base));
  if (state == nullptr) {
    if (e < config_.min_epoch)
      return refuse(out, Refusal::ExpiredEpoch,
                    "epoch " + std::to_string(e) + " is before the first accepted " + std::to_string(config_.min_epoch));
  } else if (e == state->epoch) {
    window = &state->current;
  } else if (e + 1 == state->epoch) {
    if (!state->has_previous || !(now_s - state->since_s <= config_.overlap_s))  // NaN time: expired
      return refuse(out, Refusal::ExpiredEpoch,
                    "epoch " + std::to_string(e) + " of sender " + std::to_string(out.sender) +
                        " ended (its overlap of " + std::to_string(config_.overlap_s) + " s is over)");
    window = &state->previous;
  } else if (e < state->epoch) {
    return refuse(out, Refusal::ExpiredEpoch,
                  "epoch " + std::to_string(e) + " of sender " + std::to_string(out.sender) + " is older than " +
                      std::to_string(state->epoch - 1));
  }
  if (window != nullptr) {
    switch (window->check(out.counter)) {
      case ReplayWindow::Verdict::Fresh: break;
      case ReplayWindow::Verdict::Replayed:
        return refuse(out, Refusal::Replayed, "counter " + std::to_string(out.counter) + " of sender " +
                                                  std::to_string(out.sender) + " epoch " + std::to_string(e) +
                                                  " was opened already");
      case ReplayWindow::Verdict::TooOld:
        return refuse(out, Refusal::TooOld, "counter " + std::to_string(out.counter) + " is left of the window (top " +
                                                std::to_string(window->top() - 1) + ")");
      case ReplayWindow::Verdict::Exhausted:
        return refuse(out, Refusal::CounterExhausted, "counter " + std::to_string(out.counter) + " past the limit");
    }
  } else if (out.counter >= ReplayWindow::kRejectAfter) {
    return refuse(out, Refusal::CounterExhausted, "counter " + std::to_string(out.counter) + " past the limit");
  }

  // The tag (constant-time check inside libsodium); the header is the associated data.
  uint8_t nonce[crypto_aead_xchacha20poly1305_ietf_NPUBBYTES];
  nonce_of(h, nonce);
  const size_t clen = d.size() - kHeaderSize;
  plain_.resize(clen - kTagSize);
  unsigned long long mlen = 0;
  if (crypto_aead_xchacha20poly1305_ietf_decrypt(plain_.data(), &mlen, nullptr, d.data() + kHeaderSize, clen, h,
                                                 kHeaderSize, nonce, subkey(out.epoch).data()) != 0)
    return refuse(out, Refusal::AuthFailed,
                  "sender " + std::to_string(out.sender) + " epoch " + std::to_string(e) +
                      ": the tag does not verify (another key, or a tampered datagram)");

  // Authentic: commit the counter (and the epoch switch) before looking inside, so that an
  // authentic datagram is never processed twice, whatever it holds.
  if (state == nullptr) {
    senders_.emplace_back();
    state = &senders_.back();
    state->sender = out.sender;
    state->epoch = out.epoch;
    state->since_s = now_s;
    state->has_previous = false;
    window = &state->current;
  } else if (window == nullptr) {
    if (e == uint64_t{state->epoch} + 1) {
      state->previous = state->current;
      state->has_previous = true;
    } else {
      state->previous = ReplayWindow{};  // skipped epochs: the one before the new is still fresh
      state->has_previous = true;
    }
    state->current = ReplayWindow{};
    state->epoch = out.epoch;
    state->since_s = now_s;
    window = &state->current;
  }
  window->commit(out.counter);

  const size_t m = static_cast<size_t>(mlen);
  const size_t n = plain_[0];
  if (n == 0 || n > kMaxChannel || 1 + n > m)
    return refuse(out, Refusal::ChannelMalformed,
                  "channel name length " + std::to_string(n) + " (1.." + std::to_string(kMaxChannel) + ", inside " +
                      std::to_string(m - 1) + " bytes)");
  const std::string_view channel(reinterpret_cast<const char*>(plain_.data() + 1), n);
  if (!valid_channel(channel))
    return refuse(out, Refusal::ChannelMalformed, "channel name holds a byte that is not printable ASCII");
  if (m - 1 - n > kMaxPayload)
    return refuse(out, Refusal::Oversize, "payload of " + std::to_string(m - 1 - n) + " bytes, at most " +
                                              std::to_string(kMaxPayload));
  out.channel.assign(channel);
  out.payload.assign(plain_.begin() + static_cast<std::ptrdiff_t>(1 + n), plain_.begin() + static_cast<std::ptrdiff_t>(m));
  ++counters_.opened;
  return true;
}

}  // namespace aerie::seal
