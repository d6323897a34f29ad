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

// OTB's temporal robustness evaluation (TRE; Wu et al., CVPR 2013, sec. 4.1): the sequence and
// k - 1 segments of it, segment j starting at frame floor(j n / k) (moved on to the next frame
// whose target is visible) and running to the end. Segment j > 0 is named
// "<name>@<its first frame, 1-based>"; segment 0 is the sequence itself. A start that repeats
// the one before, or leaves fewer than 2 frames, gives no segment. Throws std::invalid_argument
// unless k >= 1.
std::vector<Sequence> temporal_segments(const Sequence& s, int k);
// The sequence a segment belongs to: its name up to the first '@'.
std::string base_name(const std::string& segment);

}  // namespace aerie::track::eval
