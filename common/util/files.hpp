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

}  // namespace aerie::util
