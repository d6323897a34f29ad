#pragma once
// The image channels that rectangle features sum over ("integral channel features",
// Dollar et al. 2009): grey level, gradient magnitude and, for colour frames, the two chroma
// channels. Each channel has its own integral image over the same region.
#include <array>
#include <opencv2/core.hpp>
#include <string>
#include <vector>

#include "air/track/features/integral.hpp"

namespace aerie::track {

enum Channel : int { kGray = 0, kGradient = 1, kChromaCr = 2, kChromaCb = 3, kNumChannels = 4 };

// "gray", "gradient", "color" (both chroma channels) -> channel ids; throws on other names.
std::vector<int> parse_channels(const std::vector<std::string>& names);

// Per-channel integral images of one pyramid level over one region.
class ChannelImages {
 public:
  // gray: 8-bit level image; chroma: CV_8UC2 (Cr, Cb) of the same size, or empty.
  // Only the channels listed in `wanted` are computed.
  void compute(const cv::Mat& gray, const cv::Mat& chroma, const std::vector<int>& wanted, cv::Point origin);
  const IntegralImage& operator[](int channel) const { return ii_[channel]; }
  cv::Rect roi() const { return roi_; }

 private:
  std::array<IntegralImage, kNumChannels> ii_;
  cv::Rect roi_;
  cv::Mat gradient_, chroma_[2];  // reused buffers
};

// Gradient magnitude (|dI/dx| + |dI/dy|) / 2 with central differences, 8-bit, same size.
void gradient_magnitude(const cv::Mat& gray, cv::Mat& out);
inline cv::Mat gradient_magnitude(const cv::Mat& gray) {
  cv::Mat out;
  gradient_magnitude(gray, out);
  return out;
}

}  // namespace aerie::track
