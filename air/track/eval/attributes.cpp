#include "air/track/eval/attributes.hpp"

#include <algorithm>
#include <cmath>
#include <fstream>
#include <sstream>
#include <stdexcept>

#include "air/track/eval/metrics.hpp"

namespace aerie::track::eval {

const std::vector<std::string>& attribute_names() {
  static const std::vector<std::string> names = {"FM", "LR", "OCC", "SV"};
  return names;
}

bool has_attribute(const Attributes& a, const std::string& name) {
  if (name == "FM") return a.fast_motion;
  if (name == "LR") return a.low_resolution;
  if (name == "OCC") return a.occlusion;
  if (name == "SV") return a.scale_variation;
  throw std::invalid_argument("unknown attribute '" + name + "' (known: FM, LR, OCC, SV)");
}

Attributes attributes(const std::vector<cv::Rect2d>& groundtruth, const std::vector<std::string>& tags) {
  if (groundtruth.empty() || !is_valid_box(groundtruth[0]))
    throw std::invalid_argument("attributes: the first ground-truth box must be a valid box");
  Attributes a;
  a.tags = tags;
  a.frames = static_cast<int>(groundtruth.size());
  const double area0 = groundtruth[0].area();
  a.min_area = area0;
  for (size_t i = 0; i < groundtruth.size(); ++i) {
    const cv::Rect2d& b = groundtruth[i];
    if (!is_valid_box(b)) {
      ++a.absent;
      continue;
    }
    if (i > 0 && is_valid_box(groundtruth[i - 1])) {
      const double shift = centre_error(b, groundtruth[i - 1]);
      ++a.steps;
      a.fast_steps += shift > kFastMotionPx;
      a.max_centre_shift = std::max(a.max_centre_shift, shift);
    }
    a.min_area = std::min(a.min_area, b.area());
    a.small_frames += b.area() < kLowResolutionPx;
    const double scale = std::sqrt(b.area() / area0);
    a.min_scale = std::min(a.min_scale, scale);
    a.max_scale = std::max(a.max_scale, scale);
    a.scale_frames += scale < 1 / kScaleRatio || scale > kScaleRatio;
  }
  a.fast_motion = a.fast_steps > 0;
  a.low_resolution = a.small_frames > 0;
  a.scale_variation = a.scale_frames > 0;
  a.occlusion = a.absent > 0 || std::find(tags.begin(), tags.end(), "OCC") != tags.end();
  return a;
}

Attributes attributes(const Sequence& seq, size_t max_frames) {
  const size_t n = max_frames > 0 ? std::min(max_frames, seq.groundtruth.size()) : seq.groundtruth.size();
  return attributes(std::vector<cv::Rect2d>(seq.groundtruth.begin(), seq.groundtruth.begin() + n),
                    benchmark_tags(seq.dir / "SOURCE.txt"));
}

std::vector<std::string> benchmark_tags(const std::filesystem::path& source_txt) {
  std::ifstream in(source_txt);
  const std::string key = "Benchmark attribute tags:";
  std::string line;
  while (std::getline(in, line)) {
    if (line.rfind(key, 0) != 0) continue;
    // "OPR, SV, OCC, IPR  [where they come from]" or "not copied (...)"
    std::string list = line.substr(key.size(), line.find('[') - key.size());
    std::replace(list.begin(), list.end(), ',', ' ');
    std::istringstream ss(list);
    std::vector<std::string> tags;
    for (std::string t; ss >> t;) {
      // Tags are upper-case abbreviations; anything else (e.g. "not copied") means none.
      if (!std::all_of(t.begin(), t.end(), [](char c) { return std::isupper(static_cast<unsigned char>(c)); }))
        return {};
      tags.push_back(t);
    }
    return tags;
  }
  return {};
}

}  // namespace aerie::track::eval
