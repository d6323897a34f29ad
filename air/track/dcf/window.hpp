#pragma once
// Image windows and tapers shared by the correlation-filter trackers.
#include <opencv2/core.hpp>
#include <vector>

namespace aerie::track {

// The window of `size` image pixels centred on `centre` (a pixel of the image), replicated
// beyond the image border, resized to `out`.
cv::Mat subwindow(const cv::Mat& image, cv::Point2d centre, cv::Size2d size, cv::Size out);

// Symmetric Hann window of n samples.
std::vector<float> hann(int n);

// The translation window of a correlation filter: target + padding x its mean side, resized to
// about template_area pixels, a whole number of cells of FFT-friendly count; the filter's
// spatial support (the target box x mask_scale, rounded up to cells, centred, CSR-DCF); the
// Gaussian label of sigma output_sigma x sqrt(target area), centred on shift (0, 0) circularly.
struct FilterWindow {
  cv::Size cells;     // of the response
  cv::Size model;     // the resized window, pixels (cells x cell)
  cv::Size2d window;  // the window at scale 1, image pixels
  cv::Mat hann;       // cells, CV_32F
  cv::Mat mask;       // cells, CV_32F of 0/1
  cv::Mat yf;         // DFT of the label (CV_32FC2)
};
FilterWindow filter_window(cv::Size2d target, double padding, double template_area, int cell, double mask_scale,
                           double output_sigma);

// The 8 window centres around pos, 3/4 of a window apart, clamped to the image (re-detection).
std::vector<cv::Point2d> neighbour_windows(cv::Point2d pos, cv::Size2d window, cv::Size image);

// Signed circular offset of index i on a grid of n (i > n / 2 counts from the end).
inline int circular(int i, int n) { return i > n / 2 ? i - n : i; }

}  // namespace aerie::track
