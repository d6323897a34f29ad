#pragma once
// The stereo visual odometry front end (thesis Fig. 4.4): per rectified stereo pair
//   1. bucketed FAST + modified BRIEF on the left image (features/),
//   2. dense disparity by SGBM_F on one of every `depth_every` pairs (sgbm_ctf/), each feature's
//      disparity refined at full resolution by a short SAD search around it; on the pairs in
//      between, tracked features carry their depth over (eq. 4.12) and that depth, projected
//      into the right image, seeds the same short search,
//   3. matching to the previous left frame (Hamming, mutual + ratio checks, search around the
//      position predicted by the previous motion),
//   4. 2D+3D motion by LM (motion/), pose chained T_odom_{k+1} = T_odom_k * M^-1,
//   5. keyframes (too few tracked features or enough motion) to the bundle adjuster running
//      in its own thread (ba/); its refined poses re-anchor the published pose.
// Tracking failure resets the front end: the pose is kept, tracks restart, status says so.
#include <Eigen/Core>
#include <opencv2/core.hpp>

#include <cstdint>
#include <map>
#include <memory>
#include <optional>
#include <string>
#include <vector>

#include "air/stereo/ba/ba.hpp"
#include "air/stereo/features/features.hpp"
#include "air/stereo/motion/motion.hpp"
#include "air/stereo/sgbm_ctf/sgbm_ctf.hpp"
#include "common/geometry/se3.hpp"

namespace aerie::stereo {

struct VoParams {
  SgbmCtfParams depth = default_depth();  // dense disparity (num_disparities = D)
  int depth_every = 2;        // dense depth on one of every N pairs (thesis: 2)
  int depth_scale = 2;        // 1: dense depth at full resolution, 2: on the half-resolution pair
  int refine_radius = 2;      // per-feature disparity search at full resolution: +- px (0 = off)
  int refine_half_window = 3; // SAD window (2 h + 1)^2 of that refinement
  double max_depth_m = 40.0;  // features farther than this count as 2D (no depth)
  FeatureParams features;
  MatchParams matching;
  double predicted_search_radius = 30.0;  // search radius when a motion prediction exists
  // Matched positions refined by a Lucas-Kanade alignment of the previous frame's patch: the
  // track then follows the same image point instead of the corner re-detected in every frame
  // (re-detection shifts with viewpoint and scale, a bias that accumulates). 0 = off.
  int klt_window = 11;
  MotionParams motion;
  int lost_min_inliers = 15;  // fewer 3D inliers: tracking lost
  // Keyframes: when fewer features than this are tracked from the last keyframe, or the
  // motion since it exceeds either threshold.
  int keyframe_min_tracked = 150;
  double keyframe_translation_m = 0.5;
  double keyframe_rotation_deg = 10.0;
  BaParams ba;
  bool ba_synchronous = false;  // wait for each BA (reproducible offline evaluation)
  // Asynchronous BA: keyframe k's result is applied at keyframe k+1 (waiting for it there if
  // it is not done), so the trajectory depends on the data alone and a replay reproduces a
  // live run; false: at whichever frame it is ready (depends on the machine's speed).
  bool ba_next_keyframe = true;

  void validate() const;  // throws std::invalid_argument naming the key
  static SgbmCtfParams default_depth() {
    SgbmCtfParams d;
    d.sgm.num_disparities = 48;
    return d;
  }
};

enum class VoStatus { Ok, Initialising, Lost, Reset };
const char* to_string(VoStatus s);

struct VoTimings {  // thread CPU ms per stage
  double depth = 0, features = 0, matching = 0, motion = 0, bookkeeping = 0;
  double total() const { return depth + features + matching + motion + bookkeeping; }
};

struct VoResult {
  int64_t utime = 0;
  int64_t frame = 0;
  VoStatus status = VoStatus::Initialising;
  std::string message;                  // why Lost / Reset
  geometry::SE3 T_world_cam;            // published pose (re-anchored by BA)
  geometry::SE3 T_odom_cam;             // pure frame-to-frame chain
  Eigen::Matrix<double, 6, 6> covariance = Eigen::Matrix<double, 6, 6>::Zero();  // [rot; trans], world
  geometry::SE3 motion;                 // T_cur_prev of this step
  int features = 0, matches = 0, features_2d = 0, features_3d = 0, inliers = 0;
  double inlier_ratio = 0;              // inliers / matches
  bool keyframe = false;
  bool depth_computed = false;
  bool ba_applied = false;              // a BA result re-anchored the pose in this frame
  std::vector<int> per_bucket;
  cv::Mat disparity;                    // CV_32F, when depth_computed; 1/depth_scale of the input size
  VoTimings timings;
};

class StereoOdometry {
 public:
  StereoOdometry(const StereoCamera& cam, const VoParams& params);
  ~StereoOdometry();

