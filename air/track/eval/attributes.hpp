#pragma once
// Sequence attributes of the OTB benchmark (Wu et al. 2013, Table 1) computed from the ground
// truth, for the per-attribute breakdown of aerie-bench-track. OTB's thresholds:
//   FM  fast motion:     centre shift > 20 px between two consecutive annotated frames (tm = 20)
//   LR  low resolution:  box area < 400 px (tr = 400), the small-target attribute
//   SV  scale variation: sqrt(area / area of frame 1) outside [1/2, 2] (ts = 2)
//   OCC occlusion:       frames without a target box (NaN rows: fully occluded or out of view)
//                        or "OCC" among the benchmark's tags in SOURCE.txt
// As in OTB a sequence has an attribute when it holds on any frame (no minimum share).
#include <filesystem>
#include <opencv2/core.hpp>
#include <string>
#include <vector>

#include "air/track/eval/sequence.hpp"

namespace aerie::track::eval {

constexpr double kFastMotionPx = 20;    // tm
constexpr double kLowResolutionPx = 400;  // tr, box area
constexpr double kScaleRatio = 2;       // ts

struct Attributes {
  bool fast_motion = false, low_resolution = false, occlusion = false, scale_variation = false;
  // The statistics behind the flags (frames without a valid box are left out of all but `absent`).
  int frames = 0, absent = 0;
  int steps = 0, fast_steps = 0;  // centre shifts between consecutive annotated frames, of which > 20 px
  double max_centre_shift = 0;
  double min_area = 0;  // px
  int small_frames = 0;  // annotated frames with area < 400 px
  double min_scale = 1, max_scale = 1;  // sqrt(area / area of frame 1)
  int scale_frames = 0;  // annotated frames with that ratio outside [1/2, 2]
  std::vector<std::string> tags;  // the benchmark's attribute tags (SOURCE.txt), empty when not known
};

// The attribute names in table order and whether `a` has the one named.
const std::vector<std::string>& attribute_names();  // FM, LR, OCC, SV
bool has_attribute(const Attributes& a, const std::string& name);

// groundtruth[0] (frame 1) must be a valid box. `tags`: the benchmark's tags (only OCC is used).
Attributes attributes(const std::vector<cv::Rect2d>& groundtruth, const std::vector<std::string>& tags = {});
// The sequence's ground truth (its first `max_frames` boxes, 0 = all) and the tags of
// <dir>/SOURCE.txt when it has them (a simulated sequence has none: OCC then only from absent frames).
Attributes attributes(const Sequence& seq, size_t max_frames = 0);

// The tags of the "Benchmark attribute tags: OPR, SV, OCC  [...]" line; empty when the file or
// the line is missing or says the tags were not copied.
std::vector<std::string> benchmark_tags(const std::filesystem::path& source_txt);

}  // namespace aerie::track::eval
