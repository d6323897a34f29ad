#include "tools/padcheck/pad_check.hpp"

#include <opencv2/imgcodecs.hpp>

#include <cmath>
#include <cstdio>
#include <fstream>
#include <ostream>
#include <sstream>
#include <stdexcept>

namespace aerie::padcheck {

std::vector<Altitude> read_altitudes(const std::string& csv) {
  std::ifstream in(csv);
  if (!in) throw std::runtime_error(csv + ": cannot be read");
  std::vector<Altitude> out;
  std::string line;
  std::getline(in, line);  // header
  for (int n = 2; std::getline(in, line); ++n) {
    if (line.find_first_not_of(" \t\r") == std::string::npos) continue;
    const size_t comma = line.find(',');
    Altitude a;
    char* end = nullptr;
    if (comma != std::string::npos) {
      a.image = line.substr(0, comma);
      a.metres = std::strtod(line.c_str() + comma + 1, &end);
    }
    if (comma == std::string::npos || end == line.c_str() + comma + 1 || !(a.metres > 0) || !std::isfinite(a.metres))
      throw std::runtime_error(csv + ":" + std::to_string(n) + ": expected 'image,altitude_m' with an altitude > 0, got '" +
                               line + "'");
    out.push_back(a);
  }
  if (out.empty()) throw std::runtime_error(csv + ": no rows after the header");
  return out;
}

cv::Mat read_mask(const std::string& path) {
  if (path.empty()) return {};
  cv::Mat m = cv::imread(path, cv::IMREAD_GRAYSCALE);
  if (m.empty()) throw std::invalid_argument("mask '" + path + "': cannot be read (missing, or not an image)");
  return m;
}

std::vector<FrameResult> check_frames(const track::PadDesign& design, const cv::Mat& mask, const std::string& images_dir,
                                      const std::vector<Altitude>& altitudes, const track::RoundOptions& options,
                                      int held_out_every) {
  std::vector<FrameResult> out;
  for (size_t i = 0; i < altitudes.size(); ++i) {
    const std::string path = images_dir + "/" + altitudes[i].image;
    const cv::Mat frame = cv::imread(path, cv::IMREAD_GRAYSCALE);
    if (frame.empty()) throw std::invalid_argument("frame '" + path + "': cannot be read");
    if (!mask.empty() && mask.size() != frame.size())
      throw std::invalid_argument("mask is " + std::to_string(mask.cols) + "x" + std::to_string(mask.rows) + ", frame '" +
                                  path + "' " + std::to_string(frame.cols) + "x" + std::to_string(frame.rows));
    FrameResult r;
    r.image = altitudes[i].image;
    r.altitude_m = altitudes[i].metres;
    r.held_out = held_out_every > 0 && static_cast<int>(i % held_out_every) == held_out_every - 1;
    if (const auto s = track::observe_round_pad(frame, design, mask, options)) {
      r.found = true;
      r.diameter_px = s->diameter_px;
      r.product = s->diameter_px * r.altitude_m;
      r.score = s->score;
    }
    out.push_back(r);
  }
  return out;
}

Spread spread(const std::vector<FrameResult>& frames, int part) {
  Spread s;
  double sum = 0, sq = 0;
  for (const auto& f : frames)
    if (f.found && (part == 0 || f.held_out == (part == 2))) ++s.n, sum += f.product, sq += f.product * f.product;
  if (s.n == 0) return s;
  s.mean = sum / s.n;
  const double var = s.n > 1 ? (sq - s.n * s.mean * s.mean) / (s.n - 1) : 0;
  s.cv = std::sqrt(std::max(0.0, var)) / s.mean;
  return s;
}

void write_csv(std::ostream& out, const std::vector<FrameResult>& frames) {
  out << "image,altitude_m,found,diameter_px,diameter_x_altitude,score,held_out\n";
  char buf[256];
  for (const auto& f : frames) {
    std::snprintf(buf, sizeof buf, "%s,%.6f,%d,%.3f,%.4f,%.3f,%d\n", f.image.c_str(), f.altitude_m, f.found ? 1 : 0,
                  f.diameter_px, f.product, f.score, f.held_out ? 1 : 0);
    out << buf;
  }
}

void print_table(std::ostream& out, const std::vector<FrameResult>& frames) {
  char buf[256];
  out << "image              altitude_m  found  diameter_px  d_x_alt  score  part\n";
  for (const auto& f : frames) {
    std::snprintf(buf, sizeof buf, "%-18s %10.3f  %5s  %11.1f  %7.1f  %5.2f  %s\n", f.image.c_str(), f.altitude_m,
                  f.found ? "yes" : "no", f.diameter_px, f.product, f.score, f.held_out ? "held-out" : "tuning");
    out << buf;
  }
  for (int part = 0; part < 3; ++part) {
    const Spread s = spread(frames, part);
    std::snprintf(buf, sizeof buf, "%-9s found %2d: mean diameter x altitude %.1f px m, CV %.2f %%\n",
                  part == 0 ? "all" : part == 1 ? "tuning" : "held-out", s.n, s.mean, 100 * s.cv);
    out << buf;
  }
}

}  // namespace aerie::padcheck
