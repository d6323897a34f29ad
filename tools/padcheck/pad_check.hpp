#pragma once
// The pad's detection on real frames at known altitudes, without intrinsics (issue 50,
// section 4): a round design's outer diameter in pixels times the altitude is constant under a
// pinhole camera looking down at the pad; its coefficient of variation over the frames
// measures the detection (and the altitudes). docs/track.md, "Landing: real pad images".
#include <opencv2/core.hpp>

#include <iosfwd>
#include <string>
#include <vector>

#include "air/track/landing/pad_design.hpp"

namespace aerie::padcheck {

struct Altitude {
  std::string image;  // file name in the images folder
  double metres = 0;
};

// "name,altitude" rows after one header line (the vision-agh layout). Throws std::runtime_error
// naming the file and line on a missing file, a short row or a non-positive altitude.
std::vector<Altitude> read_altitudes(const std::string& csv);
// A mask of the frame's size (0 where the view is blocked); empty path: none. Throws
// std::invalid_argument naming the file when it cannot be read.
cv::Mat read_mask(const std::string& path);

struct FrameResult {
  std::string image;
  double altitude_m = 0;
  bool found = false;
  double diameter_px = 0;  // the ring's outer diameter (found only)
  double product = 0;      // diameter_px x altitude_m (px m)
  double score = 0;
  bool held_out = false;   // not among the frames the settings were chosen on
};

// Every frame of `altitudes` in `images_dir`; frame i (0-based) is held out when
// held_out_every > 0 and i % held_out_every == held_out_every - 1. Throws std::invalid_argument
// naming a frame that cannot be read or whose size is not the mask's.
std::vector<FrameResult> check_frames(const track::PadDesign& design, const cv::Mat& mask, const std::string& images_dir,
                                      const std::vector<Altitude>& altitudes, const track::RoundOptions& options = {},
                                      int held_out_every = 0);

struct Spread {
  int n = 0;
  double mean = 0, cv = 0;  // of diameter x altitude; cv: sample standard deviation / mean
};
// Over the found frames; part: 0 all, 1 the tuning frames only, 2 the held-out frames only.
Spread spread(const std::vector<FrameResult>& frames, int part = 0);

void write_csv(std::ostream& out, const std::vector<FrameResult>& frames);
void print_table(std::ostream& out, const std::vector<FrameResult>& frames);

}  // namespace aerie::padcheck
