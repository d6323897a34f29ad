#include "common/seal/keys.hpp"

#include <sodium.h>

#include <cstdio>
#include <stdexcept>
#include <vector>

#include "common/util/key_file.hpp"

namespace aerie::seal {

void init_sodium() {
  // sodium_init() is itself thread-safe; the static makes it one call per process.
  static const int rc = sodium_init();
  if (rc < 0) throw std::runtime_error("libsodium: sodium_init() failed");
}

SecretKey::SecretKey() = default;

SecretKey::~SecretKey() { sodium_memzero(bytes_.data(), bytes_.size()); }

SecretKey::SecretKey(SecretKey&& other) noexcept : bytes_(other.bytes_) {
  sodium_memzero(other.bytes_.data(), other.bytes_.size());
}

SecretKey& SecretKey::operator=(SecretKey&& other) noexcept {
  if (this != &other) {
    bytes_ = other.bytes_;
    sodium_memzero(other.bytes_.data(), other.bytes_.size());
  }
  return *this;
}

SecretKey SecretKey::generate() {
  init_sodium();
  static_assert(crypto_kdf_KEYBYTES == kSize);
  SecretKey key;
  crypto_kdf_keygen(key.bytes_.data());
  return key;
}

SecretKey SecretKey::from_bytes(std::span<const uint8_t> bytes) {
  if (bytes.size() != kSize)
    throw std::invalid_argument("mission key: " + std::to_string(bytes.size()) + " bytes, expected " +
                                std::to_string(kSize));
  SecretKey key;
  std::copy(bytes.begin(), bytes.end(), key.bytes_.begin());
  return key;
}

SecretKey SecretKey::clone() const {
  SecretKey key;
  key.bytes_ = bytes_;
  return key;
}

bool SecretKey::equals(const SecretKey& other) const {
  return sodium_memcmp(bytes_.data(), other.bytes_.data(), kSize) == 0;
}

SecretKey load_key(const std::string& path) {
  init_sodium();
  std::vector<uint8_t> bytes = util::read_key_file(path, SecretKey::kSize, "mission key");
  SecretKey key = SecretKey::from_bytes(bytes);
  sodium_memzero(bytes.data(), bytes.size());
  return key;
}

void save_key(const std::string& path, const SecretKey& key, bool overwrite) {
  std::vector<uint8_t> bytes(key.data(), key.data() + key.size());
  try {
    util::write_key_file(path, bytes, overwrite, "mission key");
  } catch (...) {
    sodium_memzero(bytes.data(), bytes.size());
    throw;
  }
  sodium_memzero(bytes.data(), bytes.size());
}

std::string fingerprint(const SecretKey& key) { return fingerprint(std::span<const uint8_t>(key.data(), key.size())); }

std::string fingerprint(std::span<const uint8_t> bytes) {
  init_sodium();
  uint8_t personal[crypto_generichash_blake2b_PERSONALBYTES] = {'a', 'e', 'r', 'i', 'e', '-', 'f', 'p'};
  uint8_t hash[crypto_generichash_blake2b_BYTES_MIN];  // 16 bytes, the shortest BLAKE2b libsodium gives
  crypto_generichash_blake2b_salt_personal(hash, sizeof hash, bytes.data(), bytes.size(), nullptr, 0, nullptr,
                                           personal);
  std::string out;
  char hex[3];
  for (int i = 0; i < 8; ++i) {
    if (i > 0 && i % 2 == 0) out += ':';
    std::snprintf(hex, sizeof hex, "%02x", hash[i]);
    out += hex;
  }
  return out;
}

}  // namespace aerie::seal
