#pragma once
// Integral image of a region of interest, addressed in the coordinates of the whole
// (pyramid level) image, so that samples keep their global positions. The sum table is
// computed by cv::integral (SIMD-dispatched inside OpenCV).
#include <cstdint>
#include <opencv2/core.hpp>

namespace aerie::track {

class IntegralImage {
 public:
  // Columns readable past the right end of every row (vector loads that run over the end of
  // a row of samples stay inside the allocation).
  static constexpr int kPadColumns = 16;

  IntegralImage() = default;
  // gray: 8-bit single channel covering `origin` .. origin + gray.size() of the level image.
  IntegralImage(const cv::Mat& gray, cv::Point origin) { compute(gray, origin); }
  // The same, reusing this object's memory when the size allows.
  void compute(const cv::Mat& gray, cv::Point origin);

  bool empty() const { return sum_.empty(); }
  // The region covered, in level-image pixels: rectangles inside it can be summed.
  cv::Rect roi() const { return {origin_, cv::Size(sum_.cols - 1, sum_.rows - 1)}; }
  // Sum of the pixels in [x, x+w) x [y, y+h); the rectangle must lie inside roi().
  int32_t sum(int x, int y, int w, int h) const {
    const int32_t* a = row(y);
    const int32_t* b = row(y + h);
    return b[x + w] - b[x] - a[x + w] + a[x];
  }
  // Row y (level-image coordinates) of the sum table, indexed by level-image x:
  // row(y)[x] = sum of pixels above y and left of x.
  const int32_t* row(int y) const { return sum_.ptr<int32_t>(y - origin_.y) - origin_.x; }

 private:
  cv::Mat buffer_;  // (h+1) x (w+1+kPadColumns), CV_32S
  cv::Mat sum_;     // its first w+1 columns
  cv::Point origin_;
};

}  // namespace aerie::track
