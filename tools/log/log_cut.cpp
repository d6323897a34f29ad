#include "tools/log/log_cut.hpp"

#include <cmath>
#include <filesystem>
#include <optional>
#include <regex>
#include <stdexcept>

namespace aerie::logtools {

CutResult cut(const std::string& in_path, double from_s, double to_s, const std::string& out_path, bool resync,
              bool force, const std::string& exclude) {
  std::optional<std::regex> excluded;
  try {
    if (!exclude.empty()) excluded.emplace(exclude);
  } catch (const std::regex_error& e) {
    throw std::invalid_argument("cut: --exclude '" + exclude + "' is not a regular expression: " + e.what());
  }
  if (!(from_s >= 0) || !(to_s > from_s))
    throw std::invalid_argument("cut: need 0 <= --from < --to (got " + std::to_string(from_s) + ", " +
                                std::to_string(to_s) + ")");
  std::error_code ec;
  if (std::filesystem::equivalent(in_path, out_path, ec))
    throw std::invalid_argument("cut: the output " + out_path + " is the input log");
  if (!force && std::filesystem::exists(std::filesystem::symlink_status(out_path, ec)))
    throw std::invalid_argument("cut: the output " + out_path + " exists; pass --force to overwrite it");
  logio::Reader reader(in_path, {.resync = resync});
  logio::Writer writer(out_path);
  CutResult r;
  logio::Event ev;
  int64_t t0 = 0;
  // Integer microsecond bounds, so that an event exactly at a bound is placed exactly.
  const int64_t from_us = std::llround(from_s * 1e6);
  const int64_t to_us = std::isinf(to_s) ? INT64_MAX : std::llround(to_s * 1e6);
  while (reader.next(ev)) {
    if (r.events_read++ == 0) t0 = ev.utime;
    const int64_t t = ev.utime - t0;
    if (t >= from_us && t < to_us && !(excluded && std::regex_match(ev.channel, *excluded))) writer.write(ev);
  }
  writer.close();
  r.events_written = writer.events_written();
  r.damage = reader.damage();
  return r;
}

}  // namespace aerie::logtools
