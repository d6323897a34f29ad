#include "common/util/key_file.hpp"

#include <fcntl.h>
#include <sys/stat.h>
#include <unistd.h>

#include <cerrno>
#include <cstdio>
#include <cstring>
#include <stdexcept>

#include "common/util/files.hpp"

namespace aerie::util {

namespace {
std::string octal_mode(mode_t mode) {
  char buf[8];
  std::snprintf(buf, sizeof buf, "%04o", static_cast<unsigned>(mode & 07777));
  return buf;
}
}  // namespace

std::vector<uint8_t> read_key_file(const std::string& path, size_t expected_size, const std::string& what,
                                   KeyFile kind) {
  require_regular_file(path, what);
  const int fd = ::open(path.c_str(), O_RDONLY | O_CLOEXEC | O_NOFOLLOW);
  if (fd < 0) throw std::runtime_error(path + ": cannot open " + what + " (" + std::strerror(errno) + ")");
  struct stat st {};
  if (::fstat(fd, &st) != 0) {
    ::close(fd);
    throw std::runtime_error(path + ": cannot stat " + what);
  }
  if (kind == KeyFile::Secret && (st.st_mode & 077) != 0) {
    ::close(fd);
    throw std::runtime_error(path + ": " + what + " is readable or writable by others (mode " +
                             octal_mode(st.st_mode) + "); chmod 600 " + path);
  }
  if (kind == KeyFile::Public && (st.st_mode & 022) != 0) {
    ::close(fd);
    throw std::runtime_error(path + ": " + what + " is writable by others (mode " + octal_mode(st.st_mode) +
                             "); chmod 644 " + path);
  }
  if (static_cast<size_t>(st.st_size) != expected_size) {
    ::close(fd);
    throw std::runtime_error(path + ": " + what + " holds " + std::to_string(st.st_size) + " bytes, expected " +
                             std::to_string(expected_size));
  }
  std::vector<uint8_t> bytes(expected_size);
  size_t got = 0;
  while (got < expected_size) {
    const ssize_t n = ::read(fd, bytes.data() + got, expected_size - got);
    if (n <= 0) {
      if (n < 0 && errno == EINTR) continue;
      ::close(fd);
      throw std::runtime_error(path + ": cannot read " + what);
    }
    got += static_cast<size_t>(n);
  }
  ::close(fd);
  return bytes;
}

void write_key_file(const std::string& path, const std::vector<uint8_t>& bytes, bool overwrite,
                    const std::string& what, KeyFile kind) {
  if (!overwrite && ::access(path.c_str(), F_OK) == 0)
    throw std::runtime_error(path + ": " + what + " exists already (refusing to overwrite it)");
  const std::string tmp = path + ".part";
  ::unlink(tmp.c_str());
  const int fd = ::open(tmp.c_str(), O_WRONLY | O_CREAT | O_EXCL | O_CLOEXEC | O_NOFOLLOW, 0600);
  if (fd >= 0 && kind == KeyFile::Public) ::fchmod(fd, 0644);  // past the umask: a public key is read by others
  if (fd < 0) throw std::runtime_error(path + ": cannot create " + what + " (" + std::strerror(errno) + ")");
  size_t put = 0;
  while (put < bytes.size()) {
    const ssize_t n = ::write(fd, bytes.data() + put, bytes.size() - put);
    if (n <= 0) {
      if (n < 0 && errno == EINTR) continue;
      ::close(fd);
      ::unlink(tmp.c_str());
      throw std::runtime_error(path + ": cannot write " + what);
    }
    put += static_cast<size_t>(n);
  }
  const bool synced = ::fsync(fd) == 0;
  ::close(fd);
  if (!synced || ::rename(tmp.c_str(), path.c_str()) != 0) {
    ::unlink(tmp.c_str());
    throw std::runtime_error(path + ": cannot write " + what + " (" + std::strerror(errno) + ")");
  }
}

}  // namespace aerie::util
