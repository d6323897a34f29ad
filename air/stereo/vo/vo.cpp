#include "air/stereo/vo/vo.hpp"

#include <opencv2/imgproc.hpp>
#include <opencv2/video/tracking.hpp>

#include <algorithm>
#include <cmath>
#include <stdexcept>

#include "air/stereo/cpu_time.hpp"

namespace aerie::stereo {
namespace {

using Mat6 = Eigen::Matrix<double, 6, 6>;

// Adjoint of T for perturbations ordered [rotation; translation].
Mat6 adjoint(const geometry::SE3& T) {
  const Eigen::Matrix3d R = T.rotation_matrix();
  Mat6 A = Mat6::Zero();
  A.topLeftCorner<3, 3>() = R;
  A.bottomRightCorner<3, 3>() = R;
  A.bottomLeftCorner<3, 3>() = geometry::hat<double>(T.translation()) * R;
  return A;
}

}  // namespace

const char* to_string(VoStatus s) {
  switch (s) {
    case VoStatus::Ok: return "OK";
    case VoStatus::Initialising: return "INITIALISING";
    case VoStatus::Lost: return "LOST";
    case VoStatus::Reset: return "RESET";
  }
  return "?";
}

void VoParams::validate() const {
  depth.validate("vo.depth");
  features.validate("vo.features");
  motion.validate("vo.motion");
  ba.validate("vo.ba");
  auto fail = [](const std::string& key, const std::string& expected) {
    throw std::invalid_argument("vo." + key + ": " + expected);
  };
  if (depth_every < 1) fail("depth_every", ">= 1");
  if (depth_scale != 1 && depth_scale != 2) fail("depth_scale", "1 or 2");
  if (refine_radius < 0 || refine_half_window < 1) fail("refine_radius/refine_half_window", ">= 0 / >= 1");
  if (!(max_depth_m > 0)) fail("max_depth_m", "> 0");
  if (!(predicted_search_radius > 0) || !(matching.search_radius > 0)) fail("matching.search_radius", "> 0");
  if (lost_min_inliers < motion.min_3d) fail("lost_min_inliers", ">= motion.min_3d");
  if (keyframe_min_tracked < 0 || !(keyframe_translation_m > 0) || !(keyframe_rotation_deg > 0))
    fail("keyframe_*", "positive thresholds");
}

StereoOdometry::StereoOdometry(const StereoCamera& cam, const VoParams& params)
    : cam_(cam),
      params_(params),
      sgbm_((params.validate(), params.depth)),
      extractor_(params.features),
      motion_(params.motion) {
  cam_.validate("vo camera");
  if (params_.ba.enabled) ba_ = std::make_unique<BundleAdjuster>(cam_, params_.ba);
}

StereoOdometry::~StereoOdometry() = default;

void StereoOdometry::flush() {
  if (ba_) ba_->wait_idle();
}

void StereoOdometry::reset(const std::string& why) {
  prev_.reset();
  last_motion_.reset();
  if (ba_) ba_->reset();
  // The odometry chain restarts from the pose published last, so the pose does not jump.
  T_odom_cam_ = T_world_cam_;
  anchor_.reset();
  ba_due_.reset();
  kf_odom_.clear();
  have_kf_ = false;
  restarted_ = true;
  restart_reason_ = why;
}

std::optional<double> StereoOdometry::refine_disparity(const cv::Mat& left, const cv::Mat& right, cv::Point2f p,
                                                       double d0) const {
  // SAD of a (2h+1)^2 patch along the row, +-r around d0, parabola through the minimum.
  const int h = params_.refine_half_window, r = params_.refine_radius;
  const int u = cvRound(p.x), v = cvRound(p.y), dc = static_cast<int>(std::lround(d0));
  if (v - h < 0 || v + h >= left.rows || u + h >= left.cols || u - dc - r - h < 0) return std::nullopt;
  std::vector<int> sad(2 * r + 1);
  for (int k = -r; k <= r; ++k) {
    int s = 0;
    for (int y = -h; y <= h; ++y) {
      const uint8_t* a = left.ptr<uint8_t>(v + y) + u - h;
      const uint8_t* b = right.ptr<uint8_t>(v + y) + u - (dc + k) - h;
      for (int x = 0; x <= 2 * h; ++x) s += std::abs(a[x] - b[x]);
    }
    sad[k + r] = s;
  }
  const int best = static_cast<int>(std::min_element(sad.begin(), sad.end()) - sad.begin());
  if (best == 0 || best == 2 * r) return std::nullopt;  // minimum on the border: no confirmation
  const double den = sad[best - 1] + sad[best + 1] - 2.0 * sad[best];
  const double frac = den > 0 ? (sad[best - 1] - sad[best + 1]) / (2.0 * den) : 0.0;
  return dc + (best - r) + frac;
}

void StereoOdometry::assign_depth(const cv::Mat& left, const cv::Mat& right, const cv::Mat& disparity, int s,
                                  bool refine, Frame& frame) const {
  const double min_disparity = cam_.disparity(params_.max_depth_m);
  for (size_t j = 0; j < frame.feats.features.size(); ++j) {
    const cv::Point2f p = frame.feats.features[j].pt;
    const int x = std::min(disparity.cols - 1, cvRound(p.x) / s), y = std::min(disparity.rows - 1, cvRound(p.y) / s);
    const float d0 = disparity.at<float>(y, x);
    if (d0 < 0) continue;  // no dense depth here: keep what the track carried over
    std::optional<double> d = static_cast<double>(d0) * s;
    if (refine) d = refine_disparity(left, right, p, *d);
    if (!d || *d < min_disparity) continue;
    Track& t = frame.tracks[j];
    t.X = cam_.triangulate(p.x, p.y, *d);
    t.has_depth = true;
    t.disparity = *d;
  }
}

void StereoOdometry::make_keyframe(int64_t utime, const Frame& frame) {
  Keyframe kf;
  kf.id = keyframe_count_++;
  kf.utime = utime;
  kf.T_odom_cam = T_odom_cam_;
  last_kf_tracks_.clear();
  for (size_t j = 0; j < frame.tracks.size(); ++j) {
    const auto& f = frame.feats.features[j];
    kf.observations.push_back({frame.tracks[j].id, Eigen::Vector2d(f.pt.x, f.pt.y), frame.tracks[j].disparity});
    last_kf_tracks_.push_back(frame.tracks[j].id);
  }
  std::sort(last_kf_tracks_.begin(), last_kf_tracks_.end());
  T_odom_last_kf_ = T_odom_cam_;
  have_kf_ = true;
  kf_odom_[kf.id] = T_odom_cam_;
  while (static_cast<int>(kf_odom_.size()) > 4 * params_.ba.window) kf_odom_.erase(kf_odom_.begin());
  if (ba_) {
    if (ba_at_next_keyframe()) {
      ba_->wait_idle();         // the previous keyframe's optimisation
      ba_due_ = ba_->poll();    // applied at this frame, however fast the machine is
    }
    ba_->add_keyframe(std::move(kf));
    if (params_.ba_synchronous) ba_->wait_idle();
  }
}

VoResult StereoOdometry::process(const cv::Mat& left, const cv::Mat& right, int64_t utime) {
  return run(left, right, utime, nullptr);
}

VoResult StereoOdometry::process_with_disparity(const cv::Mat& left, const cv::Mat& right, int64_t utime,
                                                const cv::Mat& disparity) {
  if (disparity.type() != CV_32FC1 || disparity.size() != left.size())
    throw std::invalid_argument("vo: the given disparity must be CV_32F of the image size");
  return run(left, right, utime, &disparity);
}

VoResult StereoOdometry::run(const cv::Mat& left, const cv::Mat& right, int64_t utime, const cv::Mat* given) {
  if (left.type() != CV_8UC1 || right.type() != CV_8UC1)
    throw std::invalid_argument("vo: expected 8-bit gray rectified images");
  if (left.cols != cam_.width || left.rows != cam_.height || right.size() != left.size())
    throw std::invalid_argument("vo: images are " + std::to_string(left.cols) + "x" + std::to_string(left.rows) +
                                " / " + std::to_string(right.cols) + "x" + std::to_string(right.rows) +
                                ", the camera is " + std::to_string(cam_.width) + "x" + std::to_string(cam_.height));
  VoResult r;
  r.utime = utime;
  r.frame = frame_count_++;
  CpuStopwatch sw;

  // 1. Features on the left image.
  Frame cur;
  cur.feats = extractor_.extract(left);
  cur.tracks.resize(cur.feats.features.size());
  r.features = static_cast<int>(cur.feats.features.size());
  r.per_bucket = cur.feats.per_bucket;
  r.timings.features = sw.lap();

  // 2. Dense depth on one of every depth_every pairs, and always when (re)starting.
  const bool depth_frame = given || !prev_ || (r.frame % params_.depth_every) == 0;
  const int scale = given ? 1 : params_.depth_scale;
  const bool refine = !given && params_.refine_radius > 0;
  cv::Mat disparity;
  if (given) {
    disparity = *given;
  } else if (depth_frame) {
    if (params_.depth_scale == 1) {
      disparity = sgbm_.compute(left, right);
    } else {
      cv::resize(left, left_half_, cv::Size(), 0.5, 0.5, cv::INTER_AREA);
      cv::resize(right, right_half_, cv::Size(), 0.5, 0.5, cv::INTER_AREA);
      disparity = sgbm_.compute(left_half_, right_half_);
    }
    r.depth_computed = true;
  }
  r.timings.depth = sw.lap();

  if (!prev_) {
    for (auto& t : cur.tracks) t.id = next_track_++;
    assign_depth(left, right, disparity, scale, refine, cur);
    r.status = restarted_ ? VoStatus::Reset : VoStatus::Initialising;
    r.message = restarted_ ? "tracking restarted: " + restart_reason_ : "first frame";
    restarted_ = false;
    for (const auto& t : cur.tracks) r.features_3d += t.has_depth;
    cur.left = left.clone();
    prev_ = std::move(cur);
    prev_utime_ = utime;
    make_keyframe(utime, *prev_);
    r.keyframe = true;
  } else {
    const Frame& prev = *prev_;
    // 3. Matching, around the positions the previous motion predicts (constant velocity: the
    //    last motion scaled to this frame interval, so dropped frames are bridged).
    std::optional<geometry::SE3> prediction;
    const int64_t dt = utime - prev_utime_;
    if (last_motion_ && last_dt_ > 0 && dt > 0) {
      const double scale = std::min(5.0, static_cast<double>(dt) / static_cast<double>(last_dt_));
      prediction = geometry::SE3::exp(scale * last_motion_->log());
    }
    std::vector<cv::Point2f> predicted;
    if (prediction) {
      const Eigen::Matrix3d R = prediction->rotation_matrix();
      for (size_t i = 0; i < prev.tracks.size(); ++i) {
        const auto& f = prev.feats.features[i];
        Eigen::Vector3d X = prev.tracks[i].has_depth
                                ? Eigen::Vector3d(*prediction * prev.tracks[i].X)
                                : Eigen::Vector3d(R * Eigen::Vector3d((f.pt.x - cam_.cx) / cam_.fx,
                                                                      (f.pt.y - cam_.cy) / cam_.fy, 1.0));
        if (X.z() < 1e-3) X = Eigen::Vector3d((f.pt.x - cam_.cx) / cam_.fx, (f.pt.y - cam_.cy) / cam_.fy, 1.0);
        const Eigen::Vector2d uv = cam_.project(X);
        predicted.emplace_back(static_cast<float>(uv.x()), static_cast<float>(uv.y()));
      }
    }
    MatchParams mp = params_.matching;
    if (prediction) mp.search_radius = params_.predicted_search_radius;
    auto matches = match_features(prev.feats.features, cur.feats.features, extractor_.descriptor_words(), mp,
                                  prediction ? &predicted : nullptr);
    if (prediction && static_cast<int>(matches.size()) < 2 * params_.lost_min_inliers) {
      // The motion changed abruptly: search again without the prediction.
      matches = match_features(prev.feats.features, cur.feats.features, extractor_.descriptor_words(),
                               params_.matching);
      prediction.reset();
    }
    if (params_.klt_window > 0 && !matches.empty()) {
      std::vector<cv::Point2f> from, to;
      for (const auto& m : matches) {
        from.push_back(prev.feats.features[m.prev].pt);
        to.push_back(cur.feats.features[m.cur].pt);
      }
      std::vector<uchar> ok;
      std::vector<float> err;
      cv::calcOpticalFlowPyrLK(prev.left, left, from, to, ok, err, cv::Size(params_.klt_window, params_.klt_window), 0,
                               cv::TermCriteria(cv::TermCriteria::COUNT + cv::TermCriteria::EPS, 10, 0.01),
                               cv::OPTFLOW_USE_INITIAL_FLOW);
      size_t kept = 0;
      for (size_t k = 0; k < matches.size(); ++k) {
        cv::Point2f& p = cur.feats.features[matches[k].cur].pt;
        if (!ok[k] || cv::norm(to[k] - p) > 2.0) continue;  // the patch does not confirm the match
        p = to[k];
        matches[kept++] = matches[k];
      }
      matches.resize(kept);
    }
    r.matches = static_cast<int>(matches.size());
    r.timings.matching = sw.lap();

    // 4. Motion from features with depth in the previous frame (3D -> 2D) and without (2D -> 2D).
    std::vector<Correspondence3D> c3;
    std::vector<Correspondence2D> c2;
    std::vector<int> index3, index2;
    for (size_t m = 0; m < matches.size(); ++m) {
      const Track& tp = prev.tracks[matches[m].prev];
      const cv::Point2f pc = cur.feats.features[matches[m].cur].pt;
      const Eigen::Vector2d xn = cam_.normalise(pc.x, pc.y);
      if (tp.has_depth) {
        c3.push_back({tp.X, xn});
        index3.push_back(static_cast<int>(m));
      } else {
        const cv::Point2f pp = prev.feats.features[matches[m].prev].pt;
        c2.push_back({cam_.normalise(pp.x, pp.y), xn});
        index2.push_back(static_cast<int>(m));
      }
    }
    r.features_3d = static_cast<int>(c3.size());
    r.features_2d = static_cast<int>(c2.size());
    const MotionResult mr = motion_.estimate(cam_, c3, c2, prediction);
    r.timings.motion = sw.lap();

    if (!mr.ok || mr.inliers_3d < params_.lost_min_inliers) {
      r.status = VoStatus::Lost;
      r.message = "tracking lost: " + (mr.ok ? std::to_string(mr.inliers_3d) + " inliers with depth" : mr.failure);
      r.T_world_cam = T_world_cam_;
      r.T_odom_cam = T_odom_cam_;
      r.covariance = covariance_;
      if (r.depth_computed) r.disparity = disparity;
      reset(r.message);
      r.timings.bookkeeping = sw.lap();
      return r;
    }
    r.status = VoStatus::Ok;
    r.inliers = mr.inliers_3d + mr.inliers_2d;
    r.inlier_ratio = matches.empty() ? 0.0 : static_cast<double>(r.inliers) / static_cast<double>(matches.size());
    r.motion = mr.T_next_k;
    last_motion_ = mr.T_next_k;
    last_dt_ = dt;
    // T_odom_{k+1} = T_odom_k * M^-1; covariance to first order in the world frame.
    const geometry::SE3 Minv = mr.T_next_k.inverse();
    const Mat6 A = adjoint(T_odom_cam_) * adjoint(Minv);
    T_odom_cam_ = T_odom_cam_ * Minv;
    covariance_ += A * mr.covariance * A.transpose();

    // 5. Tracks continue through the inlier matches; their depth is carried over (eq. 4.12)
    //    and replaced by the new measurement on depth frames.
    std::vector<int> cur_from_prev(cur.tracks.size(), -1);
    for (size_t k = 0; k < index3.size(); ++k)
      if (mr.inlier_3d[k]) cur_from_prev[matches[index3[k]].cur] = matches[index3[k]].prev;
    for (size_t k = 0; k < index2.size(); ++k)
      if (mr.inlier_2d[k]) cur_from_prev[matches[index2[k]].cur] = matches[index2[k]].prev;
    for (size_t j = 0; j < cur.tracks.size(); ++j) {
      Track& t = cur.tracks[j];
      if (cur_from_prev[j] < 0) {
        t.id = next_track_++;
        continue;
      }
      const Track& tp = prev.tracks[cur_from_prev[j]];
      t.id = tp.id;
      if (tp.has_depth) {
        t.X = mr.T_next_k * tp.X;
        t.has_depth = t.X.z() > 0;
      }
    }
    if (depth_frame) {
      assign_depth(left, right, disparity, scale, refine, cur);
    } else if (refine) {
      // Between dense maps the carried-over depth predicts where each tracked feature lies in
      // the right image; a short search there measures its disparity afresh.
      const double min_disparity = cam_.disparity(params_.max_depth_m);
      for (size_t j = 0; j < cur.tracks.size(); ++j) {
        Track& t = cur.tracks[j];
        if (!t.has_depth) continue;
        const cv::Point2f p = cur.feats.features[j].pt;
        const auto d = refine_disparity(left, right, p, cam_.disparity(t.X.z()));
        if (!d || *d < min_disparity) continue;
        t.X = cam_.triangulate(p.x, p.y, *d);
        t.disparity = *d;
      }
    }

    // 6. Keyframe: few tracks left from the last one, or enough motion since it (taken on a
    //    frame with measured disparities, so that the bundle adjuster gets stereo observations).
    int tracked = 0;
    for (const auto& t : cur.tracks) tracked += std::binary_search(last_kf_tracks_.begin(), last_kf_tracks_.end(), t.id);
    const geometry::SE3 since = T_odom_last_kf_.inverse() * T_odom_cam_;
    const bool want = !have_kf_ || tracked < params_.keyframe_min_tracked ||
                      since.translation().norm() > params_.keyframe_translation_m ||
                      geometry::rotation_angle(since.rotation_matrix()) * 180.0 / M_PI > params_.keyframe_rotation_deg;
    cur.left = left.clone();
    prev_ = std::move(cur);
    prev_utime_ = utime;
    if (want && (depth_frame || refine)) {
      make_keyframe(utime, *prev_);
      r.keyframe = true;
    }
  }

  // 7. Re-anchor on the newest bundle-adjusted keyframe: T_world = T_world_K * T_odom_K^-1 * T_odom.
  if (ba_) {
    std::optional<BaResult> res;
    if (ba_at_next_keyframe())
      res.swap(ba_due_);
    else
      res = ba_->poll();
    if (res) {
      const auto kf = kf_odom_.find(res->keyframe_id);
      if (kf != kf_odom_.end()) {
        anchor_ = std::make_pair(res->T_world_cam, kf->second);
        r.ba_applied = true;
      }
    }
  }
  T_world_cam_ = anchor_ ? anchor_->first * (anchor_->second.inverse() * T_odom_cam_) : T_odom_cam_;
  r.T_world_cam = T_world_cam_;
  r.T_odom_cam = T_odom_cam_;
  r.covariance = covariance_;
  if (r.depth_computed) r.disparity = disparity;
  r.timings.bookkeeping = sw.lap();
  return r;
}

}  // namespace aerie::stereo
