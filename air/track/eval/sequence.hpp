#pragma once
// Single-object tracking sequences in the OTB folder layout: <SEQ>/img/* frames (sorted by
// file name) and <SEQ>/groundtruth.txt with one "x,y,w,h" box per frame (comma, tab or
// space separated; NaN or non-positive sizes mark frames without a visible target).
#include <filesystem>
#include <opencv2/core.hpp>
#include <string>
#include <vector>

namespace aerie::track::eval {

struct Sequence {
  std::string name;
  std::filesystem::path dir;
  std::vector<std::filesystem::path> frames;
  std::vector<cv::Rect2d> groundtruth;  // one per frame
};

// Throws std::runtime_error naming the file (and line) when the layout or a box is wrong,
// or when the frame and box counts differ.
Sequence load_sequence(const std::filesystem::path& dir);
// Every immediate subfolder of data_dir with img/ and groundtruth.txt, sorted by name.
std::vector<Sequence> find_sequences(const std::filesystem::path& data_dir);

std::vector<cv::Rect2d> read_boxes(const std::filesystem::path& file);
void write_boxes(const std::filesystem::path& file, const std::vector<cv::Rect2d>& boxes);

bool is_valid_box(const cv::Rect2d& b);

}  // namespace aerie::track::eval
