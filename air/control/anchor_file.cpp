#include "air/control/anchor_file.hpp"

#include <cmath>
#include <sstream>

#include "common/util/files.hpp"

namespace aerie::control {

namespace {
constexpr const char* kHeader = "aerie-control anchor 1";
}

void write_anchor(const std::string& path, const std::string& channel, const Anchor& a) {
  std::ostringstream out;
  out.precision(17);
  out << kHeader << "\nchannel " << channel << "\nutime " << a.utime << "\nstart " << a.start.x() << ' ' << a.start.y()
      << ' ' << a.start.z() << "\nreference_deg " << a.reference_deg << '\n';
  util::write_file_atomically(path, out.str());
}

std::optional<Anchor> read_anchor(const std::string& path, const std::string& channel, std::string& why) {
  std::string text;
  try {
    text = util::read_regular_file(path, "anchor file");
  } catch (const std::exception& e) {
    why = e.what();
    return std::nullopt;
  }
  std::istringstream in(text);
  std::string header, key_channel, file_channel, key_utime, key_start, key_reference, rest;
  Anchor a;
  std::getline(in, header);
  in >> key_channel >> file_channel >> key_utime >> a.utime >> key_start >> a.start.x() >> a.start.y() >> a.start.z() >>
      key_reference >> a.reference_deg;
  if (header != kHeader || !in || key_channel != "channel" || key_utime != "utime" || key_start != "start" ||
      key_reference != "reference_deg" || (in >> rest) || !a.start.allFinite() || !std::isfinite(a.reference_deg)) {
    why = path + ": not an anchor file of aerie-control (" + kHeader + ")";
    return std::nullopt;
  }
  if (file_channel != channel) {
    why = path + ": the anchor is in " + file_channel + "'s frame, not " + channel + "'s";
    return std::nullopt;
  }
  return a;
}

}  // namespace aerie::control
