#pragma once
// Staple's colour model (Bertinetto et al., CVPR 2016): foreground and background colour
// histograms of the tracking window, the per-pixel likelihood P(foreground | colour) =
// H_fg / (H_fg + H_bg), and its mean over a target-sized box at each shift, merged with a
// correlation filter's response.
#include <opencv2/core.hpp>

namespace aerie::track {

class ColourHistogram {
 public:
  ColourHistogram() = default;
  // bins per colour channel (grey patches: one channel), a power of two in [2, 256];
  // inner_padding: the foreground is the target shrunk by this x (w + h) / 2.
  ColourHistogram(int bins, double inner_padding) : bins_(bins), inner_padding_(inner_padding) {}

  // patch: the window resized to the model, target centred; target: its size there (pixels).
  // Foreground: the shrunk target; background: outside the target. Rate 1 replaces the model.
  void learn(const cv::Mat& patch, cv::Size2d target, double rate);
  cv::Mat likelihood(const cv::Mat& patch) const;  // CV_32F per pixel
  // response (cells, circular shifts of `cell` model pixels) <- (1 - weight) response +
  // weight * the mean likelihood of a target-sized box centred at each shift.
  void merge(cv::Mat& response, const cv::Mat& patch, cv::Size2d target, int cell, double weight) const;

 private:
  int bins_ = 32;
  double inner_padding_ = 0.2;
  cv::Mat fg_, bg_;  // normalised histograms
};

}  // namespace aerie::track
