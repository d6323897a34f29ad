#pragma once
// A conservative appearance verifier beside ECO's adaptive filter, for the LOST flag only.
//
// A correlation filter's confidence stays high when the box slides off the target onto
// something the filter still matches (it has learned what it now covers). The verifier keeps
// a few appearances of the target that change only on very confident frames and measures how
// well the current box still looks like one of them. The idea is TLD's conservative object
// model (Kalal, Mikolajczyk, Matas, "Tracking-Learning-Detection", TPAMI 2012: normalised
// 15x15 patches, nearest-neighbour normalised cross-correlation) and the separate verification
// stage of long-term correlation trackers (Ma et al., "Long-term Correlation Tracking", CVPR
// 2015; Hong et al., MUSTer, CVPR 2015).
//
// Exemplars: kSize x kSize grey patches of the target box, zero mean and unit norm. The
// similarity of a box is the largest normalised cross-correlation between an exemplar and any
// kSize x kSize part of the box's patch, grown by kMargin cells on each side (so a box off by
// up to kMargin / kSize of its size, 1/8, still matches exactly).
#include <opencv2/core.hpp>
#include <vector>

namespace aerie::track {

class AppearanceVerifier {
 public:
  static constexpr int kSize = 16, kMargin = 2;
  static constexpr int kPatch = kSize + 2 * kMargin;
  // The patch covers the box times this, resized to kPatch x kPatch.
  static constexpr double kGrowth = static_cast<double>(kPatch) / kSize;

  // capacity: the most exemplars kept (>= 1); the first one is never replaced.
  explicit AppearanceVerifier(int capacity = 1);

  // patch: kPatch x kPatch, one channel (8-bit or float). Largest NCC over the exemplars and
  // the (2 kMargin + 1)^2 placements, in [-1, 1]; 0 with no exemplar or a flat placement.
  double similarity(const cv::Mat& patch) const;
  // Keeps the centre kSize x kSize of patch as an exemplar: a free slot, else replaces the
  // oldest but the first. A flat patch (no texture to correlate) is not kept.
  void add(const cv::Mat& patch);
  size_t size() const { return exemplars_.size(); }

 private:
  int capacity_;
  size_t next_ = 1;                 // the slot the next exemplar replaces once full
  std::vector<cv::Mat> exemplars_;  // CV_32F kSize x kSize, zero mean, unit norm
};

}  // namespace aerie::track
