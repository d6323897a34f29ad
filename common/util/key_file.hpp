#pragma once
// Key files (the link's mission key, MAVLink signing keys): read only from a regular file that
// no one but its owner can read or write (mode 0600 or stricter, as ssh insists on for its
// private keys), written with mode 0600 from the first byte. Errors name the file and what is
// wrong with it, never its content.
#include <cstdint>
#include <string>
#include <vector>

namespace aerie::util {

// Throws std::runtime_error "PATH: <what> not found" / "... must be a regular file" /
// "... is readable or writable by others (mode 0644); chmod 600 PATH" /
// "... holds N bytes, expected M".
// KeyFile::Secret: mode 0600 or stricter. KeyFile::Public (an operator's public key, as ssh's
// authorized_keys): others may read it, but no one but its owner may write it ("... is writable
// by others (mode 0666); chmod 644 PATH").
enum class KeyFile { Secret, Public };
std::vector<uint8_t> read_key_file(const std::string& path, size_t expected_size,
                                      const std::string& what = "key file", KeyFile kind = KeyFile::Secret);
// Writes `bytes` to `path` (mode 0600, created next to it and renamed over it, so a reader
// never sees a partial key). Refuses to replace an existing file unless `overwrite`.
// KeyFile::Public writes mode 0644.
void write_key_file(const std::string& path, const std::vector<uint8_t>& bytes, bool overwrite = false,
                       const std::string& what = "key file", KeyFile kind = KeyFile::Secret);

}  // namespace aerie::util
