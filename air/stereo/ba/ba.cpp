#include "air/stereo/ba/ba.hpp"

#include <ceres/ceres.h>

#include <cmath>
#include <map>
#include <stdexcept>

#include "air/stereo/cpu_time.hpp"
#include "common/geometry/so3.hpp"

namespace aerie::stereo {
namespace {

// Pose parameters: [w; t] of T_cam_world, X_c = exp([w]x) X_w + t.
struct PoseParams {
  double w[3];
  double t[3];
};

PoseParams to_params(const geometry::SE3& T_world_cam) {
  const geometry::SE3 T = T_world_cam.inverse();
  const Eigen::Vector3d w = geometry::so3_log(T.rotation_matrix());
  PoseParams p{};
  for (int i = 0; i < 3; ++i) {
    p.w[i] = w[i];
    p.t[i] = T.translation()[i];
  }
  return p;
}

geometry::SE3 from_params(const PoseParams& p) {
  return geometry::SE3::from_rotation_vector(Eigen::Vector3d(p.w[0], p.w[1], p.w[2]),
                                             Eigen::Vector3d(p.t[0], p.t[1], p.t[2]))
      .inverse();
}

// Reprojection of a world point into the left camera (and the right one when the
// observation has a disparity): residuals in pixels.
template <int kResiduals>
struct Reprojection {
  StereoCamera cam;
  Eigen::Vector2d uv;
  double u_right;
  template <typename T>
  bool operator()(const T* w, const T* t, const T* X, T* r) const {
    const geometry::Vec3<T> Xc =
        geometry::so3_exp<T>(geometry::Vec3<T>(w[0], w[1], w[2])) * geometry::Vec3<T>(X[0], X[1], X[2]) +
        geometry::Vec3<T>(t[0], t[1], t[2]);
    if (Xc[2] < T(1e-3)) return false;  // behind the camera: let the solver step back
    const T inv_z = T(1) / Xc[2];
    r[0] = T(cam.fx) * Xc[0] * inv_z + T(cam.cx) - T(uv.x());
    r[1] = T(cam.fy) * Xc[1] * inv_z + T(cam.cy) - T(uv.y());
    if constexpr (kResiduals == 3) r[2] = T(cam.fx) * (Xc[0] - T(cam.baseline)) * inv_z + T(cam.cx) - T(u_right);
    return true;
  }
};

}  // namespace

void BaParams::validate(const std::string& what) const {
  if (window < 2) throw std::invalid_argument(what + ".window: at least 2 keyframes");
  if (max_iterations < 1) throw std::invalid_argument(what + ".max_iterations: >= 1");
  if (!(huber_px > 0) || !(outlier_px > 0)) throw std::invalid_argument(what + ".huber_px/outlier_px: > 0");
  if (min_observations < 2) throw std::invalid_argument(what + ".min_observations: >= 2");
  if (!(max_depth_m > 0)) throw std::invalid_argument(what + ".max_depth_m: > 0");
}

BaResult bundle_adjust(const std::vector<Keyframe>& window, const std::vector<geometry::SE3>& poses,
                       const StereoCamera& cam, const BaParams& params) {
  if (window.size() != poses.size()) throw std::invalid_argument("bundle_adjust: one pose per keyframe expected");
  CpuStopwatch sw;
  BaResult res;
  if (window.empty()) return res;
  res.keyframe_id = window.back().id;

  // Tracks seen by enough keyframes, started from their first stereo observation.
  struct Seen {
    std::vector<std::pair<size_t, const KeyframeObservation*>> obs;
  };
  std::map<int64_t, Seen> tracks;
  for (size_t k = 0; k < window.size(); ++k)
    for (const auto& o : window[k].observations) tracks[o.track].obs.emplace_back(k, &o);
  const double min_disp = cam.disparity(params.max_depth_m);

  std::vector<PoseParams> pp;
  for (const auto& T : poses) pp.push_back(to_params(T));
  std::vector<Eigen::Vector3d> points;
  points.reserve(tracks.size());

  ceres::Problem::Options popts;
  popts.loss_function_ownership = ceres::DO_NOT_TAKE_OWNERSHIP;
  popts.enable_fast_removal = true;
  ceres::Problem problem(popts);
  std::vector<ceres::ResidualBlockId> blocks;
  ceres::HuberLoss loss(params.huber_px);
  for (auto& [id, seen] : tracks) {
    if (static_cast<int>(seen.obs.size()) < params.min_observations) continue;
    const KeyframeObservation* first = nullptr;
    size_t kf = 0;
    for (const auto& [k, o] : seen.obs)
      if (o->disparity > min_disp) {
        first = o;
        kf = k;
        break;
      }
    if (!first) continue;
    points.push_back(poses[kf] * cam.triangulate(first->uv.x(), first->uv.y(), first->disparity));
    double* X = points.back().data();
    for (const auto& [k, o] : seen.obs) {
      ceres::CostFunction* cf;
      if (o->disparity > min_disp) {
        cf = new ceres::AutoDiffCostFunction<Reprojection<3>, 3, 3, 3, 3>(
            new Reprojection<3>{cam, o->uv, o->uv.x() - o->disparity});
        res.residuals += 3;
      } else {
        cf = new ceres::AutoDiffCostFunction<Reprojection<2>, 2, 3, 3, 3>(new Reprojection<2>{cam, o->uv, 0.0});
        res.residuals += 2;
      }
      blocks.push_back(problem.AddResidualBlock(cf, &loss, pp[k].w, pp[k].t, X));
    }
    ++res.landmarks;
  }
  if (res.landmarks == 0 || window.size() < 2) {
    res.T_world_cam = poses.back();
    for (size_t k = 0; k < window.size(); ++k) res.window.emplace_back(window[k].id, poses[k]);
    res.ms = sw.ms();
    return res;
  }
  // Gauge: the oldest keyframe in the problem stays where the window found it (keyframes
  // sharing no track with the others are not in the problem and keep their poses).
  for (auto& p : pp)
    if (problem.HasParameterBlock(p.w)) {
      problem.SetParameterBlockConstant(p.w);
      problem.SetParameterBlockConstant(p.t);
      break;
    }
  ceres::Solver::Options opts;
  opts.linear_solver_type = ceres::DENSE_SCHUR;
  opts.max_num_iterations = params.max_iterations;
  opts.logging_type = ceres::SILENT;
  opts.num_threads = 1;
  // Solve, drop the observations still off by more than outlier_px (mismatched tracks), solve again.
  ceres::Solver::Summary summary;
  ceres::Solve(opts, &problem, &summary);
  res.initial_rms_px = std::sqrt(2.0 * summary.initial_cost / std::max(1, res.residuals));
  for (const auto id : blocks) {
    double r[3] = {0, 0, 0}, cost = 0;
    problem.EvaluateResidualBlock(id, false, &cost, r, nullptr);
    if (r[0] * r[0] + r[1] * r[1] + r[2] * r[2] > params.outlier_px * params.outlier_px) {
      res.residuals -= problem.GetCostFunctionForResidualBlock(id)->num_residuals();
      problem.RemoveResidualBlock(id);
      ++res.outliers;
    }
  }
  if (res.outliers > 0) ceres::Solve(opts, &problem, &summary);
  res.final_rms_px = std::sqrt(2.0 * summary.final_cost / std::max(1, res.residuals));
  for (size_t k = 0; k < window.size(); ++k) res.window.emplace_back(window[k].id, from_params(pp[k]));
  res.T_world_cam = res.window.back().second;
  res.ms = sw.ms();
  return res;
}

BundleAdjuster::BundleAdjuster(const StereoCamera& cam, const BaParams& params) : cam_(cam), params_(params) {
  params_.validate();
  cam_.validate("bundle adjustment camera");
  thread_ = std::thread([this] { run(); });
}

BundleAdjuster::~BundleAdjuster() {
  {
    std::lock_guard lock(mutex_);
    stop_ = true;
  }
  wake_.notify_all();
  thread_.join();
}

void BundleAdjuster::add_keyframe(Keyframe kf) {
  {
    std::lock_guard lock(mutex_);
    queue_.push_back(std::move(kf));
  }
  wake_.notify_one();
}

std::optional<BaResult> BundleAdjuster::poll() {
  std::lock_guard lock(mutex_);
  std::optional<BaResult> r;
  r.swap(result_);
  return r;
}

void BundleAdjuster::wait_idle() {
  std::unique_lock lock(mutex_);
  idle_.wait(lock, [this] { return (queue_.empty() && !busy_) || stop_; });
}

void BundleAdjuster::reset() {
  std::lock_guard lock(mutex_);
  queue_.clear();
  result_.reset();
  reset_ = true;
}

void BundleAdjuster::run() {
  for (;;) {
    std::vector<Keyframe> fresh;
    {
      std::unique_lock lock(mutex_);
      wake_.wait(lock, [this] { return stop_ || reset_ || !queue_.empty(); });
      if (stop_) break;
      if (reset_) {
        window_.clear();
        poses_.clear();
        reset_ = false;
      }
      // Everything queued joins the window at once: when the optimisation is slower than
      // the keyframe rate, intermediate solutions are skipped, never the keyframes.
      fresh.assign(std::make_move_iterator(queue_.begin()), std::make_move_iterator(queue_.end()));
      queue_.clear();
      busy_ = true;
    }
    for (auto& kf : fresh) {
      // A new keyframe starts from the refined pose of the previous one and the odometry
      // between the two.
      const geometry::SE3 T = window_.empty()
                                  ? kf.T_odom_cam
                                  : poses_.back() * (window_.back().T_odom_cam.inverse() * kf.T_odom_cam);
      window_.push_back(std::move(kf));
      poses_.push_back(T);
      while (static_cast<int>(window_.size()) > params_.window) {
        window_.pop_front();
        poses_.pop_front();
      }
    }
    std::optional<BaResult> out;
    if (window_.size() >= 2) {
      const std::vector<Keyframe> win(window_.begin(), window_.end());
      const std::vector<geometry::SE3> init(poses_.begin(), poses_.end());
      BaResult r = bundle_adjust(win, init, cam_, params_);
      for (size_t k = 0; k < r.window.size(); ++k) poses_[k] = r.window[k].second;
      out = std::move(r);
    }
    {
      std::lock_guard lock(mutex_);
      if (out && !reset_) result_ = std::move(out);
      busy_ = false;
    }
    idle_.notify_all();
  }
  idle_.notify_all();
}

}  // namespace aerie::stereo
