#include "air/mono/local_ba.hpp"

#include <ceres/ceres.h>

#include <cmath>
#include <stdexcept>

#include "air/stereo/cpu_time.hpp"
#include "common/geometry/so3.hpp"

namespace aerie::mono {
namespace {

// [w; t] of T_cam_world: X_c = exp([w]x) X_w + t.
struct Pose {
  double p[6];
};

Pose to_pose(const geometry::SE3& T_world_cam) {
  const geometry::SE3 T = T_world_cam.inverse();
  const Eigen::Vector3d w = geometry::so3_log(T.rotation_matrix());
  return {{w[0], w[1], w[2], T.translation()[0], T.translation()[1], T.translation()[2]}};
}

geometry::SE3 from_pose(const Pose& q) {
  return geometry::SE3::from_rotation_vector(Eigen::Vector3d(q.p[0], q.p[1], q.p[2]),
                                             Eigen::Vector3d(q.p[3], q.p[4], q.p[5]))
      .inverse();
}

// Pinhole reprojection (pixels) of a world point, as air/stereo/ba's left-image residual.
struct Reprojection {
  PinholeCamera cam;
  Eigen::Vector2d uv;
  template <typename T>
  bool operator()(const T* pose, const T* X, T* r) const {
    const geometry::Vec3<T> Xc = geometry::so3_exp<T>(geometry::Vec3<T>(pose[0], pose[1], pose[2])) *
                                     geometry::Vec3<T>(X[0], X[1], X[2]) +
                                 geometry::Vec3<T>(pose[3], pose[4], pose[5]);
    if (Xc[2] < T(1e-6)) return false;
    r[0] = T(cam.fx) * Xc[0] / Xc[2] + T(cam.cx) - T(uv.x());
    r[1] = T(cam.fy) * Xc[1] / Xc[2] + T(cam.cy) - T(uv.y());
    return true;
  }
};

double rms(const BaJob& job, const std::vector<Pose>& poses, const std::vector<Eigen::Vector3d>& X, const PinholeCamera& cam,
           std::vector<double>* errors = nullptr) {
  double s = 0;
  for (const auto& o : job.observations) {
    const Eigen::Vector3d Xc = from_pose(poses[o.keyframe]).inverse() * X[o.landmark];
    const double e = Xc.z() > 0 ? (cam.project(Xc) - o.uv).norm() : 1e6;
    s += e * e;
    if (errors) errors->push_back(e);
  }
  return job.observations.empty() ? 0.0 : std::sqrt(s / static_cast<double>(job.observations.size()));
}

}  // namespace

void LocalBaParams::validate(const std::string& what) const {
  if (window < 3) throw std::invalid_argument(what + ".window: expected >= 3 keyframes (two are held fixed)");
  if (max_iterations < 1) throw std::invalid_argument(what + ".max_iterations: expected >= 1");
  if (!(huber_px > 0) || !(outlier_px > 0)) throw std::invalid_argument(what + ".huber_px/outlier_px: expected > 0");
}

BaOutput local_bundle_adjust(const BaJob& job, const PinholeCamera& cam, const LocalBaParams& params) {
  stereo::CpuStopwatch sw;
  BaOutput out;
  out.generation = job.generation;
  std::vector<Pose> poses;
  for (const auto& k : job.keyframes) poses.push_back(to_pose(k.T_world_cam));
  std::vector<Eigen::Vector3d> X;
  for (const auto& l : job.landmarks) X.push_back(l.X);
  out.initial_rms_px = rms(job, poses, X, cam);

  ceres::Problem problem;
  for (const auto& o : job.observations) {
    auto* cost = new ceres::AutoDiffCostFunction<Reprojection, 2, 6, 3>(new Reprojection{cam, o.uv});
    problem.AddResidualBlock(cost, new ceres::HuberLoss(params.huber_px), poses[o.keyframe].p, X[o.landmark].data());
  }
  for (size_t k = 0; k < job.keyframes.size(); ++k)
    if (job.keyframes[k].fixed && problem.HasParameterBlock(poses[k].p)) problem.SetParameterBlockConstant(poses[k].p);
  ceres::Solver::Options opt;
  opt.linear_solver_type = ceres::DENSE_SCHUR;
  opt.max_num_iterations = params.max_iterations;
  opt.num_threads = 1;  // deterministic, and the BA thread is one core's worth
  opt.logging_type = ceres::SILENT;
  ceres::Solver::Summary summary;
  if (!job.observations.empty()) ceres::Solve(opt, &problem, &summary);

  std::vector<double> errors;
  out.final_rms_px = rms(job, poses, X, cam, &errors);
  std::vector<bool> outlier(job.landmarks.size(), false);
  for (size_t i = 0; i < job.observations.size(); ++i)
    if (errors[i] > params.outlier_px) outlier[job.observations[i].landmark] = true;
  for (size_t k = 0; k < job.keyframes.size(); ++k) out.keyframes.push_back({job.keyframes[k].id, from_pose(poses[k]), job.keyframes[k].fixed});
  for (size_t i = 0; i < job.landmarks.size(); ++i) {
    out.landmarks.push_back({job.landmarks[i].id, X[i]});
    if (outlier[i]) out.outlier_landmarks.push_back(job.landmarks[i].id);
  }
  out.ms = sw.ms();
  return out;
}

LocalBundleAdjuster::LocalBundleAdjuster(const PinholeCamera& cam, const LocalBaParams& params)
    : cam_(cam), params_(params), thread_([this] { run(); }) {}

LocalBundleAdjuster::~LocalBundleAdjuster() {
  {
    std::lock_guard<std::mutex> lock(mutex_);
    stop_ = true;
  }
  wake_.notify_all();
  thread_.join();
}

void LocalBundleAdjuster::submit(BaJob job) {
  {
    std::lock_guard<std::mutex> lock(mutex_);
    job_ = std::move(job);
  }
  wake_.notify_all();
}

void LocalBundleAdjuster::wait_idle() {
  std::unique_lock<std::mutex> lock(mutex_);
  idle_.wait(lock, [this] { return !busy_ && !job_; });
}

std::optional<BaOutput> LocalBundleAdjuster::poll() {
  std::lock_guard<std::mutex> lock(mutex_);
  std::optional<BaOutput> r;
  r.swap(result_);
  return r;
}

void LocalBundleAdjuster::run() {
  for (;;) {
    BaJob job;
    {
      std::unique_lock<std::mutex> lock(mutex_);
      wake_.wait(lock, [this] { return stop_ || job_; });
      if (stop_) return;
      job = std::move(*job_);
      job_.reset();
      busy_ = true;
    }
    BaOutput out = local_bundle_adjust(job, cam_, params_);
    {
      std::lock_guard<std::mutex> lock(mutex_);
      result_ = std::move(out);
      busy_ = false;
    }
    idle_.notify_all();
  }
}

}  // namespace aerie::mono
