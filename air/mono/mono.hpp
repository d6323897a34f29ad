#pragma once
// Monocular keyframe visual odometry (issue 47 section 1; docs/mono.md):
//   1. tracking: corners of the stereo front end's bucketed FAST (air/stereo/features, thesis
//      eq. 4.5) followed frame to frame by pyramidal Lucas-Kanade (tracking.mode klt), or
//      re-detected in every frame and matched by modified BRIEF (tracking.mode brief, eqs.
//      4.6-4.7, the stereo VO's matcher); new corners are added at every keyframe;
//   2. initialisation from two views with model selection (two_view.hpp): the map's scale is
//      arbitrary, the median depth of the first points is 1;
//   3. pose from the 2D-3D matches: solvePnPRansac (AP3P) and a robust (Huber) Levenberg-
//      Marquardt refinement of the inliers;
//   4. keyframes when the tracked share of the last keyframe's landmarks drops below
//      keyframes.min_tracked_ratio or their median parallax reaches keyframes.parallax_deg;
//      new landmarks triangulated between a track's first keyframe and the new one (parallax
//      and reprojection checks);
//   5. local BA over the newest keyframes in its own thread (local_ba.hpp), its result applied
//      at the next keyframe (ba.apply next_keyframe), so a run is a function of its images.
// A loss (too few PnP inliers, or too many unusable frames in a row) drops the map; the
// odometry initialises a new one from the following frames and reports RESET on the frame
// it is made: the new map has a new arbitrary scale (scale_generation counts the maps), its
// frame starts at the last published pose.
#include <Eigen/Core>
#include <opencv2/core.hpp>

#include <cstdint>
#include <deque>
#include <map>
#include <memory>
#include <optional>
#include <string>
#include <vector>

#include "air/mono/local_ba.hpp"
#include "air/mono/two_view.hpp"
#include "air/stereo/features/features.hpp"
#include "common/geometry/se3.hpp"

namespace aerie::mono {

enum class TrackingMode { Klt, Brief };

struct MonoParams {
  stereo::FeatureParams features;
  TrackingMode tracking = TrackingMode::Klt;
  int klt_window = 15;          // Lucas-Kanade window (pixels)
  int klt_levels = 2;           // pyramid levels above the image
  double klt_max_error = 20.0;  // mean absolute patch difference (grey levels) a track may have
  double min_track_distance_px = 8.0;  // new corners keep this distance from live tracks
  stereo::MatchParams matching;  // tracking.mode brief
  TwoViewParams init;
  int pnp_iterations = 100;
  double pnp_ransac_px = 2.0;
  double pnp_huber_px = 1.0;
  int lost_min_inliers = 20;     // fewer PnP inliers: tracking lost
  double keyframe_min_tracked_ratio = 0.7;
  double keyframe_parallax_deg = 4.0;
  int keyframe_min_landmarks = 60;  // fewer landmarks tracked: keyframe (to triangulate more)
  double triangulation_reprojection_px = 2.0;
  LocalBaParams ba;
  bool ba_synchronous = false;   // wait for each BA at the keyframe that started it
  // Input checks: a frame whose grey-level standard deviation is below min_contrast (black,
  // saturated, uniform) or that is identical to the previous frame (frozen camera) is skipped;
  // more than max_skipped_frames of them in a row lose the map.
  double min_contrast = 4.0;
  int max_skipped_frames = 5;

  void validate() const;  // throws std::invalid_argument naming the key
};

enum class MonoStatus { Ok, Initialising, Lost, Reset };
const char* to_string(MonoStatus s);

struct MonoTimings {  // thread CPU ms per stage
  double tracking = 0, init = 0, pose = 0, keyframe = 0;
  double total() const { return tracking + init + pose + keyframe; }
};

struct MonoResult {
  int64_t utime = 0;
  int64_t frame = 0;
  MonoStatus status = MonoStatus::Initialising;
  std::string message;            // why INITIALISING / LOST / RESET, or what was skipped
  bool skipped = false;           // the frame was refused (input_problem says why)
  std::string input_problem;      // "frozen", "blank", or ""
  geometry::SE3 T_world_cam;      // arbitrary scale (scale_generation's)
  int64_t scale_generation = 0;   // maps made so far; a new one has a new scale
  Model init_model = Model::None; // model of the two-view initialisation (on the frame it succeeded)
  double init_ratio_h = 0;        // its R_H
  int tracks = 0, tracked_landmarks = 0, inliers = 0;
  int keyframes = 0, landmarks = 0;  // in the map
  bool keyframe = false;
  bool ba_applied = false;
  MonoTimings timings;
};

class MonoOdometry {
 public:
  MonoOdometry(const PinholeCamera& cam, const MonoParams& params);
  ~MonoOdometry();

  // CV_8UC1 image of the camera's size. Throws std::invalid_argument on a wrong size or type
  // (the state is unchanged).
  MonoResult process(const cv::Mat& gray, int64_t utime);
  // Drops the map; the next frames initialise a new one (reported RESET).
  void reset(const std::string& why);
  // Waits for the bundle adjuster (offline runs).
  void flush();

  const PinholeCamera& camera() const { return cam_; }
  const MonoParams& params() const { return params_; }

 private:
  struct Track {
    int64_t id = -1;
    cv::Point2f pt;
    stereo::Feature feature;  // brief mode: the descriptor this track was matched with
  };
  struct Keyframe {
    int64_t id = -1;
    geometry::SE3 T_world_cam;
    std::map<int64_t, cv::Point2f> obs;  // track id -> pixel
  };

  void track(const cv::Mat& gray);
  void replenish(const cv::Mat& gray);
  bool try_initialise(MonoResult& r);
  bool estimate_pose(MonoResult& r);
  void make_keyframe(MonoResult& r);
  void triangulate_new(const Keyframe& kf);
  void submit_ba();
  void apply_ba(const BaOutput& out, MonoResult& r);
  void lose(MonoResult& r, const std::string& why);

  PinholeCamera cam_;
  MonoParams params_;
  stereo::FeatureExtractor extractor_;
  std::unique_ptr<LocalBundleAdjuster> ba_;

  cv::Mat prev_gray_;
  std::vector<Track> tracks_;
  int64_t next_track_ = 0, frame_count_ = 0, next_kf_ = 0, generation_ = 0;
  int skipped_run_ = 0;
  // Initialisation: the reference frame's track positions; no map yet.
  std::optional<std::map<int64_t, cv::Point2f>> ref_;
  bool have_map_ = false, restarted_ = false;
  std::string restart_reason_;
  std::map<int64_t, Eigen::Vector3d> landmarks_;  // track id -> world point
  std::deque<Keyframe> keyframes_;
  geometry::SE3 T_world_cam_;       // the last pose
  geometry::SE3 T_world_map_;       // where the current map's frame sits (the pose when it was made)
  bool ba_pending_ = false;         // a job was submitted and is applied at the next keyframe
};

}  // namespace aerie::mono
