#include "common/seal/operator.hpp"

#include <sodium.h>

#include <cstring>
#include <stdexcept>

#include "common/seal/seal.hpp"
#include "common/util/key_file.hpp"

namespace aerie::seal {
namespace {

constexpr char kDomain[] = "aerie-cmd1";  // the signature's domain: never valid for anything else
constexpr size_t kDomainSize = sizeof(kDomain) - 1;
static_assert(crypto_sign_BYTES == kSignatureSize && crypto_sign_PUBLICKEYBYTES == OperatorPublicKey::kSize &&
              crypto_sign_SEEDBYTES == SecretKey::kSize && crypto_sign_SECRETKEYBYTES == 64);

void put_u64(uint8_t* p, uint64_t v) {
  for (int i = 0; i < 8; ++i) p[i] = static_cast<uint8_t>(v >> (8 * i));
}
uint64_t get_u64(const uint8_t* p) {
  uint64_t v = 0;
  for (int i = 7; i >= 0; --i) v = (v << 8) | p[i];
  return v;
}

// What the signature covers: domain || session || counter || channel length || channel || payload.
std::vector<uint8_t> signed_message(const uint8_t* session, uint64_t counter, std::string_view channel,
                                    std::span<const uint8_t> payload) {
  std::vector<uint8_t> m(kDomainSize + kSessionSize + 8 + 1 + channel.size() + payload.size());
  uint8_t* p = m.data();
  std::memcpy(p, kDomain, kDomainSize);
  p += kDomainSize;
  std::memcpy(p, session, kSessionSize);
  p += kSessionSize;
  put_u64(p, counter);
  p += 8;
  *p++ = static_cast<uint8_t>(channel.size());
  std::memcpy(p, channel.data(), channel.size());
  p += channel.size();
  if (!payload.empty()) std::memcpy(p, payload.data(), payload.size());
  return m;
}

}  // namespace

Session new_session() {
  init_sodium();
  Session s;
  randombytes_buf(s.data(), s.size());
  return s;
}

// --- keys --------------------------------------------------------------------------------------

OperatorPublicKey OperatorPublicKey::load(const std::string& path) {
  const auto bytes = util::read_key_file(path, kSize, "operator public key", util::KeyFile::Public);
  OperatorPublicKey k;
  std::copy(bytes.begin(), bytes.end(), k.bytes.begin());
  return k;
}

void OperatorPublicKey::save(const std::string& path, bool overwrite) const {
  util::write_key_file(path, std::vector<uint8_t>(bytes.begin(), bytes.end()), overwrite, "operator public key",
                       util::KeyFile::Public);
}

std::string OperatorPublicKey::fingerprint() const { return seal::fingerprint(std::span<const uint8_t>(bytes)); }

OperatorKey::OperatorKey(SecretKey seed) : seed_(std::move(seed)) {
  init_sodium();
  crypto_sign_seed_keypair(public_.bytes.data(), secret_.data(), seed_.data());
}

OperatorKey::~OperatorKey() { sodium_memzero(secret_.data(), secret_.size()); }

OperatorKey::OperatorKey(OperatorKey&& other) noexcept
    : seed_(std::move(other.seed_)), secret_(other.secret_), public_(other.public_) {
  sodium_memzero(other.secret_.data(), other.secret_.size());
}

OperatorKey OperatorKey::clone() const { return OperatorKey(seed_.clone()); }

OperatorKey OperatorKey::generate() { return OperatorKey(SecretKey::generate()); }

OperatorKey OperatorKey::from_seed(SecretKey seed) { return OperatorKey(std::move(seed)); }

OperatorKey OperatorKey::load(const std::string& path) {
  std::vector<uint8_t> bytes = util::read_key_file(path, SecretKey::kSize, "operator key");
  SecretKey seed = SecretKey::from_bytes(bytes);
  sodium_memzero(bytes.data(), bytes.size());
  return from_seed(std::move(seed));
}

void OperatorKey::save(const std::string& path, bool overwrite) const {
  std::vector<uint8_t> bytes(seed_.data(), seed_.data() + seed_.size());
  try {
    util::write_key_file(path, bytes, overwrite, "operator key");
  } catch (...) {
    sodium_memzero(bytes.data(), bytes.size());
    throw;
  }
  sodium_memzero(bytes.data(), bytes.size());
}

std::array<uint8_t, kSignatureSize> OperatorKey::sign(std::span<const uint8_t> message) const {
  std::array<uint8_t, kSignatureSize> sig{};
  crypto_sign_detached(sig.data(), nullptr, message.data(), message.size(), secret_.data());
  return sig;
}

// --- signing -----------------------------------------------------------------------------------

CommandSigner::CommandSigner(OperatorKey key) : key_(std::move(key)) {}

std::vector<uint8_t> CommandSigner::sign(const Session& session, std::string_view channel,
                                         std::span<const uint8_t> payload) {
  if (session != session_) {
    session_ = session;
    counter_ = 0;
  }
  return sign_with_counter(session, ++counter_, channel, payload);
}

std::vector<uint8_t> CommandSigner::sign_with_counter(const Session& session, uint64_t counter,
                                                      std::string_view channel,
                                                      std::span<const uint8_t> payload) const {
  if (!valid_channel(channel))
    throw std::invalid_argument("operator signature: channel '" + std::string(channel) + "' is not a valid name");
  const auto sig = key_.sign(signed_message(session.data(), counter, channel, payload));
  std::vector<uint8_t> env(kCommandOverhead + payload.size());
  std::memcpy(env.data(), session.data(), kSessionSize);
  put_u64(env.data() + kSessionSize, counter);
  std::memcpy(env.data() + kSessionSize + 8, sig.data(), sig.size());
  if (!payload.empty()) std::memcpy(env.data() + kCommandOverhead, payload.data(), payload.size());
  return env;
}

// --- verifying ---------------------------------------------------------------------------------

const char* to_string(CommandRefusal r) {
  switch (r) {
    case CommandRefusal::None: return "none";
    case CommandRefusal::Unsigned: return "unsigned";
    case CommandRefusal::OtherSession: return "other session";
    case CommandRefusal::BadSignature: return "bad signature";
    case CommandRefusal::Replayed: return "replayed command";
    case CommandRefusal::TooOld: return "command too old";
    case CommandRefusal::kCount: break;
  }
  return "unknown";
}

CommandVerifier::CommandVerifier(std::vector<OperatorPublicKey> operators, Session session)
    : operators_(std::move(operators)), windows_(operators_.size()), session_(session) {
  if (operators_.empty()) throw std::invalid_argument("operator signature: no operator public key to verify with");
  init_sodium();
}

CommandRefusal CommandVerifier::verify(std::string_view channel, std::span<const uint8_t> env,
                                       std::span<const uint8_t>& payload, std::string& why) {
  if (env.size() < kCommandOverhead) {
    why = channel.empty() ? "a command" : std::string(channel);
    why += " of " + std::to_string(env.size()) + " bytes carries no operator signature";
    return CommandRefusal::Unsigned;
  }
  if (sodium_memcmp(env.data(), session_.data(), kSessionSize) != 0) {
    why = std::string(channel) + " signed for another session of the air half (recorded earlier, or for another vehicle)";
    return CommandRefusal::OtherSession;
  }
  const uint64_t counter = get_u64(env.data() + kSessionSize);
  const uint8_t* sig = env.data() + kSessionSize + 8;
  const std::span<const uint8_t> body = env.subspan(kCommandOverhead);
  const auto message = signed_message(env.data(), counter, channel, body);
  for (size_t i = 0; i < operators_.size(); ++i) {
    if (crypto_sign_verify_detached(sig, message.data(), message.size(), operators_[i].bytes.data()) != 0) continue;
    // The window moves only for a command whose signature verified (replay_window.hpp).
    switch (windows_[i].check(counter)) {
      case ReplayWindow::Verdict::Fresh:
        windows_[i].commit(counter);
        payload = body;
        return CommandRefusal::None;
      case ReplayWindow::Verdict::Replayed:
        why = std::string(channel) + " counter " + std::to_string(counter) + " from operator " +
              operators_[i].fingerprint() + " was accepted already";
        return CommandRefusal::Replayed;
      case ReplayWindow::Verdict::TooOld:
      case ReplayWindow::Verdict::Exhausted:
        why = std::string(channel) + " counter " + std::to_string(counter) + " from operator " +
              operators_[i].fingerprint() + " is outside the replay window";
        return CommandRefusal::TooOld;
    }
  }
  why = std::string(channel) + ": no operator key of this half verifies the signature";
  return CommandRefusal::BadSignature;
}

}  // namespace aerie::seal
