#pragma once
// The user's own landing pad (issue 50, section 3; docs/track.md, "Landing: the user's own pad"):
// a pad described by its drawing (an image of the pad seen from above) and its physical size,
// instead of the built-in H.
//
// Two outlines are recognised in the drawing (the outer boundary of its dark paint):
// * square: the drawing is the pad's square (dark where it is not painted white, as the built-in
//   pad). Found in a frame as a dark quad (Otsu contours), its sides fitted as the H pad's
//   (pad_pose.cpp), the corner order chosen by correlating the quad's top view with the drawing
//   in its four rotations, the pose by IPPE + LM with the pad's metric size. A drawing that is
//   the same turned by 90 or 180 deg gives the yaw modulo that (PadDesign::symmetry).
// * round: a dark ring on a light ground (a printed marker). Found as a dark ring whose hole is
//   concentric with the ring's inner/outer ratio of the drawing, its inside correlated with the
//   drawing over all rotations; its outer diameter in pixels needs no intrinsics
//   (observe_round_pad), the range is f * diameter / pixels.
#include <opencv2/core.hpp>

#include <optional>
#include <string>

#include "air/track/landing/pad_pose.hpp"

namespace aerie::track {

struct PadDesign {
  enum class Outline { Square, Round };
  std::string name;         // the file it came from, for messages
  cv::Mat image;            // 8-bit gray drawing: column = pad +x, row = pad -y
  double size_m = 0;        // the drawing's width in metres (its height follows from its aspect)
  Outline outline = Outline::Square;
  int symmetry = 1;         // 1, 2 or 4: the drawing is unchanged turned by 360 / symmetry deg
  cv::Rect outline_box;     // the outline's box in the drawing (px): the whole drawing when square
  double ring_inner_ratio = 0;  // round: diameter of the ring's hole over its outer diameter
  double ring_diameter_m = 0;   // round: the ring's outer diameter (m)
  cv::Mat templ;            // the outline's inside at 64 x 64 (CV_32F), for the correlation
};

// The drawing from a PNG (or any format OpenCV reads; transparent pixels count as white) and
// its width in metres. Throws std::invalid_argument naming the file when it cannot be read, is
// an SVG (rasterise it first: rsvg-convert -b white -w 1024 pad.svg -o pad.png), has no dark
// outline, or when size_m is not > 0.
PadDesign load_pad_design(const std::string& path, double size_m);
// The same from an image in memory (`name` for the messages).
PadDesign make_pad_design(const cv::Mat& image, double size_m, const std::string& name = "pad image");

// The pose of a square design inside `search` (as observe_pad; yaw modulo 2 pi / symmetry, in
// (-pi / symmetry, pi / symmetry]). Throws std::invalid_argument on a round design, an empty
// frame or unusable intrinsics.
std::optional<PadObservation> observe_design(const cv::Mat& frame, const cv::Rect2d& search, const camera::CameraModel& camera,
                                             const PadDesign& design, const PadOptions& options = {},
                                             PadMiss* miss = nullptr);

struct RoundSighting {
  cv::RotatedRect outer;   // the ring's outer ellipse (px)
  double diameter_px = 0;  // the ring's outer diameter from its outer and inner edges (px)
  double score = 0;        // correlation of its inside with the drawing at the best rotation
  double rotation_deg = 0; // that rotation (the drawing turned counter-clockwise in the image)
};

struct RoundOptions {
  double min_diameter_px = 24;  // smaller rings are not looked for
  double min_score = 0.5;       // correlation of the inside with the drawing
  double ratio_tolerance = 0.08;  // |hole / outer - the drawing's| allowed
  double threshold_c = 12;      // adaptive threshold: darker than the local mean by this much
};

// The round design in a whole frame (8-bit gray or BGR); mask: empty, or 8-bit of the frame's
// size, 0 where the view is blocked (the drone's legs): a ring reaching into it, or into the
// image border, is not fully visible and not reported. Best sighting (highest score) or nullopt.
// Throws std::invalid_argument on an empty frame, a square design or a mask of another size.
std::optional<RoundSighting> observe_round_pad(const cv::Mat& frame, const PadDesign& design, const cv::Mat& mask = {},
                                               const RoundOptions& options = {});

}  // namespace aerie::track
