#pragma once
// The mission key: 32 random bytes shared by the air and the ground half of the link, kept in a
// file of mode 0600 (common/util/key_file.hpp), never logged, printed or sent. Operators
// compare fingerprints, never keys (docs/security.md, "Key files and fingerprints").
#include <array>
#include <cstddef>
#include <cstdint>
#include <span>
#include <string>

namespace aerie::seal {

// libsodium's sodium_init(), once per process (thread-safe); throws std::runtime_error if it fails.
void init_sodium();

// 32 secret bytes, zeroed (sodium_memzero) when destroyed or moved from. Not copyable: a copy
// is made only by clone(), so that every copy of a key is written out where it happens.
class SecretKey {
 public:
  static constexpr size_t kSize = 32;

  SecretKey();  // all zero
  ~SecretKey();
  SecretKey(const SecretKey&) = delete;
  SecretKey& operator=(const SecretKey&) = delete;
  SecretKey(SecretKey&& other) noexcept;
  SecretKey& operator=(SecretKey&& other) noexcept;

  static SecretKey generate();  // crypto_kdf_keygen
  // Throws std::invalid_argument unless `bytes` holds exactly kSize bytes.
  static SecretKey from_bytes(std::span<const uint8_t> bytes);
  SecretKey clone() const;

  const uint8_t* data() const { return bytes_.data(); }
  uint8_t* data() { return bytes_.data(); }
  static constexpr size_t size() { return kSize; }
  // Constant time (sodium_memcmp).
  bool equals(const SecretKey& other) const;

 private:
  std::array<uint8_t, kSize> bytes_{};
};

// Reads a mission key file (util::read_key_file: mode 0600 or stricter, exactly 32 bytes;
// errors name the file, never the content).
SecretKey load_key(const std::string& path);
// Writes a mission key file with mode 0600; refuses to replace an existing one unless `overwrite`.
void save_key(const std::string& path, const SecretKey& key, bool overwrite = false);

// A short stable name of a key, "3fa2:91c0:5b7e:0d14": the first 8 bytes of
// BLAKE2b-128(key, personal "aerie-fp"), so that both halves' status can be compared without
// showing the key. It reveals nothing usable about the key (a preimage of BLAKE2b).
std::string fingerprint(const SecretKey& key);
// The same name of any bytes (an operator's public key, operator.hpp).
std::string fingerprint(std::span<const uint8_t> bytes);

}  // namespace aerie::seal
