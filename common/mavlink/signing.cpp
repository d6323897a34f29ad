#include "common/mavlink/signing.hpp"

#include <sodium.h>

#include <algorithm>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <sstream>
#include <stdexcept>

#include "common/mavlink/frame.hpp"
#include "common/util/key_file.hpp"

namespace aerie::mavlink {

namespace {

void ensure_sodium() {
  static const bool ok = sodium_init() >= 0;
  if (!ok) throw std::runtime_error("MAVLink signing: libsodium failed to initialise");
}

uint64_t read_timestamp(std::span<const uint8_t> bytes) {
  uint64_t t = 0;
  for (size_t i = 0; i < 6; ++i) t |= static_cast<uint64_t>(bytes[i]) << (8 * i);
  return t;
}

}  // namespace

uint64_t to_signing_time(std::chrono::system_clock::time_point t) {
  const auto us = std::chrono::duration_cast<std::chrono::microseconds>(t.time_since_epoch()).count();
  const int64_t since = us - static_cast<int64_t>(kSigningEpochUnixSeconds) * 1'000'000;
  return since <= 0 ? 0 : static_cast<uint64_t>(since) / 10;
}

uint64_t signing_time_now() { return to_signing_time(std::chrono::system_clock::now()); }

SignatureBytes compute_signature(const Key& key, std::span<const uint8_t> frame, uint8_t link_id, uint64_t timestamp) {
  ensure_sodium();
  crypto_hash_sha256_state state;
  crypto_hash_sha256_init(&state);
  crypto_hash_sha256_update(&state, key.data(), key.size());
  crypto_hash_sha256_update(&state, frame.data(), frame.size());
  std::array<uint8_t, 7> tail{link_id};
  for (size_t i = 0; i < 6; ++i) tail[1 + i] = static_cast<uint8_t>(timestamp >> (8 * i));
  crypto_hash_sha256_update(&state, tail.data(), tail.size());
  std::array<uint8_t, crypto_hash_sha256_BYTES> digest{};
  crypto_hash_sha256_final(&state, digest.data());
  SignatureBytes out{};
  std::copy_n(digest.begin(), out.size(), out.begin());
  sodium_memzero(&state, sizeof state);
  return out;
}

// --- Signer ---------------------------------------------------------------------------------

Signer::Signer(const Key& key, uint8_t link_id, uint64_t persisted_timestamp, SigningClock clock)
    : key_(key), link_id_(link_id), clock_(std::move(clock)) {
  if (!clock_) throw std::invalid_argument("MAVLink Signer: no clock given");
  const uint64_t resume = persisted_timestamp ? persisted_timestamp + kOneMinuteTicks : 0;
  // next_timestamp() returns max(now, last_ + 1): start just below the resume point.
  last_ = resume ? resume - 1 : 0;
}

uint64_t Signer::next_timestamp() {
  last_ = std::max(clock_(), last_ + 1);
  if (last_ > kMaxTimestamp) throw std::runtime_error("MAVLink Signer: signing timestamp exceeds 48 bits");
  return last_;
}

void Signer::append_signature(std::vector<uint8_t>& frame) {
  if (frame.size() < kHeaderLengthV2 + kChecksumLength || frame[0] != kMagicV2 ||
      !(frame[2] & kIncompatSigned) || frame.size() != kHeaderLengthV2 + frame[1] + kChecksumLength)
    throw std::invalid_argument(
        "MAVLink Signer: expected a MAVLink 2 frame with the signed flag set, up to its CRC");
  const uint64_t ts = next_timestamp();
  const SignatureBytes sig = compute_signature(key_, frame, link_id_, ts);
  frame.push_back(link_id_);
  for (size_t i = 0; i < 6; ++i) frame.push_back(static_cast<uint8_t>(ts >> (8 * i)));
  frame.insert(frame.end(), sig.begin(), sig.end());
}

bool Signer::should_persist(uint64_t now) const {
  return !persisted_at_ || now >= *persisted_at_ + kOneMinuteTicks || now < *persisted_at_;
}

uint64_t Signer::mark_persisted() { return mark_persisted(clock_()); }

uint64_t Signer::mark_persisted(uint64_t now) {
  persisted_at_ = now;
  return last_;
}

// --- Verifier -------------------------------------------------------------------------------

Verifier::Verifier(const Key& key, SigningClock clock, size_t max_streams)
    : key_(key), clock_(std::move(clock)), max_streams_(std::max<size_t>(1, max_streams)) {
  if (!clock_) throw std::invalid_argument("MAVLink Verifier: no clock given");
}

Verifier::Verdict Verifier::verify(std::span<const uint8_t> frame) {
  if (frame.size() < kHeaderLengthV2 + kChecksumLength + kSignatureLength || frame[0] != kMagicV2 ||
      !(frame[2] & kIncompatSigned))
    return Verdict::bad_signature;
  const size_t signed_part = frame.size() - kSignatureLength;
  const uint8_t link_id = frame[signed_part];
  const uint64_t ts = read_timestamp(frame.subspan(signed_part + 1, 6));
  const SignatureBytes expected = compute_signature(key_, frame.first(signed_part), link_id, ts);
  if (sodium_memcmp(expected.data(), frame.data() + signed_part + 7, expected.size()) != 0)
    return Verdict::bad_signature;

  const StreamId id{frame[5], frame[6], link_id};
  auto it = streams_.find(id);
  if (it != streams_.end()) {
    if (ts <= it->second) return Verdict::replayed;
    it->second = ts;
  } else {
    const uint64_t now = clock_();
    const bool recent = ts + kOneMinuteTicks >= now;
    if (!recent && ts <= newest_) return Verdict::stale;
    if (streams_.size() >= max_streams_) {
      // Bounded: forget the stream that has been silent longest (the oldest last timestamp).
      auto oldest = std::min_element(streams_.begin(), streams_.end(),
                                     [](const auto& a, const auto& b) { return a.second < b.second; });
      streams_.erase(oldest);
    }
    streams_.emplace(id, ts);
  }
  newest_ = std::max(newest_, ts);
  return Verdict::accepted;
}

std::string to_string(Verifier::Verdict verdict) {
  switch (verdict) {
    case Verifier::Verdict::accepted: return "accepted";
    case Verifier::Verdict::bad_signature: return "bad signature";
    case Verifier::Verdict::replayed: return "replayed timestamp";
    case Verifier::Verdict::stale: return "timestamp of a new stream more than a minute old";
  }
  return "unknown";
}

// --- keys and timestamps --------------------------------------------------------------------

Key load_key(const std::string& path) {
  const std::vector<uint8_t> bytes = util::read_key_file(path, 32, "MAVLink signing key");
  Key key{};
  std::copy_n(bytes.begin(), key.size(), key.begin());
  return key;
}

void save_key(const std::string& path, const Key& key, bool overwrite) {
  util::write_key_file(path, std::vector<uint8_t>(key.begin(), key.end()), overwrite, "MAVLink signing key");
}

Key generate_key() {
  ensure_sodium();
  Key key{};
  randombytes_buf(key.data(), key.size());
  return key;
}

std::string fingerprint(const Key& key) {
  ensure_sodium();
  std::array<uint8_t, crypto_hash_sha256_BYTES> digest{};
  crypto_hash_sha256(digest.data(), key.data(), key.size());
  static constexpr char kHex[] = "0123456789abcdef";
  std::string out;
  for (size_t i = 0; i < 8; ++i) {
    out += kHex[digest[i] >> 4];
    out += kHex[digest[i] & 0xF];
  }
  return out;
}

void save_timestamp(const std::string& path, uint64_t timestamp) {
  const std::string tmp = path + ".tmp";
  {
    std::ofstream out(tmp, std::ios::trunc);
    out << timestamp << "\n";
    out.flush();
    if (!out) throw std::runtime_error(tmp + ": cannot write the MAVLink signing timestamp");
  }
  std::error_code ec;
  std::filesystem::rename(tmp, path, ec);
  if (ec) throw std::runtime_error(path + ": cannot replace the MAVLink signing timestamp file: " + ec.message());
}

uint64_t load_timestamp(const std::string& path) {
  std::ifstream in(path);
  if (!in) {
    if (!std::filesystem::exists(path)) return 0;
    throw std::runtime_error(path + ": cannot read the MAVLink signing timestamp file");
  }
  std::string text((std::istreambuf_iterator<char>(in)), std::istreambuf_iterator<char>());
  while (!text.empty() && (text.back() == '\n' || text.back() == '\r' || text.back() == ' ')) text.pop_back();
  uint64_t value = 0;
  if (text.empty() || text.size() > 15 || !std::all_of(text.begin(), text.end(), [](char c) { return c >= '0' && c <= '9'; }))
    throw std::runtime_error(path + ": expected a MAVLink signing timestamp (a decimal number of 10 us ticks)");
  value = std::stoull(text);
  if (value > kMaxTimestamp) throw std::runtime_error(path + ": signing timestamp exceeds 48 bits");
  return value;
}

SetupSigning make_setup_signing(uint8_t target_system, uint8_t target_component, const Key& key,
                                uint64_t initial_timestamp) {
  SetupSigning msg;
  msg.target_system = target_system;
  msg.target_component = target_component;
  msg.secret_key = key;
  msg.initial_timestamp = initial_timestamp;
  return msg;
}

}  // namespace aerie::mavlink
