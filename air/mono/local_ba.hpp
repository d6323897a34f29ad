#pragma once
// Local bundle adjustment of a monocular map: a window of keyframes and the landmarks they
// see, refined with Ceres (reprojection residuals u, v in pixels, Huber loss), the two oldest
// keyframes of the window held fixed (they fix the gauge: position, orientation and the
// map's arbitrary scale). The stereo BA (air/stereo/ba) starts its landmarks from stereo
// depth and fixes only one keyframe, so it cannot serve a monocular map; this is its
// monocular sibling, with the same residual and loss.
// LocalBundleAdjuster runs the optimisation in a thread of its own; the front end applies a
// result at the keyframe after the one that asked for it (the stereo VO's next_keyframe
// rule), waiting for it there, so the trajectory depends on the data alone.
#include <Eigen/Core>

#include <condition_variable>
#include <cstdint>
#include <mutex>
#include <optional>
#include <string>
#include <thread>
#include <vector>

#include "air/mono/two_view.hpp"
#include "common/geometry/se3.hpp"

namespace aerie::mono {

struct LocalBaParams {
  bool enabled = true;
  int window = 6;            // keyframes optimised together (the two oldest held fixed)
  int max_iterations = 10;
  double huber_px = 1.0;
  double outlier_px = 3.0;   // observations off by more after the solve are reported as outliers
  void validate(const std::string& what = "ba") const;
};

struct BaKeyframe {
  int64_t id = -1;
  geometry::SE3 T_world_cam;
  bool fixed = false;
};
struct BaLandmark {
  int64_t id = -1;
  Eigen::Vector3d X = Eigen::Vector3d::Zero();  // world
};
struct BaObservation {
  int keyframe = -1, landmark = -1;  // indices into the job's vectors
  Eigen::Vector2d uv;
};
struct BaJob {
  int64_t generation = 0;  // the map this job belongs to (a result of an older map is dropped)
  std::vector<BaKeyframe> keyframes;
  std::vector<BaLandmark> landmarks;
  std::vector<BaObservation> observations;
};
struct BaOutput {
  int64_t generation = 0;
  std::vector<BaKeyframe> keyframes;   // refined
  std::vector<BaLandmark> landmarks;   // refined
  std::vector<int64_t> outlier_landmarks;  // landmarks with an observation off by more than outlier_px
  double initial_rms_px = 0, final_rms_px = 0;
  double ms = 0;  // thread CPU time
};

// The optimisation (synchronous; the thread and the tests call it).
BaOutput local_bundle_adjust(const BaJob& job, const PinholeCamera& cam, const LocalBaParams& params);

class LocalBundleAdjuster {
 public:
  LocalBundleAdjuster(const PinholeCamera& cam, const LocalBaParams& params);
  ~LocalBundleAdjuster();
  LocalBundleAdjuster(const LocalBundleAdjuster&) = delete;
  LocalBundleAdjuster& operator=(const LocalBundleAdjuster&) = delete;

  void submit(BaJob job);              // returns at once (replaces a job not started yet)
  void wait_idle();                    // blocks until the submitted job is done
  std::optional<BaOutput> poll();      // the finished result, once

 private:
  void run();
  PinholeCamera cam_;
  LocalBaParams params_;
  std::mutex mutex_;
  std::condition_variable wake_, idle_;
  std::optional<BaJob> job_;
  std::optional<BaOutput> result_;
  bool busy_ = false, stop_ = false;
  std::thread thread_;
};

}  // namespace aerie::mono
