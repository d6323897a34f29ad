#pragma once
// What the published images look like: size (a target size or a downscale factor)
// and gray or colour. Scaling the images scales the intrinsics and the ground-truth
// boxes with them (pixel centres stay pixel centres: u' = (u + 0.5) s - 0.5).
#include <optional>
#include <opencv2/core.hpp>

#include "air/capture/frame_source.hpp"
#include "common/camera/rectification.hpp"

namespace aerie::capture {

struct OutputOptions {
  int width = 0, height = 0;  // target size (0 = keep); both or neither
  double downscale = 1.0;     // divide the source size by this (when no target size)
  bool color = false;         // BGR; false = 8-bit gray
};

class OutputFormat {
 public:
  // Throws std::invalid_argument for inconsistent options.
  OutputFormat(const OutputOptions& options, cv::Size source_size);
  // Final image size.
  cv::Size size() const { return size_; }
  bool resizes() const { return size_ != source_; }

  void apply(Frame& frame) const;  // images and the ground-truth box
  camera::RectifiedStereo apply(const camera::RectifiedStereo& in) const;

 private:
  double sx() const { return static_cast<double>(size_.width) / source_.width; }
  double sy() const { return static_cast<double>(size_.height) / source_.height; }
  cv::Mat convert(const cv::Mat& img) const;

  OutputOptions opt_;
  cv::Size source_, size_;
};

}  // namespace aerie::capture
