#pragma once
// Keyframe bundle adjustment (thesis ch. 4: "a Bundle Adjustment using keyframes is
// adopted to refine the camera motion parallelly"): a sliding window of keyframes and the
// feature tracks they share, refined with Ceres (stereo reprojection residuals u_l, v, u_r
// for observations with disparity, u, v otherwise; Huber loss), in a thread of its own.
// The front end hands over keyframes without waiting and picks up refined poses when
// they are ready.
#include <Eigen/Core>

#include <condition_variable>
#include <cstdint>
#include <deque>
#include <mutex>
#include <optional>
#include <string>
#include <thread>
#include <vector>

#include "air/stereo/motion/stereo_camera.hpp"
#include "common/geometry/se3.hpp"

namespace aerie::stereo {

struct KeyframeObservation {
  int64_t track = -1;      // feature track id (the same physical point in every keyframe)
  Eigen::Vector2d uv;      // left image pixel
  double disparity = -1;   // > 0 when the point has stereo depth in this keyframe
};

struct Keyframe {
  int64_t id = -1;
  int64_t utime = 0;
  // Odometry pose (the front end's chain of frame-to-frame motions, never corrected).
  geometry::SE3 T_odom_cam;
  std::vector<KeyframeObservation> observations;
};

struct BaParams {
  bool enabled = true;
  int window = 8;            // keyframes optimised together (the oldest is held fixed)
  int max_iterations = 15;
  double huber_px = 1.0;
  double outlier_px = 2.0;   // observations off by more after the first solve are dropped
  int min_observations = 2;  // keyframes that must see a track for it to enter the problem
  double max_depth_m = 60.0; // observations farther than this add no depth constraint
  void validate(const std::string& what = "ba") const;
};

struct BaResult {
  int64_t keyframe_id = -1;      // the newest keyframe of the window
  geometry::SE3 T_world_cam;     // its refined pose
  std::vector<std::pair<int64_t, geometry::SE3>> window;  // all refined poses of the window
  int landmarks = 0, residuals = 0, outliers = 0;
  double initial_rms_px = 0, final_rms_px = 0;
  double ms = 0;                 // thread CPU time of the optimisation
};

// The optimisation itself (synchronous, used by the thread and by the tests). `poses` are
// the initial T_world_cam of `window` (same order); the first stays fixed.
BaResult bundle_adjust(const std::vector<Keyframe>& window, const std::vector<geometry::SE3>& poses,
                       const StereoCamera& cam, const BaParams& params);

class BundleAdjuster {
 public:
  BundleAdjuster(const StereoCamera& cam, const BaParams& params);
  ~BundleAdjuster();
  BundleAdjuster(const BundleAdjuster&) = delete;
  BundleAdjuster& operator=(const BundleAdjuster&) = delete;

  // Queues a keyframe and returns at once.
  void add_keyframe(Keyframe kf);
  // The newest finished result, if one arrived since the last call.
  std::optional<BaResult> poll();
  // Blocks until every queued keyframe is optimised (reproducible offline runs).
  void wait_idle();
  // Forgets every keyframe (after the front end lost track).
  void reset();

 private:
  void run();

  StereoCamera cam_;
  BaParams params_;
  std::mutex mutex_;
  std::condition_variable wake_, idle_;
  std::deque<Keyframe> queue_;
  std::optional<BaResult> result_;
  bool stop_ = false, busy_ = false, reset_ = false;
  // Owned by the worker thread: the window and the refined world poses of its keyframes.
  std::deque<Keyframe> window_;
  std::deque<geometry::SE3> poses_;
  std::thread thread_;
};

}  // namespace aerie::stereo
