#pragma once
// A folder of images (one camera), played in file-name order. Times come from an
// optional timestamps file (one time in seconds per line, as many lines as images;
// KITTI's times.txt and `aerie-log export`'s times.txt have this form), otherwise
// from a nominal frame rate.
#include <string>
#include <vector>

#include "air/capture/frame_source.hpp"

namespace aerie::capture {

class ImageFolderSource final : public FrameSource {
 public:
  // Throws std::runtime_error naming the folder/file: missing folder, no images,
  // unreadable first image, timestamps count not matching the images.
  ImageFolderSource(const std::string& dir, const std::string& timestamps_file, double fps, bool color);

  std::string describe() const override;
  bool stereo() const override { return false; }
  cv::Size size() const override { return size_; }
  int64_t frame_count() const override { return static_cast<int64_t>(files_.size()); }
  void seek(int64_t index) override { next_ = index; }
  bool next(Frame& frame) override;

  const std::vector<std::string>& files() const { return files_; }

 private:
  std::string dir_;
  std::vector<std::string> files_;
  std::vector<int64_t> utimes_;
  bool color_;
  cv::Size size_;
  int64_t next_ = 0;
};

}  // namespace aerie::capture
