#include "air/capture/image_folder_source.hpp"

#include <cmath>

#include "air/capture/dataset_io.hpp"

namespace aerie::capture {

ImageFolderSource::ImageFolderSource(const std::string& dir, const std::string& timestamps_file, double fps,
                                     bool color)
    : dir_(dir), files_(list_images(dir)), color_(color) {
  if (files_.empty()) throw std::runtime_error(dir + ": no images (png, jpg, bmp, pgm, ppm, tif) in the folder");
  if (!timestamps_file.empty()) {
    utimes_ = read_timestamps(timestamps_file);
    if (utimes_.size() != files_.size())
      throw std::runtime_error(timestamps_file + ": " + std::to_string(utimes_.size()) + " timestamps for " +
                               std::to_string(files_.size()) + " images in " + dir);
  } else {
    if (!(fps > 0)) throw std::invalid_argument("image folder " + dir + ": the frame rate must be positive");
    for (size_t i = 0; i < files_.size(); ++i) utimes_.push_back(std::llround(static_cast<double>(i) * 1e6 / fps));
  }
  try {
    size_ = load_image(files_[0], color_).size();
  } catch (const FrameError& e) {
    throw std::runtime_error(e.what());
  }
}

std::string ImageFolderSource::describe() const {
  return "image folder " + dir_ + " (" + std::to_string(files_.size()) + " frames, " + std::to_string(size_.width) +
         "x" + std::to_string(size_.height) + ")";
}

bool ImageFolderSource::next(Frame& frame) {
  if (next_ >= frame_count()) return false;
  const int64_t i = next_++;
  const auto& file = files_[static_cast<size_t>(i)];
  cv::Mat img = load_image(file, color_);
  if (img.size() != size_)
    throw FrameError(file + ": image is " + std::to_string(img.cols) + "x" + std::to_string(img.rows) +
                     ", the sequence is " + std::to_string(size_.width) + "x" + std::to_string(size_.height));
  frame = Frame{};
  frame.index = i;
  frame.utime = utimes_[static_cast<size_t>(i)];
  frame.left = std::move(img);
  return true;
}

}  // namespace aerie::capture
