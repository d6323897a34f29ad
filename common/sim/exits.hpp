#pragma once
// Tracking sequences in which the target leaves the image and comes back, for a tracker's
// LOST flag and its re-acquisition: the intruder aircraft (intruder.hpp) over the cloudy sky,
// fully in view at the first frame, then `exits` exits, each of one of three kinds:
//   pan:       the camera pans fast away (the aircraft leaves through a border), dwells, pans back;
//   drift:     the aircraft drifts slowly out through a border and comes back in;
//   occlusion: a foreground mast (a textured full-height band) slides into the image, the
//              aircraft passes behind it and out the other side, the mast slides out.
// While out the aircraft is entirely out of view for `out_frames` (drawn per exit); after a
// border exit it re-enters at the same border, at the same place or (with probability
// `reenter_elsewhere`) elsewhere along it. The aircraft wanders in view between exits.
#include <opencv2/core.hpp>

#include <cstdint>
#include <string>
#include <vector>

#include "common/sim/intruder.hpp"

namespace aerie::sim {

struct ExitsConfig {
  // Sky, aircraft, camera and image as the intruder scene's (its frames, scale_change and
  // draw_target are not used), with a steadier camera and a smaller aircraft by default.
  IntruderConfig look = [] {
    IntruderConfig i;
    i.vibration_px = 1.0;
    i.wingspan_px = 80.0;  // apparent wingspan at scale 1 (px)
    i.max_roll_deg = 10.0;
    return i;
  }();
  double scale_amplitude = 0.15;  // the apparent size varies by +- this fraction
  int exits = 3;                                          // exits per sequence
  std::vector<std::string> kinds = {"pan", "drift", "occlusion"};  // taken in turn from a seeded one
  int in_frames_min = 20, in_frames_max = 50;   // in-view wandering before each exit and after the last
  int out_frames_min = 10, out_frames_max = 40;  // frames entirely out of view per exit
  double min_visible = 0.25;   // a frame is out of view when less of the box than this is visible
  double pan_speed_px = 40.0;   // camera pan and mast slide (px per frame)
  double drift_speed_px = 6.0;  // the aircraft's drift (px per frame)
  double reenter_elsewhere = 0.5;  // probability that a border exit re-enters elsewhere along the border
};

struct ExitsFrame {
  MonoFrame mono;               // image and the aircraft's true geometry (the box may lie off the image)
  double visible_fraction = 1;  // of the box's area: inside the image and not behind the mast
  bool in_view = true;          // visible_fraction >= min_visible
  cv::Rect2d occluder;          // the mast in the image (empty when there is none)
  std::string event = "none";   // kind of the exit under way (pan, drift, occlusion), none between exits
};

// Throws std::invalid_argument naming the first bad value (an unknown kind, a range).
void validate_exits_config(const ExitsConfig& config);

// The fraction of `box` inside [0, width] x [0, height] and outside `occluder`.
double visible_fraction(const cv::Rect2d& box, cv::Size image, const cv::Rect2d& occluder);

class ExitsScene {
 public:
  explicit ExitsScene(const ExitsConfig& config);  // throws std::invalid_argument on a bad config
  ExitsFrame frame(int k) const;                    // deterministic, any order
  int frame_count() const { return static_cast<int>(path_.size()); }
  const ExitsConfig& config() const { return config_; }

 private:
  struct Plan;
  ExitsScene(const ExitsConfig& config, Plan plan);
  ExitsConfig config_;
  std::vector<IntruderPose> path_;
  std::vector<double> mast_x_;       // left edge of the mast in the image before vibration (NaN: none)
  std::vector<int> event_;           // index into config_.kinds, -1 between exits
  double mast_width_ = 0;
  cv::Mat mast_;                     // mast texture, CV_8U or CV_8UC3
  IntruderScene scene_;
};

}  // namespace aerie::sim
