#include "air/track/features/channels.hpp"

#include <opencv2/imgproc.hpp>
#include <stdexcept>

namespace aerie::track {

std::vector<int> parse_channels(const std::vector<std::string>& names) {
  std::vector<int> out;
  for (const auto& n : names) {
    if (n == "gray")
      out.push_back(kGray);
    else if (n == "gradient")
      out.push_back(kGradient);
    else if (n == "color") {
      out.push_back(kChromaCr);
      out.push_back(kChromaCb);
    } else
      throw std::invalid_argument("unknown feature channel '" + n + "' (known: gray, gradient, color)");
  }
  if (out.empty()) throw std::invalid_argument("at least one feature channel is needed");
  return out;
}

void gradient_magnitude(const cv::Mat& gray, cv::Mat& out) {
  out.create(gray.size(), CV_8UC1);
  out.setTo(0);
  if (gray.cols < 3 || gray.rows < 3) return;
  const int w = gray.cols - 2, h = gray.rows - 2;
  cv::Mat gx, gy;
  cv::absdiff(gray(cv::Rect(2, 1, w, h)), gray(cv::Rect(0, 1, w, h)), gx);
  cv::absdiff(gray(cv::Rect(1, 2, w, h)), gray(cv::Rect(1, 0, w, h)), gy);
  cv::Mat inner = out(cv::Rect(1, 1, w, h));
  cv::addWeighted(gx, 0.5, gy, 0.5, 0, inner);
}

void ChannelImages::compute(const cv::Mat& gray, const cv::Mat& chroma, const std::vector<int>& wanted,
                            cv::Point origin) {
  roi_ = cv::Rect(origin, gray.size());
  bool split = false;
  for (int c : wanted) {
    switch (c) {
      case kGray:
        ii_[c].compute(gray, origin);
        break;
      case kGradient:
        gradient_magnitude(gray, gradient_);
        ii_[c].compute(gradient_, origin);
        break;
      case kChromaCr:
      case kChromaCb:
        if (chroma.empty()) throw std::invalid_argument("colour feature channels need a colour frame");
        if (!split) cv::split(chroma, chroma_);
        split = true;
        ii_[c].compute(chroma_[c - kChromaCr], origin);
        break;
      default:
        throw std::invalid_argument("bad channel id");
    }
  }
}

}  // namespace aerie::track
