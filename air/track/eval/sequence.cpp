#include "air/track/eval/sequence.hpp"

#include <algorithm>
#include <cmath>
#include <fstream>
#include <iomanip>
#include <sstream>
#include <stdexcept>

namespace aerie::track::eval {
namespace fs = std::filesystem;

bool is_valid_box(const cv::Rect2d& b) {
  return std::isfinite(b.x) && std::isfinite(b.y) && std::isfinite(b.width) && std::isfinite(b.height) &&
         b.width > 0 && b.height > 0;
}

std::vector<cv::Rect2d> read_boxes(const fs::path& file) {
  std::ifstream in(file);
  if (!in) throw std::runtime_error(file.string() + ": cannot open");
  std::vector<cv::Rect2d> out;
  std::string line;
  int n = 0;
  while (std::getline(in, line)) {
    ++n;
    if (line.find_first_not_of(" \t\r") == std::string::npos) continue;
    std::replace_if(line.begin(), line.end(), [](char c) { return c == ',' || c == '\t' || c == '\r'; }, ' ');
    std::istringstream ss(line);
    double v[4];
    std::string tok;
    for (double& x : v) {
      if (!(ss >> tok)) throw std::runtime_error(file.string() + ":" + std::to_string(n) + ": expected x,y,w,h");
      try {
        x = (tok == "NaN" || tok == "nan") ? NAN : std::stod(tok);
      } catch (const std::exception&) {
        throw std::runtime_error(file.string() + ":" + std::to_string(n) + ": '" + tok + "' is not a number");
      }
    }
    out.emplace_back(v[0], v[1], v[2], v[3]);
  }
  return out;
}

void write_boxes(const fs::path& file, const std::vector<cv::Rect2d>& boxes) {
  std::ofstream out(file);
  if (!out) throw std::runtime_error(file.string() + ": cannot write");
  out << std::fixed << std::setprecision(2);
  for (const auto& b : boxes) out << b.x << ',' << b.y << ',' << b.width << ',' << b.height << '\n';
  if (!out) throw std::runtime_error(file.string() + ": write failed");
}

Sequence load_sequence(const fs::path& dir) {
  Sequence s;
  s.dir = dir;
  s.name = dir.filename().string();
  const fs::path img = dir / "img", gt = dir / "groundtruth.txt";
  if (!fs::is_directory(img)) throw std::runtime_error(img.string() + ": no frame folder");
  for (const auto& e : fs::directory_iterator(img)) {
    const auto ext = e.path().extension().string();
    if (e.is_regular_file() && (ext == ".jpg" || ext == ".jpeg" || ext == ".png" || ext == ".bmp" || ext == ".JPG"))
      s.frames.push_back(e.path());
  }
  std::sort(s.frames.begin(), s.frames.end());
  s.groundtruth = read_boxes(gt);
  if (s.frames.empty()) throw std::runtime_error(img.string() + ": no frames");
  if (s.frames.size() != s.groundtruth.size())
    throw std::runtime_error(gt.string() + ": " + std::to_string(s.groundtruth.size()) + " boxes for " +
                             std::to_string(s.frames.size()) + " frames");
  if (!is_valid_box(s.groundtruth.front()))
    throw std::runtime_error(gt.string() + ": the first box (the initialisation) is not a valid box");
  return s;
}

std::vector<Sequence> find_sequences(const fs::path& data_dir) {
  if (!fs::is_directory(data_dir)) throw std::runtime_error(data_dir.string() + ": not a folder");
  std::vector<fs::path> dirs;
  for (const auto& e : fs::directory_iterator(data_dir))
    if (e.is_directory() && fs::is_directory(e.path() / "img") && fs::exists(e.path() / "groundtruth.txt"))
      dirs.push_back(e.path());
  std::sort(dirs.begin(), dirs.end());
  std::vector<Sequence> out;
  for (const auto& d : dirs) out.push_back(load_sequence(d));
  return out;
}

std::vector<Sequence> temporal_segments(const Sequence& s, int k) {
  if (k < 1) throw std::invalid_argument("temporal segments: k = " + std::to_string(k) + ", need k >= 1");
  const size_t n = s.frames.size();
  std::vector<Sequence> out{s};
  size_t last = 0;
  for (int j = 1; j < k; ++j) {
    size_t start = j * n / k;
    while (start < n && !is_valid_box(s.groundtruth[start])) ++start;
    if (start <= last || start + 2 > n) continue;
    last = start;
    Sequence seg{s.name + "@" + std::to_string(start + 1), s.dir,
                 {s.frames.begin() + static_cast<std::ptrdiff_t>(start), s.frames.end()},
                 {s.groundtruth.begin() + static_cast<std::ptrdiff_t>(start), s.groundtruth.end()}};
    out.push_back(std::move(seg));
  }
  return out;
}

std::string base_name(const std::string& segment) { return segment.substr(0, segment.find('@')); }

}  // namespace aerie::track::eval
