#pragma once
// Reading a file that comes from a user (a config, a calibration, a controller): only a
// regular file (or a link to one) is read, since a FIFO or a device given by mistake
// would block the node at start-up or never end; errors name the file.
#include <string>

namespace aerie::util {

// Throws std::runtime_error "PATH: <what> not found" / "PATH: <what> must be a regular file" /
// "PATH: cannot open".
void require_regular_file(const std::string& path, const std::string& what = "file");
// The whole file, after require_regular_file.
std::string read_regular_file(const std::string& path, const std::string& what = "file");
// Writes `content` next to `path` and renames it over `path`, so that a reader (or a node
// killed mid-write) never sees a truncated file. Throws std::runtime_error naming the file.
void write_file_atomically(const std::string& path, const std::string& content);

}  // namespace aerie::util
