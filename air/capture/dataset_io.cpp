#include "air/capture/dataset_io.hpp"

#include <algorithm>
#include <cctype>
#include <charconv>
#include <cmath>
#include <filesystem>
#include <fstream>
#include <limits>
#include <sstream>
#include <stdexcept>

namespace aerie::capture {
namespace fs = std::filesystem;

namespace {

[[noreturn]] void fail_line(const std::string& file, int line, const std::string& what) {
  throw std::runtime_error(file + ":" + std::to_string(line) + ": " + what);
}

std::ifstream open_text(const std::string& file) {
  std::ifstream in(file);
  if (!in) throw std::runtime_error(file + ": cannot open file");
  return in;
}

bool skip_line(const std::string& line) {
  const auto p = line.find_first_not_of(" \t\r");
  return p == std::string::npos || line[p] == '#';
}

// Numbers of a line separated by spaces, tabs or commas.
std::vector<double> numbers(const std::string& line, const std::string& file, int lineno) {
  std::string s = line;
  std::replace(s.begin(), s.end(), ',', ' ');
  std::istringstream ss(s);
  std::vector<double> v;
  std::string tok;
  while (ss >> tok) {
    double x = 0;
    const auto [p, ec] = std::from_chars(tok.data(), tok.data() + tok.size(), x);
    if (ec != std::errc() || p != tok.data() + tok.size()) fail_line(file, lineno, "'" + tok + "' is not a number");
    v.push_back(x);
  }
  return v;
}

}  // namespace

std::vector<std::string> list_images(const std::string& dir) {
  std::error_code ec;
  if (!fs::is_directory(dir, ec)) throw std::runtime_error(dir + ": image folder does not exist");
  static const std::vector<std::string> exts = {".png", ".jpg", ".jpeg", ".bmp", ".pgm", ".ppm", ".tif", ".tiff"};
  std::vector<std::string> files;
  for (const auto& e : fs::directory_iterator(dir)) {
    if (!e.is_regular_file()) continue;
    std::string ext = e.path().extension().string();
    std::transform(ext.begin(), ext.end(), ext.begin(), [](unsigned char c) { return std::tolower(c); });
    if (std::find(exts.begin(), exts.end(), ext) != exts.end()) files.push_back(e.path().string());
  }
  std::sort(files.begin(), files.end());
  return files;
}

std::optional<int64_t> parse_seconds(const std::string& text) {
  // Times whose microseconds do not fit in int64 (e.g. EuRoC's nanosecond stamps given as seconds).
  constexpr int64_t kMaxSeconds = (std::numeric_limits<int64_t>::max() - 1'000'000) / 1'000'000;
  size_t i = 0;
  const bool neg = !text.empty() && text[0] == '-';
  if (neg) ++i;
  int64_t whole = 0;
  size_t digits = 0;
  for (; i < text.size() && std::isdigit(static_cast<unsigned char>(text[i])); ++i, ++digits) {
    whole = whole * 10 + (text[i] - '0');
    if (whole > kMaxSeconds) return std::nullopt;
  }
  int64_t frac = 0;
  int frac_digits = 0;
  bool round_up = false;
  if (i < text.size() && text[i] == '.') {
    for (++i; i < text.size() && std::isdigit(static_cast<unsigned char>(text[i])); ++i, ++digits) {
      if (frac_digits < 6) {
        frac = frac * 10 + (text[i] - '0');
        ++frac_digits;
      } else if (frac_digits == 6) {
        round_up = text[i] >= '5';
        ++frac_digits;
      }
    }
  }
  if (i != text.size() || digits == 0) {
    // Exponent notation ("1.5e-3") and the like: fall back to floating point.
    double x = 0;
    const auto [p, ec] = std::from_chars(text.data(), text.data() + text.size(), x);
    if (ec != std::errc() || p != text.data() + text.size()) return std::nullopt;
    if (!(std::abs(x) <= static_cast<double>(kMaxSeconds))) return std::nullopt;  // also NaN, inf
    return static_cast<int64_t>(std::llround(x * 1e6));
  }
  for (int k = std::min(frac_digits, 6); k < 6; ++k) frac *= 10;
  const int64_t us = whole * 1'000'000 + frac + (round_up ? 1 : 0);
  return neg ? -us : us;
}

std::vector<int64_t> read_timestamps(const std::string& file) {
  auto in = open_text(file);
  std::vector<int64_t> out;
  std::string line;
  for (int lineno = 1; std::getline(in, line); ++lineno) {
    if (skip_line(line)) continue;
    std::istringstream ss(line);
    std::string tok;
    ss >> tok;
    if (!tok.empty() && tok.back() == ',') tok.pop_back();
    const auto t = parse_seconds(tok);
    if (!t) fail_line(file, lineno, "'" + tok + "' is not a time in seconds");
    out.push_back(*t);
  }
  return out;
}

Trajectory read_tum(const std::string& file) {
  auto in = open_text(file);
  Trajectory traj;
  std::string line;
  for (int lineno = 1; std::getline(in, line); ++lineno) {
    if (skip_line(line)) continue;
    std::istringstream ss(line);
    std::string t;
    ss >> t;
    const auto utime = parse_seconds(t);
    const auto v = numbers(line.substr(line.find(t) + t.size()), file, lineno);
    if (!utime || v.size() != 7) fail_line(file, lineno, "expected 't x y z qx qy qz qw'");
    const Eigen::Quaterniond q(v[6], v[3], v[4], v[5]);
    traj[*utime] = geometry::SE3(q, Eigen::Vector3d(v[0], v[1], v[2]));
  }
  return traj;
}

Trajectory read_euroc_groundtruth(const std::string& file) {
  auto in = open_text(file);
  Trajectory traj;
  std::string line;
  for (int lineno = 1; std::getline(in, line); ++lineno) {
    if (skip_line(line)) continue;
    const auto comma = line.find(',');
    int64_t ns = 0;
    const auto [p, ec] = std::from_chars(line.data(), line.data() + (comma == std::string::npos ? line.size() : comma), ns);
    if (ec != std::errc() || comma == std::string::npos) fail_line(file, lineno, "expected 'timestamp_ns, px, py, pz, qw, qx, qy, qz, ...'");
    const auto v = numbers(line.substr(comma + 1), file, lineno);
    if (v.size() < 7) fail_line(file, lineno, "expected at least 'timestamp_ns, px, py, pz, qw, qx, qy, qz'");
    const Eigen::Quaterniond q(v[3], v[4], v[5], v[6]);
    traj[ns / 1000] = geometry::SE3(q, Eigen::Vector3d(v[0], v[1], v[2]));
  }
  return traj;
}

std::vector<geometry::SE3> read_kitti_poses(const std::string& file) {
  auto in = open_text(file);
  std::vector<geometry::SE3> poses;
  std::string line;
  for (int lineno = 1; std::getline(in, line); ++lineno) {
    if (skip_line(line)) continue;
    const auto v = numbers(line, file, lineno);
    if (v.size() != 12) fail_line(file, lineno, "expected 12 numbers (3x4 [R|t]), got " + std::to_string(v.size()));
    Eigen::Matrix3d R;
    R << v[0], v[1], v[2], v[4], v[5], v[6], v[8], v[9], v[10];
    poses.emplace_back(R, Eigen::Vector3d(v[3], v[7], v[11]));
  }
  return poses;
}

std::optional<geometry::SE3> interpolate(const Trajectory& traj, int64_t utime, int64_t max_gap_us) {
  const auto hi = traj.lower_bound(utime);
  if (hi == traj.end()) return std::nullopt;
  if (hi->first == utime) return hi->second;
  if (hi == traj.begin()) return std::nullopt;
  const auto lo = std::prev(hi);
  if (hi->first - lo->first > max_gap_us) return std::nullopt;
  const double a = static_cast<double>(utime - lo->first) / static_cast<double>(hi->first - lo->first);
  const Eigen::Quaterniond q = lo->second.rotation().slerp(a, hi->second.rotation());
  const Eigen::Vector3d t = (1 - a) * lo->second.translation() + a * hi->second.translation();
  return geometry::SE3(q, t);
}

}  // namespace aerie::capture

#include <opencv2/imgcodecs.hpp>

#include "air/capture/frame_source.hpp"

namespace aerie::capture {

cv::Mat load_image(const std::string& file, bool color) {
  cv::Mat img = cv::imread(file, color ? cv::IMREAD_COLOR : cv::IMREAD_GRAYSCALE);
  if (img.empty()) throw FrameError(file + ": cannot read image (missing, unreadable or not an image)");
  return img;
}

}  // namespace aerie::capture
