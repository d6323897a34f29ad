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

// Signed circular offset of index i on a grid of n (i > n / 2 counts from the end).
inline int circular(int i, int n) { return i > n / 2 ? i - n : i; }

}  // namespace aerie::track
