#pragma once
// `aerie-log cut`: the events of a time range (seconds from the log's first event)
// into a new log, renumbered from 0 as lcm-logger numbers them.
#include <cstdint>
#include <limits>
#include <string>
#include <vector>

#include "common/logio/event_log.hpp"

namespace aerie::logtools {

struct CutResult {
  int64_t events_read = 0;
  int64_t events_written = 0;
  std::vector<logio::Damage> damage;
};

// Keeps events with from_s <= (utime - first utime) / 1e6 < to_s, except those whose channel
// matches `exclude` as a whole (ECMAScript regex; "" = none: e.g. a replay leaves out what the
// nodes it feeds will publish again). Throws std::invalid_argument for a bad regex too. Throws
// std::invalid_argument for an empty range or an existing output (unless `force`: recorded
// data is never overwritten by mistake) and std::runtime_error naming the file on I/O errors.
CutResult cut(const std::string& in_path, double from_s, double to_s, const std::string& out_path,
              bool resync = false, bool force = false, const std::string& exclude = "");

}  // namespace aerie::logtools
