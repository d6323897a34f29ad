#pragma once
// Metric pose of a square landing pad of known size from one image, refined inside the
// tracker's box (autonomous landing: the box alone gives the range to a few per cent; the
// pad's four corners give it to about a centimetre).
//
// Method (docs/track.md, "Landing: pad pose"): a square seeded from the pad's H (an isolated
// bright blob inside the dark square), its four sides fitted to the dark-to-bright edges
// (robust lines, then a blurred-profile model for the sub-pixel offset), the pose of the
// square from its four corners with IPPE (infinitesimal plane-based pose estimation, Collins &
// Bartoli, IJCV 2014; cv::SOLVEPNP_IPPE_SQUARE) polished by Levenberg-Marquardt, and the
// square's 90 deg symmetry resolved by the H: the pad warped to a top view by the corners'
// homography is correlated with the marking with its bar along x and along y. The H is
// symmetric under 180 deg: yaw is modulo pi.
#include <Eigen/Core>
#include <opencv2/core.hpp>

#include <array>
#include <optional>
#include <string>

#include "common/camera/camera_model.hpp"

namespace aerie::track {

// The helipad marking of common/sim/world.cpp (paint_helipad): a dark square of side `size`
// with a thin white border, a white ring and a white "H" whose bar runs along the pad's x.
struct PadGeometry {
  double size = 1.0;     // outer side of the marking, metres
  double border = 0.015; // width of the white border, fraction of size: the detected dark
                         // square has side size * (1 - 2 border)
};

struct PadOptions {
  double max_reprojection_px = 1.5;  // RMS of the corners against the fitted square
  double min_side_px = 12;           // smaller pads are not looked for
  double border_margin_px = 2;       // a quad this close to the image border is partly visible
  double min_marking_score = 0.4;    // normalised correlation with the H template (top view)
};

struct PadObservation {
  std::array<cv::Point2d, 4> corners;  // of the dark square, pixels; corners[0] -> corners[1] is
                                       // the pad's +x (the H's bar), the order is clockwise in the image
  Eigen::Vector3d position = Eigen::Vector3d::Zero();  // pad centre, camera optical frame (m)
  Eigen::Matrix3d rotation = Eigen::Matrix3d::Identity();  // pad axes in the camera frame (z towards the camera)
  double yaw = 0;           // atan2 of the image-y over the image-x component of the pad's +x, in (-pi/2, pi/2]
  double reprojection_rms = 0;  // px
  double marking_score = 0;     // correlation with the H template
  cv::Rect2d box;           // axis-aligned box of the corners
  bool marking_only = false;  // the pose of the H alone (observe_marking); corners and box projected
};

// Why observe_pad found nothing (for the node's counters).
enum class PadMiss { None, EmptyWindow, NoQuad, TouchesBorder, NoMarking, Reprojection };
std::string to_string(PadMiss miss);

// gray: 8-bit gray or BGR frame; search: where to look (the tracker's box grown by a margin),
// clipped to the image; camera: its intrinsics (distortion is honoured for the pose).
// Returns nullopt (and the reason in *miss) when no pad is seen whole in the window.
// Throws std::invalid_argument on an empty frame, unusable intrinsics (or a camera size other
// than the frame's) or a non-positive pad size.
std::optional<PadObservation> observe_pad(const cv::Mat& gray, const cv::Rect2d& search, const camera::CameraModel& camera,
                                          const PadGeometry& pad, const PadOptions& options = {}, PadMiss* miss = nullptr);

// The pad's pose from its H alone, for a pad too close to be seen whole (the dark square cut by
// the image border, the H still inside): the four outer corners of the H's legs (the H's
// bounding rectangle, size x 0.38 by size x 0.48) fitted as the square's sides are, with the
// same IPPE + LM pose (the rectangle's 180 deg symmetry is the H's). Coarser than the square
// far away (a side 0.4 x as long), as good at the heights where only the H fits. The result
// has marking_only set; its corners and box are the dark square's projected by the pose.
// Same arguments, misses and errors as observe_pad.
std::optional<PadObservation> observe_marking(const cv::Mat& gray, const cv::Rect2d& search, const camera::CameraModel& camera,
                                              const PadGeometry& pad, const PadOptions& options = {},
                                              PadMiss* miss = nullptr);

}  // namespace aerie::track
