#include "air/mono/mono.hpp"

#include <ceres/ceres.h>
#include <opencv2/calib3d.hpp>
#include <opencv2/core/eigen.hpp>
#include <opencv2/imgproc.hpp>
#include <opencv2/video/tracking.hpp>

#include <algorithm>
#include <cmath>
#include <set>
#include <stdexcept>

#include "air/stereo/cpu_time.hpp"
#include "common/geometry/so3.hpp"

namespace aerie::mono {
namespace {

// Pose-only reprojection residual for the robust refinement: parameters [w; t] of T_cam_world.
struct PoseResidual {
  PinholeCamera cam;
  Eigen::Vector3d X;
  Eigen::Vector2d uv;
  template <typename T>
  bool operator()(const T* p, T* r) const {
    const geometry::Vec3<T> Xc = geometry::so3_exp<T>(geometry::Vec3<T>(p[0], p[1], p[2])) * X.cast<T>() +
                                 geometry::Vec3<T>(p[3], p[4], p[5]);
    if (Xc[2] < T(1e-6)) return false;
    r[0] = T(cam.fx) * Xc[0] / Xc[2] + T(cam.cx) - T(uv.x());
    r[1] = T(cam.fy) * Xc[1] / Xc[2] + T(cam.cy) - T(uv.y());
    return true;
  }
};

double median(std::vector<double> v) {
  if (v.empty()) return 0;
  std::nth_element(v.begin(), v.begin() + v.size() / 2, v.end());
  return v[v.size() / 2];
}

}  // namespace

const char* to_string(MonoStatus s) {
  switch (s) {
    case MonoStatus::Ok: return "OK";
    case MonoStatus::Initialising: return "INITIALISING";
    case MonoStatus::Lost: return "LOST";
    case MonoStatus::Reset: return "RESET";
  }
  return "?";
}

void MonoParams::validate() const {
  features.validate("mono.features");
  init.validate("mono.init");
  ba.validate("mono.ba");
  auto fail = [](const std::string& key, const std::string& expected) {
    throw std::invalid_argument("mono." + key + ": expected " + expected);
  };
  if (klt_window < 5 || klt_window % 2 == 0) fail("tracking.klt_window", "an odd number >= 5");
  if (klt_levels < 0 || klt_levels > 6) fail("tracking.klt_levels", "in [0, 6]");
  if (!(klt_max_error > 0)) fail("tracking.klt_max_error", "> 0");
  if (!(min_track_distance_px >= 0)) fail("tracking.min_track_distance_px", ">= 0");
  if (pnp_iterations < 10) fail("pnp.iterations", ">= 10");
  if (!(pnp_ransac_px > 0) || !(pnp_huber_px > 0)) fail("pnp.ransac_px/huber_px", "> 0");
  if (lost_min_inliers < 6) fail("pnp.lost_min_inliers", ">= 6");
  if (!(keyframe_min_tracked_ratio > 0 && keyframe_min_tracked_ratio < 1)) fail("keyframes.min_tracked_ratio", "in (0, 1)");
  if (!(keyframe_parallax_deg > 0)) fail("keyframes.parallax_deg", "> 0");
  if (keyframe_min_landmarks < lost_min_inliers) fail("keyframes.min_landmarks", ">= pnp.lost_min_inliers");
  if (!(triangulation_reprojection_px > 0)) fail("keyframes.reprojection_px", "> 0");
  if (!(min_contrast >= 0)) fail("input.min_contrast", ">= 0");
  if (max_skipped_frames < 0) fail("input.max_skipped_frames", ">= 0");
}

MonoOdometry::MonoOdometry(const PinholeCamera& cam, const MonoParams& params)
    : cam_(cam), params_((params.validate(), params)), extractor_(params.features) {
  cam_.validate();
  if (params_.ba.enabled) ba_ = std::make_unique<LocalBundleAdjuster>(cam_, params_.ba);
}

MonoOdometry::~MonoOdometry() = default;

void MonoOdometry::flush() {
  if (ba_) ba_->wait_idle();
}

void MonoOdometry::reset(const std::string& why) {
  landmarks_.clear();
  keyframes_.clear();
  ref_.reset();
  have_map_ = false;
  ba_pending_ = false;
  ++generation_;  // a BA result of the old map is dropped
  restarted_ = true;
  restart_reason_ = why;
}

void MonoOdometry::lose(MonoResult& r, const std::string& why) {
  r.status = MonoStatus::Lost;
  r.message = "tracking lost: " + why;
  reset(why);
}

void MonoOdometry::track(const cv::Mat& gray) {
  if (tracks_.empty() || prev_gray_.empty()) return;
  if (params_.tracking == TrackingMode::Klt) {
    std::vector<cv::Point2f> from, to;
    for (const auto& t : tracks_) from.push_back(t.pt);
    std::vector<uchar> ok;
    std::vector<float> err;
    cv::calcOpticalFlowPyrLK(prev_gray_, gray, from, to, ok, err, cv::Size(params_.klt_window, params_.klt_window),
                             params_.klt_levels,
                             cv::TermCriteria(cv::TermCriteria::COUNT + cv::TermCriteria::EPS, 20, 0.01));
    const cv::Rect2f inside(0, 0, static_cast<float>(gray.cols - 1), static_cast<float>(gray.rows - 1));
    size_t kept = 0;
    for (size_t i = 0; i < tracks_.size(); ++i) {
      if (!ok[i] || err[i] > params_.klt_max_error || !inside.contains(to[i])) continue;
      tracks_[kept] = tracks_[i];
      tracks_[kept++].pt = to[i];
    }
    tracks_.resize(kept);
    return;
  }
  // Brief: re-detect and match to the previous frame's tracks, then align the matched
  // positions by Lucas-Kanade as the stereo VO does.
  const stereo::FeatureFrame ff = extractor_.extract(gray);
  std::vector<stereo::Feature> prev;
  for (const auto& t : tracks_) prev.push_back(t.feature);
  const auto matches = stereo::match_features(prev, ff.features, extractor_.descriptor_words(), params_.matching);
  std::vector<Track> next;
  std::vector<bool> used(ff.features.size(), false);
  for (const auto& m : matches) {
    Track t = tracks_[m.prev];
    t.feature = ff.features[m.cur];
    t.pt = t.feature.pt;
    used[m.cur] = true;
    next.push_back(t);
  }
  for (size_t j = 0; j < ff.features.size(); ++j)
    if (!used[j]) next.push_back({next_track_++, ff.features[j].pt, ff.features[j]});
  tracks_ = std::move(next);
}

void MonoOdometry::replenish(const cv::Mat& gray) {
  if (params_.tracking == TrackingMode::Brief && !tracks_.empty()) return;  // detected in every frame
  const stereo::FeatureFrame ff = extractor_.extract(gray);
  // Occupancy grid of the live tracks, cells of min_track_distance_px.
  const double cell = std::max(1.0, params_.min_track_distance_px);
  const int gw = static_cast<int>(gray.cols / cell) + 1, gh = static_cast<int>(gray.rows / cell) + 1;
  std::vector<uchar> busy(static_cast<size_t>(gw * gh), 0);
  auto at = [&](const cv::Point2f& p) -> uchar& {
    const int x = std::clamp(static_cast<int>(p.x / cell), 0, gw - 1), y = std::clamp(static_cast<int>(p.y / cell), 0, gh - 1);
    return busy[static_cast<size_t>(y * gw + x)];
  };
  for (const auto& t : tracks_) at(t.pt) = 1;
  for (const auto& f : ff.features) {
    if (at(f.pt)) continue;
    at(f.pt) = 1;
    tracks_.push_back({next_track_++, f.pt, f});
  }
}

bool MonoOdometry::try_initialise(MonoResult& r) {
  stereo::CpuStopwatch sw;
  std::vector<cv::Point2f> a, b;
  std::vector<int64_t> ids;
  for (const auto& t : tracks_) {
    const auto it = ref_->find(t.id);
    if (it == ref_->end()) continue;
    a.push_back(it->second);
    b.push_back(t.pt);
    ids.push_back(t.id);
  }
  const TwoViewResult tv = initialise_two_view(a, b, cam_, params_.init);
  r.timings.init = sw.ms();
  r.init_model = tv.model;
  r.init_ratio_h = tv.ratio_h;
  if (!tv.ok) {
    r.message = "initialising: " + tv.reason;
    // Too few tracks left from the reference frame: start again from this one.
    if (static_cast<int>(a.size()) < 2 * params_.init.min_points) ref_.reset();
    return false;
  }
  // Arbitrary scale: the median depth of the first points in the reference view is 1.
  std::vector<double> depths;
  for (size_t i = 0; i < a.size(); ++i)
    if (tv.good[i]) depths.push_back(tv.points[i].z());
  const double s = 1.0 / median(depths);
  const geometry::SE3 T_cur_ref(tv.T_cur_ref.rotation_matrix(), s * tv.T_cur_ref.translation());
  T_world_map_ = T_world_cam_;  // the new map's frame: the reference view at the last published pose
  Keyframe k0, k1;
  k0.id = next_kf_++;
  k0.T_world_cam = T_world_map_;
  k1.id = next_kf_++;
  k1.T_world_cam = T_world_map_ * T_cur_ref.inverse();
  for (size_t i = 0; i < a.size(); ++i) {
    if (!tv.good[i]) continue;
    landmarks_[ids[i]] = T_world_map_ * (s * tv.points[i]);
    k0.obs[ids[i]] = a[i];
  }
  for (const auto& t : tracks_) k1.obs[t.id] = t.pt;
  keyframes_ = {k0, k1};
  T_world_cam_ = k1.T_world_cam;
  have_map_ = true;
  ref_.reset();
  ++generation_;
  r.message = std::string("map initialised from ") + to_string(tv.model) + " (R_H " + std::to_string(tv.ratio_h) +
              ", " + std::to_string(tv.n_good) + " points, median parallax " + std::to_string(tv.median_parallax_deg) +
              " deg); arbitrary scale: median depth 1";
  return true;
}

bool MonoOdometry::estimate_pose(MonoResult& r) {
  std::vector<cv::Point3f> obj;
  std::vector<cv::Point2f> img;
  std::vector<size_t> which;
  for (size_t i = 0; i < tracks_.size(); ++i) {
    const auto it = landmarks_.find(tracks_[i].id);
    if (it == landmarks_.end()) continue;
    obj.emplace_back(static_cast<float>(it->second.x()), static_cast<float>(it->second.y()),
                     static_cast<float>(it->second.z()));
    img.push_back(tracks_[i].pt);
    which.push_back(i);
  }
  r.tracked_landmarks = static_cast<int>(obj.size());
  if (static_cast<int>(obj.size()) < params_.lost_min_inliers) {
    lose(r, std::to_string(obj.size()) + " landmarks tracked, " + std::to_string(params_.lost_min_inliers) + " needed");
    return false;
  }
  cv::Mat rvec, tvec;
  std::vector<int> inl;
  const bool ok = cv::solvePnPRansac(obj, img, cam_.K(), cv::noArray(), rvec, tvec, false, params_.pnp_iterations,
                                     static_cast<float>(params_.pnp_ransac_px), 0.999, inl, cv::SOLVEPNP_AP3P);
  if (!ok || static_cast<int>(inl.size()) < params_.lost_min_inliers) {
    lose(r, std::to_string(inl.size()) + " PnP inliers of " + std::to_string(obj.size()) + ", " +
                std::to_string(params_.lost_min_inliers) + " needed");
    return false;
  }
  // Robust LM refinement on the RANSAC inliers (Huber), then the inliers again by reprojection.
  double p[6] = {rvec.at<double>(0), rvec.at<double>(1), rvec.at<double>(2),
                 tvec.at<double>(0), tvec.at<double>(1), tvec.at<double>(2)};
  ceres::Problem problem;
  for (int k : inl) {
    problem.AddResidualBlock(new ceres::AutoDiffCostFunction<PoseResidual, 2, 6>(
                                 new PoseResidual{cam_, landmarks_.at(tracks_[which[k]].id), Eigen::Vector2d(img[k].x, img[k].y)}),
                             new ceres::HuberLoss(params_.pnp_huber_px), p);
  }
  ceres::Solver::Options opt;
  opt.linear_solver_type = ceres::DENSE_QR;
  opt.max_num_iterations = 10;
  opt.num_threads = 1;
  opt.logging_type = ceres::SILENT;
  ceres::Solver::Summary summary;
  ceres::Solve(opt, &problem, &summary);
  const geometry::SE3 T_cam_world =
      geometry::SE3::from_rotation_vector(Eigen::Vector3d(p[0], p[1], p[2]), Eigen::Vector3d(p[3], p[4], p[5]));
  // Outlier tracks end (they would corrupt the next keyframe's triangulation and BA).
  std::vector<bool> keep(tracks_.size(), true);
  int inliers = 0;
  const double max_e = 2.0 * params_.pnp_ransac_px;
  for (size_t k = 0; k < which.size(); ++k) {
    const Eigen::Vector3d Xc = T_cam_world * landmarks_.at(tracks_[which[k]].id);
    const bool in = Xc.z() > 0 && (cam_.project(Xc) - Eigen::Vector2d(img[k].x, img[k].y)).norm() < max_e;
    inliers += in;
    if (!in) keep[which[k]] = false;
  }
  if (inliers < params_.lost_min_inliers) {
    lose(r, std::to_string(inliers) + " inliers after refinement, " + std::to_string(params_.lost_min_inliers) + " needed");
    return false;
  }
  size_t kept = 0;
  for (size_t i = 0; i < tracks_.size(); ++i)
    if (keep[i]) tracks_[kept++] = tracks_[i];
  tracks_.resize(kept);
  r.inliers = inliers;
  T_world_cam_ = T_cam_world.inverse();
  return true;
}

void MonoOdometry::triangulate_new(const Keyframe& kf) {
  const geometry::SE3 T2 = kf.T_world_cam.inverse();
  const double max_e2 = params_.triangulation_reprojection_px * params_.triangulation_reprojection_px;
  for (const auto& [id, uv2] : kf.obs) {
    if (landmarks_.count(id)) continue;
    // The oldest keyframe that saw this track gives the widest baseline.
    for (const auto& old : keyframes_) {
      if (old.id == kf.id) break;
      const auto it = old.obs.find(id);
      if (it == old.obs.end()) continue;
      const geometry::SE3 T1 = old.T_world_cam.inverse();
      Eigen::Vector3d X;
      if (!triangulate(T1, T2, cam_.ray(it->second), cam_.ray(uv2), X)) break;
      const Eigen::Vector3d X1 = T1 * X, X2 = T2 * X;
      if (!(X1.z() > 0) || !(X2.z() > 0)) break;
      if ((cam_.project(X1) - Eigen::Vector2d(it->second.x, it->second.y)).squaredNorm() > max_e2 ||
          (cam_.project(X2) - Eigen::Vector2d(uv2.x, uv2.y)).squaredNorm() > max_e2)
        break;
      if (parallax_deg(T1, T2, X) < params_.init.min_parallax_deg) break;
      landmarks_[id] = X;
      break;
    }
  }
}

void MonoOdometry::submit_ba() {
  const int n = static_cast<int>(keyframes_.size());
  if (!ba_ || n < 3) return;
  const int first = std::max(0, n - params_.ba.window);
  BaJob job;
  job.generation = generation_;
  std::map<int64_t, int> lm_index;
  std::map<int64_t, int> seen;
  for (int k = first; k < n; ++k)
    for (const auto& o : keyframes_[k].obs)
      if (landmarks_.count(o.first)) ++seen[o.first];
  for (int k = first; k < n; ++k) {
    const Keyframe& kf = keyframes_[k];
    const int ki = static_cast<int>(job.keyframes.size());
    job.keyframes.push_back({kf.id, kf.T_world_cam, k < first + 2});
    for (const auto& [id, uv] : kf.obs) {
      const auto s = seen.find(id);
      if (s == seen.end() || s->second < 2) continue;
      auto [it, added] = lm_index.emplace(id, static_cast<int>(job.landmarks.size()));
      if (added) job.landmarks.push_back({id, landmarks_.at(id)});
      job.observations.push_back({ki, it->second, Eigen::Vector2d(uv.x, uv.y)});
    }
  }
  ba_->submit(std::move(job));
  ba_pending_ = true;
}

void MonoOdometry::apply_ba(const BaOutput& out, MonoResult& r) {
  if (out.generation != generation_ || out.keyframes.empty()) return;  // of a map since dropped
  // The current pose moves with the newest optimised keyframe: T_w_c' = T_w_k' T_w_k^-1 T_w_c.
  const BaKeyframe& newest = out.keyframes.back();
  for (auto& kf : keyframes_) {
    if (kf.id != newest.id) continue;
    T_world_cam_ = newest.T_world_cam * (kf.T_world_cam.inverse() * T_world_cam_);
  }
  for (const auto& k : out.keyframes)
    for (auto& kf : keyframes_)
      if (kf.id == k.id) kf.T_world_cam = k.T_world_cam;
  for (const auto& l : out.landmarks) {
    const auto it = landmarks_.find(l.id);
    if (it != landmarks_.end()) it->second = l.X;
  }
  for (int64_t id : out.outlier_landmarks) landmarks_.erase(id);
  r.ba_applied = true;
}

void MonoOdometry::make_keyframe(MonoResult& r) {
  if (ba_ && ba_pending_ && !params_.ba_synchronous) {
    ba_->wait_idle();  // the previous keyframe's optimisation, applied here however fast the machine is
    ba_pending_ = false;
    if (auto out = ba_->poll()) apply_ba(*out, r);
  }
  Keyframe kf;
  kf.id = next_kf_++;
  kf.T_world_cam = T_world_cam_;
  for (const auto& t : tracks_) kf.obs[t.id] = t.pt;
  keyframes_.push_back(kf);
  triangulate_new(keyframes_.back());
  if (static_cast<int>(keyframes_.size()) > 2 * params_.ba.window) {
    while (static_cast<int>(keyframes_.size()) > 2 * params_.ba.window) keyframes_.pop_front();
    // Landmarks no kept keyframe and no live track sees are forgotten (the map stays local).
    std::set<int64_t> used;
    for (const auto& k : keyframes_)
      for (const auto& o : k.obs) used.insert(o.first);
    for (const auto& t : tracks_) used.insert(t.id);
    for (auto it = landmarks_.begin(); it != landmarks_.end();) it = used.count(it->first) ? std::next(it) : landmarks_.erase(it);
  }
  r.keyframe = true;
  submit_ba();
  if (ba_ && ba_pending_ && params_.ba_synchronous) {
    ba_->wait_idle();
    ba_pending_ = false;
    if (auto out = ba_->poll()) apply_ba(*out, r);
  }
}

MonoResult MonoOdometry::process(const cv::Mat& gray, int64_t utime) {
  if (gray.type() != CV_8UC1)
    throw std::invalid_argument("mono: expected an 8-bit gray image, got OpenCV type " + std::to_string(gray.type()));
  if (gray.cols != cam_.width || gray.rows != cam_.height)
    throw std::invalid_argument("mono: image is " + std::to_string(gray.cols) + "x" + std::to_string(gray.rows) +
                                ", the camera is " + std::to_string(cam_.width) + "x" + std::to_string(cam_.height));
  MonoResult r;
  r.utime = utime;
  r.frame = frame_count_++;
  stereo::CpuStopwatch sw;

  // Input checks: uniform (black, saturated) frames and a frozen camera are skipped.
  cv::Scalar mean, stddev;
  cv::meanStdDev(gray, mean, stddev);
  if (stddev[0] < params_.min_contrast) {
    r.input_problem = "blank";
    r.message = "blank frame skipped (mean " + std::to_string(static_cast<int>(mean[0])) + ", std " +
                std::to_string(stddev[0]) + " < input.min_contrast)";
  } else if (!prev_gray_.empty() && cv::norm(gray, prev_gray_, cv::NORM_INF) == 0) {
    r.input_problem = "frozen";
    r.message = "frozen camera: frame identical to the previous one, skipped";
  }
  if (!r.input_problem.empty()) {
    r.skipped = true;
    r.status = have_map_ ? MonoStatus::Ok : MonoStatus::Initialising;
    if (++skipped_run_ > params_.max_skipped_frames && (have_map_ || ref_)) {
      lose(r, std::to_string(skipped_run_) + " unusable frames in a row (" + r.input_problem + ")");
      tracks_.clear();
      prev_gray_.release();
    }
  } else {
    skipped_run_ = 0;
    track(gray);
    r.timings.tracking = sw.lap();
    if (!have_map_) {
      r.status = MonoStatus::Initialising;
      if (ref_ && try_initialise(r)) {
        r.status = restarted_ ? MonoStatus::Reset : MonoStatus::Ok;
        if (restarted_) r.message = "new map after a loss (" + restart_reason_ + "): " + r.message;
        restarted_ = false;
        r.keyframe = true;
        replenish(gray);
        for (const auto& t : tracks_) keyframes_.back().obs[t.id] = t.pt;
      } else if (!ref_) {
        replenish(gray);
        ref_.emplace();
        for (const auto& t : tracks_) (*ref_)[t.id] = t.pt;
        r.message = restarted_ ? "re-initialising after a loss (" + restart_reason_ + "): reference frame taken"
                               : "initialising: reference frame taken";
      }
      r.timings.init += sw.lap();
    } else if (estimate_pose(r)) {
      r.status = MonoStatus::Ok;
      r.timings.pose = sw.lap();
      // Keyframe: the last one's landmarks are tracked less, or seen under enough parallax.
      const Keyframe& last = keyframes_.back();
      const geometry::SE3 T1 = last.T_world_cam.inverse(), T2 = T_world_cam_.inverse();
      int in_last = 0, tracked = 0;
      std::vector<double> parallax;
      std::set<int64_t> live;
      for (const auto& t : tracks_) live.insert(t.id);
      for (const auto& [id, uv] : last.obs) {
        const auto lm = landmarks_.find(id);
        if (lm == landmarks_.end()) continue;
        ++in_last;
        if (!live.count(id)) continue;
        ++tracked;
        parallax.push_back(parallax_deg(T1, T2, lm->second));
      }
      const bool want = tracked < params_.keyframe_min_tracked_ratio * in_last ||
                        median(parallax) >= params_.keyframe_parallax_deg ||
                        r.tracked_landmarks < params_.keyframe_min_landmarks;
      if (want) {
        make_keyframe(r);
        replenish(gray);
        for (const auto& t : tracks_) keyframes_.back().obs.emplace(t.id, t.pt);
      }
      r.timings.keyframe = sw.lap();
    } else {
      r.timings.pose = sw.lap();
    }
    prev_gray_ = gray.clone();
  }
  r.T_world_cam = T_world_cam_;
  r.scale_generation = generation_;
  r.tracks = static_cast<int>(tracks_.size());
  r.keyframes = static_cast<int>(keyframes_.size());
  r.landmarks = static_cast<int>(landmarks_.size());
  return r;
}

}  // namespace aerie::mono
