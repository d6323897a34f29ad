#include "air/capture/video_source.hpp"

#include <opencv2/imgproc.hpp>

#include <cmath>
#include <filesystem>

#include "common/camera/calibration_io.hpp"
#include "common/util/time.hpp"

namespace aerie::capture {
namespace fs = std::filesystem;

namespace {

void to_format(cv::Mat& img, bool color) {
  if (!color && img.channels() == 3) cv::cvtColor(img, img, cv::COLOR_BGR2GRAY);
  if (color && img.channels() == 1) cv::cvtColor(img, img, cv::COLOR_GRAY2BGR);
}

std::string size_str(const cv::Size& s) { return std::to_string(s.width) + "x" + std::to_string(s.height); }

// "/dev/video2" or "2" -> an opened V4L2 capture.
cv::VideoCapture open_v4l2(const std::string& dev, const V4l2Options& o) {
  cv::VideoCapture cap;
  const bool is_index = !dev.empty() && dev.find_first_not_of("0123456789") == std::string::npos;
  if (!is_index && !fs::exists(dev)) throw std::runtime_error(dev + ": no such camera device");
  if (is_index) {
    cap.open(std::stoi(dev), cv::CAP_V4L2);
  } else {
    cap.open(dev, cv::CAP_V4L2);
  }
  if (!cap.isOpened()) throw std::runtime_error(dev + ": cannot open the camera with V4L2 (busy, or not a capture device?)");
  if (o.width > 0) cap.set(cv::CAP_PROP_FRAME_WIDTH, o.width);
  if (o.height > 0) cap.set(cv::CAP_PROP_FRAME_HEIGHT, o.height);
  if (o.fps > 0) cap.set(cv::CAP_PROP_FPS, o.fps);
  return cap;
}

}  // namespace

VideoFileSource::VideoFileSource(const std::string& file, double fps_fallback, bool color)
    : file_(file), color_(color) {
  std::error_code ec;
  if (!fs::is_regular_file(file, ec)) throw std::runtime_error(file + ": video file does not exist");
  // FFmpeg reads the containers and codecs a flight is recorded in. CAP_ANY would, for a file
  // FFmpeg refuses, go on to probe every other backend, among them gphoto2's autodetection of
  // USB cameras (which LeakSanitizer catches leaking inside libgphoto2).
  if (!cap_.open(file, cv::CAP_FFMPEG) || !cap_.isOpened())
    throw std::runtime_error(file + ": cannot open the video (unsupported container or codec?)");
  fps_ = cap_.get(cv::CAP_PROP_FPS);
  if (!(fps_ > 0 && fps_ < 1000)) fps_ = fps_fallback;
  if (!(fps_ > 0)) throw std::invalid_argument(file + ": the video states no frame rate; give one (fps)");
  count_ = static_cast<int64_t>(cap_.get(cv::CAP_PROP_FRAME_COUNT));
  size_ = {static_cast<int>(cap_.get(cv::CAP_PROP_FRAME_WIDTH)), static_cast<int>(cap_.get(cv::CAP_PROP_FRAME_HEIGHT))};
  if (count_ <= 0) count_ = -1;
}

std::string VideoFileSource::describe() const {
  return "video file " + file_ + " (" + (count_ > 0 ? std::to_string(count_) : std::string("?")) + " frames, " +
         std::to_string(fps_) + " fps)";
}

void VideoFileSource::seek(int64_t index) {
  if (index == next_) return;
  if (!cap_.set(cv::CAP_PROP_POS_FRAMES, static_cast<double>(index))) {
    FrameSource::seek(index - next_);  // the backend cannot seek: read forward
    return;
  }
  next_ = index;
}

bool VideoFileSource::next(Frame& frame) {
  cv::Mat img;
  if (!cap_.read(img) || img.empty()) return false;
  to_format(img, color_);
  frame = Frame{};
  frame.index = next_++;
  frame.utime = std::llround(static_cast<double>(frame.index) * 1e6 / fps_);
  frame.left = std::move(img);
  return true;
}

V4l2Source::V4l2Source(const V4l2Options& options) : opt_(options) {
  left_ = open_v4l2(opt_.left, opt_);
  if (!opt_.right.empty()) right_ = open_v4l2(opt_.right, opt_);
  size_ = {static_cast<int>(left_.get(cv::CAP_PROP_FRAME_WIDTH)), static_cast<int>(left_.get(cv::CAP_PROP_FRAME_HEIGHT))};
  if (!opt_.calib.empty()) {
    if (!right_.isOpened()) throw std::invalid_argument("a calibration (" + opt_.calib + ") needs a stereo pair: give the right camera too");
    const auto calib = camera::read_stereo_calibration(opt_.calib, size_.width, size_.height);
    if (calib.left.size() != size_)
      throw std::runtime_error("calibration " + opt_.calib + " is for " + size_str(calib.left.size()) + " images but " +
                               opt_.left + " delivers " + size_str(size_));
    rectifier_ = std::make_unique<camera::StereoRectifier>(calib);
  }
}

std::string V4l2Source::describe() const {
  return "V4L2 camera" + std::string(stereo() ? "s " + opt_.left + " + " + opt_.right : " " + opt_.left) + " (" +
         size_str(size_) + (rectifier_ ? ", rectified" : "") + ")";
}

std::optional<camera::RectifiedStereo> V4l2Source::rectified() const {
  if (!rectifier_) return std::nullopt;
  return rectifier_->rectified();
}

bool V4l2Source::next(Frame& frame) {
  frame = Frame{};
  frame.index = next_++;
  // Grab both first (cheap, latches the exposure), then decode.
  const bool ok_l = left_.grab();
  const bool ok_r = !right_.isOpened() || right_.grab();
  frame.utime = util::wall_utime();
  cv::Mat l, r;
  if (!ok_l || !left_.retrieve(l) || l.empty()) throw FrameError(opt_.left + ": frame " + std::to_string(frame.index) + " could not be read");
  if (right_.isOpened() && (!ok_r || !right_.retrieve(r) || r.empty()))
    throw FrameError(opt_.right + ": frame " + std::to_string(frame.index) + " could not be read");
  to_format(l, opt_.color);
  if (!r.empty()) to_format(r, opt_.color);
  if (rectifier_) {
    try {
      rectifier_->rectify(l, r, frame.left, frame.right);
    } catch (const std::invalid_argument& e) {
      throw FrameError(opt_.left + ": " + e.what());
    }
  } else {
    frame.left = std::move(l);
    frame.right = std::move(r);
  }
  return true;
}

}  // namespace aerie::capture
