#include "tools/eval/metrics.hpp"

#include <Eigen/SVD>
#include <algorithm>
#include <cmath>
#include <numeric>
#include <stdexcept>

namespace aerie::eval {
namespace {

void require_same_length(const Trajectory& ref, const Trajectory& est, const char* what) {
  if (ref.size() != est.size() || ref.empty())
    throw std::invalid_argument(std::string(what) + ": reference has " + std::to_string(ref.size()) +
                                " poses, estimate " + std::to_string(est.size()) + " (associate them first)");
}

constexpr double kRadToDeg = 180.0 / M_PI;

RelativeErrors relative_errors(const Trajectory& ref, const Trajectory& est,
                               std::vector<std::pair<size_t, size_t>> pairs) {
  RelativeErrors out;
  out.pairs = std::move(pairs);
  for (const auto& [i, j] : out.pairs) {
    const geometry::SE3 Q = ref.poses[i].inverse() * ref.poses[j];
    const geometry::SE3 P = est.poses[i].inverse() * est.poses[j];
    const geometry::SE3 E = Q.inverse() * P;
    out.translation.push_back(E.translation().norm());
    out.rotation_deg.push_back(geometry::rotation_angle(E.rotation_matrix()) * kRadToDeg);
    out.ref_distance.push_back(Q.translation().norm());
  }
  return out;
}

}  // namespace

Stats statistics(const std::vector<double>& values) {
  Stats s;
  s.count = values.size();
  if (values.empty()) return s;
  const double n = static_cast<double>(values.size());
  for (double v : values) s.sse += v * v;
  s.mean = std::accumulate(values.begin(), values.end(), 0.0) / n;
  s.rmse = std::sqrt(s.sse / n);
  double var = 0;
  for (double v : values) var += (v - s.mean) * (v - s.mean);
  s.std = std::sqrt(var / n);  // population std, as numpy/evo
  auto sorted = values;
  std::sort(sorted.begin(), sorted.end());
  s.min = sorted.front();
  s.max = sorted.back();
  const size_t m = sorted.size() / 2;
  s.median = sorted.size() % 2 ? sorted[m] : 0.5 * (sorted[m - 1] + sorted[m]);
  return s;
}

Alignment alignment_from_string(const std::string& name) {
  if (name == "none") return Alignment::None;
  if (name == "se3") return Alignment::SE3;
  if (name == "sim3") return Alignment::Sim3;
  throw std::invalid_argument("alignment '" + name + "': expected none, se3 or sim3");
}

Similarity umeyama(const std::vector<Eigen::Vector3d>& est, const std::vector<Eigen::Vector3d>& ref,
                   bool with_scale) {
  if (est.size() != ref.size() || est.size() < 2)
    throw std::invalid_argument("umeyama: need two equally long point sets of at least 2 points");
  const double n = static_cast<double>(est.size());
  Eigen::Vector3d mu_e = Eigen::Vector3d::Zero(), mu_r = Eigen::Vector3d::Zero();
  for (size_t i = 0; i < est.size(); ++i) {
    mu_e += est[i];
    mu_r += ref[i];
  }
  mu_e /= n;
  mu_r /= n;
  Eigen::Matrix3d cov = Eigen::Matrix3d::Zero();
  double var_e = 0;
  for (size_t i = 0; i < est.size(); ++i) {
    cov += (ref[i] - mu_r) * (est[i] - mu_e).transpose();
    var_e += (est[i] - mu_e).squaredNorm();
  }
  cov /= n;
  var_e /= n;
  // Umeyama 1991, eqs. 38-42.
  Eigen::JacobiSVD<Eigen::Matrix3d> svd(cov, Eigen::ComputeFullU | Eigen::ComputeFullV);
  Eigen::Matrix3d S = Eigen::Matrix3d::Identity();
  if (svd.matrixU().determinant() * svd.matrixV().determinant() < 0) S(2, 2) = -1;
  const Eigen::Matrix3d R = svd.matrixU() * S * svd.matrixV().transpose();
  Similarity sim;
  sim.scale = with_scale && var_e > 0 ? (svd.singularValues().asDiagonal() * S).trace() / var_e : 1.0;
  sim.transform = geometry::SE3(R, mu_r - sim.scale * R * mu_e);
  return sim;
}

Trajectory align(const Trajectory& est, const Trajectory& ref, Alignment alignment, Similarity* used) {
  require_same_length(ref, est, "align");
  Similarity sim;
  if (alignment != Alignment::None) {
    std::vector<Eigen::Vector3d> pe, pr;
    for (size_t i = 0; i < est.size(); ++i) {
      pe.push_back(est.poses[i].translation());
      pr.push_back(ref.poses[i].translation());
    }
    sim = umeyama(pe, pr, alignment == Alignment::Sim3);
  }
  if (used) *used = sim;
  Trajectory out;
  for (size_t i = 0; i < est.size(); ++i)
    out.push_back(est.stamps[i], geometry::SE3(sim.transform.rotation() * est.poses[i].rotation(),
                                                sim.apply(est.poses[i].translation())));
  return out;
}

std::vector<double> ate_errors(const Trajectory& ref, const Trajectory& aligned_est) {
  require_same_length(ref, aligned_est, "ATE");
  std::vector<double> e;
  for (size_t i = 0; i < ref.size(); ++i)
    e.push_back((ref.poses[i].translation() - aligned_est.poses[i].translation()).norm());
  return e;
}

double RelativeErrors::translation_percent() const {
  const double err = std::accumulate(translation.begin(), translation.end(), 0.0);
  const double dist = std::accumulate(ref_distance.begin(), ref_distance.end(), 0.0);
  return dist > 0 ? 100.0 * err / dist : 0.0;
}

RelativeErrors rpe_frames(const Trajectory& ref, const Trajectory& est, size_t delta_frames) {
  require_same_length(ref, est, "RPE");
  if (delta_frames == 0) throw std::invalid_argument("RPE: delta must be at least 1 frame");
  std::vector<std::pair<size_t, size_t>> pairs;
  for (size_t i = 0; i + delta_frames < est.size(); ++i) pairs.emplace_back(i, i + delta_frames);
  return relative_errors(ref, est, std::move(pairs));
}

RelativeErrors rpe_path(const Trajectory& ref, const Trajectory& est, double delta_m) {
  require_same_length(ref, est, "RPE");
  if (!(delta_m > 0)) throw std::invalid_argument("RPE: delta must be positive metres");
  // evo filter_pairs_by_path (all_pairs = False): indices where the accumulated path of the
  // estimate reaches delta, then consecutive pairs of those indices.
  std::vector<size_t> ids;
  double path = 0;
  for (size_t i = 1; i < est.size(); ++i) {
    path += (est.poses[i].translation() - est.poses[i - 1].translation()).norm();
    if (path >= delta_m) {
      ids.push_back(i);
      path = 0;
    }
  }
  std::vector<std::pair<size_t, size_t>> pairs;
  for (size_t k = 1; k < ids.size(); ++k) pairs.emplace_back(ids[k - 1], ids[k]);
  return relative_errors(ref, est, std::move(pairs));
}

Eigen::Vector3d roll_pitch_yaw(const Eigen::Matrix3d& R) {
  const double pitch = std::asin(std::clamp(-R(2, 0), -1.0, 1.0));
  const double roll = std::atan2(R(2, 1), R(2, 2));
  const double yaw = std::atan2(R(1, 0), R(0, 0));
  return {roll, pitch, yaw};
}

AxisRmse per_axis_rmse(const Trajectory& ref, const Trajectory& aligned_est) {
  require_same_length(ref, aligned_est, "per-axis RMSE");
  AxisRmse out;
  for (size_t i = 0; i < ref.size(); ++i) {
    const Eigen::Vector3d dp = aligned_est.poses[i].translation() - ref.poses[i].translation();
    out.position += dp.cwiseAbs2();
    // Orientation relative to each trajectory's first pose: a position-only alignment leaves
    // the rotation about a straight path undetermined, the change since the start does not.
    const Eigen::Matrix3d Rr = ref.poses[0].rotation_matrix().transpose() * ref.poses[i].rotation_matrix();
    const Eigen::Matrix3d Re =
        aligned_est.poses[0].rotation_matrix().transpose() * aligned_est.poses[i].rotation_matrix();
    const Eigen::Vector3d rpy = roll_pitch_yaw(Rr.transpose() * Re);
    out.rpy_deg += (rpy * kRadToDeg).cwiseAbs2();
  }
  const double n = static_cast<double>(ref.size());
  out.position = (out.position / n).cwiseSqrt();
  out.rpy_deg = (out.rpy_deg / n).cwiseSqrt();
  return out;
}

bool is_loop(const Trajectory& t) {
  if (t.empty()) return false;
  const double gap = (t.poses.back().translation() - t.poses.front().translation()).norm();
  return gap <= std::max(kLoopRadiusM, kLoopPathFraction * t.path_length());
}

Drift end_point_drift(const Trajectory& ref, const Trajectory& est) {
  if (est.empty()) throw std::invalid_argument("drift: empty estimate");
  Drift d;
  const Eigen::Vector3d est_end = (est.poses.front().inverse() * est.poses.back()).translation();
  d.loop_closure_m = est_end.norm();
  d.loop = is_loop(ref.empty() ? est : ref);
  if (!ref.empty()) {
    require_same_length(ref, est, "drift");
    const Eigen::Vector3d ref_end = (ref.poses.front().inverse() * ref.poses.back()).translation();
    d.vs_reference_m = (est_end - ref_end).norm();
    d.distance_m = ref.path_length();
  } else {
    d.vs_reference_m = d.loop_closure_m;
    d.distance_m = est.path_length();
  }
  return d;
}

}  // namespace aerie::eval