  // Rectified CV_8UC1 pair of the camera's size. Throws std::invalid_argument on a wrong
  // size or type (the caller reports it; the odometry state is unchanged).
  VoResult process(const cv::Mat& left, const cv::Mat& right, int64_t utime);
  // Evaluation only: the same with a given full-resolution disparity map (CV_32F, e.g. the
  // simulator's exact one) in place of SGBM_F and the feature disparity search, on every
  // frame, to separate depth errors from tracking errors.
  VoResult process_with_disparity(const cv::Mat& left, const cv::Mat& right, int64_t utime,
                                  const cv::Mat& disparity);
  // Forgets the tracks and restarts from the current pose.
  void reset(const std::string& why);
  // Waits for the bundle adjuster to finish what it has (offline runs).
  void flush();

  const StereoCamera& camera() const { return cam_; }
  const VoParams& params() const { return params_; }
  const geometry::SE3& pose() const { return T_world_cam_; }

 private:
  struct Track {
    int64_t id = -1;
    bool has_depth = false;
    Eigen::Vector3d X = Eigen::Vector3d::Zero();  // in this frame's camera coordinates
    double disparity = -1;                        // measured in this frame (> 0), else -1
  };
  struct Frame {
    FeatureFrame feats;
    std::vector<Track> tracks;
    cv::Mat left;  // for the patch alignment of the next frame's matches
  };

  VoResult run(const cv::Mat& left, const cv::Mat& right, int64_t utime, const cv::Mat* given_disparity);
  void assign_depth(const cv::Mat& left, const cv::Mat& right, const cv::Mat& disparity, int scale, bool refine,
                    Frame& frame) const;
  std::optional<double> refine_disparity(const cv::Mat& left, const cv::Mat& right, cv::Point2f p, double d0) const;
  void make_keyframe(int64_t utime, const Frame& frame);

  StereoCamera cam_;
  VoParams params_;
  CoarseToFineSgbm sgbm_;
  FeatureExtractor extractor_;
  MotionEstimator motion_;
  std::unique_ptr<BundleAdjuster> ba_;

  std::optional<Frame> prev_;
  int64_t frame_count_ = 0, next_track_ = 0, keyframe_count_ = 0;
  geometry::SE3 T_odom_cam_, T_world_cam_;
  Eigen::Matrix<double, 6, 6> covariance_ = Eigen::Matrix<double, 6, 6>::Zero();
  std::optional<geometry::SE3> last_motion_;  // T_cur_prev of the last step
  int64_t last_dt_ = 0, prev_utime_ = 0;     // its frame interval, the previous frame's time
  bool restarted_ = false;
  std::string restart_reason_;
  // Keyframes: odometry pose of the last one and which tracks it had; BA anchors.
  geometry::SE3 T_odom_last_kf_;
  std::vector<int64_t> last_kf_tracks_;
  bool have_kf_ = false;
  std::map<int64_t, geometry::SE3> kf_odom_;       // keyframe id -> T_odom_cam when it was made
  // The newest bundle-adjusted keyframe: its refined T_world_cam and its odometry pose.
  std::optional<std::pair<geometry::SE3, geometry::SE3>> anchor_;
  std::optional<BaResult> ba_due_;  // ba_next_keyframe: the previous keyframe's result, applied at this one
  bool ba_at_next_keyframe() const { return params_.ba_next_keyframe && !params_.ba_synchronous; }
  cv::Mat left_half_, right_half_;
};

}  // namespace aerie::stereo
