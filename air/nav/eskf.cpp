#include "air/nav/eskf.hpp"

#include <algorithm>
#include <cmath>
#include <stdexcept>

#include "common/geometry/so3.hpp"

namespace aerie::nav {
namespace {

using Vec6 = Eigen::Matrix<double, 6, 1>;
using Mat6x15 = Eigen::Matrix<double, 6, 15>;

Mat3 hat(const Vec3& w) { return geometry::hat<double>(w); }
Mat3 Exp(const Vec3& w) { return geometry::so3_exp<double>(w); }
Eigen::Quaterniond ExpQ(const Vec3& w) { return Eigen::Quaterniond(Exp(w)).normalized(); }

std::string utime_str(int64_t t) { return std::to_string(t); }
std::string fmt(double v, int prec = 3) {
  char buf[64];
  std::snprintf(buf, sizeof(buf), "%.*f", prec, v);
  return buf;
}

Outcome refuse(std::string why) { return {false, std::move(why)}; }

}  // namespace

ImuSample interpolate_imu(const ImuSample& a, const ImuSample& b, int64_t t, bool hold) {
  ImuSample c = a;
  c.utime = t;
  if (!hold) {
    const double l = static_cast<double>(t - a.utime) / static_cast<double>(b.utime - a.utime);
    c.gyro = a.gyro + l * (b.gyro - a.gyro);
    c.accel = a.accel + l * (b.accel - a.accel);
  }
  return c;
}

const char* to_string(NavStatus s) {
  switch (s) {
    case NavStatus::Initialising: return "INITIALISING";
    case NavStatus::Ok: return "OK";
    case NavStatus::ImuOnly: return "IMU_ONLY";
    case NavStatus::Lost: return "LOST";
  }
  return "?";
}

void EskfParams::validate() const {
  auto positive = [](double v, const char* name) {
    if (!(v > 0.0) || !std::isfinite(v)) throw std::invalid_argument(std::string("nav: ") + name + " must be > 0");
  };
  auto non_negative = [](double v, const char* name) {
    if (!(v >= 0.0) || !std::isfinite(v)) throw std::invalid_argument(std::string("nav: ") + name + " must be >= 0");
  };
  positive(gravity_m_s2, "gravity_m_s2");
  positive(gyro_noise_density, "imu.gyro_noise_density");
  positive(gyro_random_walk, "imu.gyro_random_walk");
  positive(accel_noise_density, "imu.accel_noise_density");
  positive(accel_random_walk, "imu.accel_random_walk");
  positive(max_imu_dt_s, "imu.max_dt_s");
  positive(max_gyro_rad_s, "imu.max_gyro_rad_s");
  positive(max_accel_m_s2, "imu.max_accel_m_s2");
  positive(static_window_s, "alignment.window_s");
  positive(static_max_gyro_std_rad_s, "alignment.max_gyro_std_rad_s");
  positive(static_max_accel_std_m_s2, "alignment.max_accel_std_m_s2");
  if (!std::isfinite(initial_yaw_rad)) throw std::invalid_argument("nav: alignment.yaw_deg must be finite");
  non_negative(init_position_sigma_m, "alignment.position_sigma_m");
  non_negative(init_velocity_sigma_m_s, "alignment.velocity_sigma_m_s");
  non_negative(init_yaw_sigma_rad, "alignment.yaw_sigma_deg");
  non_negative(init_gyro_bias_sigma_rad_s, "alignment.gyro_bias_sigma_rad_s");
  non_negative(init_accel_bias_sigma_m_s2, "alignment.accel_bias_sigma_m_s2");
  positive(vo_rotation_sigma_rad, "vo.rotation_sigma_deg");
  positive(vo_position_sigma_m, "vo.position_sigma_m");
  if (!std::isfinite(gate_chi2)) throw std::invalid_argument("nav: vo.gate_chi2 must be finite");
  positive(imu_only_after_s, "outage.imu_only_after_s");
  if (!(lost_after_s > imu_only_after_s)) throw std::invalid_argument("nav: outage.lost_after_s must be > outage.imu_only_after_s");
  positive(buffer_s, "buffer_s");
  if (max_pending_vo < 0) throw std::invalid_argument("nav: max_pending_vo must be >= 0");
  if (!T_body_cam.translation().allFinite() || !T_world_vo.translation().allFinite())
    throw std::invalid_argument("nav: T_body_cam / T_world_vo must be finite");
}

Eskf::Eskf(EskfParams params) : p_(std::move(params)) { p_.validate(); }

// ---------------------------------------------------------------------------------------------
// IMU

Outcome check_imu(const EskfParams& p, const ImuSample& s, std::optional<int64_t> prev, bool aligned,
                  EskfCounters& counters) {
  // Message time is microseconds since an epoch: never negative. Refusing it keeps every
  // difference of two accepted times inside int64 (a first sample at INT64_MIN made the next
  // gap overflow: the nav fuzzer).
  if (s.utime < 0) {
    ++counters.imu_negative_time;
    return refuse("IMU sample at utime " + utime_str(s.utime) + ": negative time");
  }
  if (!s.gyro.allFinite() || !s.accel.allFinite()) {
    ++counters.imu_non_finite;
    return refuse("IMU sample at utime " + utime_str(s.utime) + ": non-finite gyro or accel (NaN/Inf)");
  }
  if (s.gyro.cwiseAbs().maxCoeff() > p.max_gyro_rad_s || s.accel.cwiseAbs().maxCoeff() > p.max_accel_m_s2) {
    ++counters.imu_out_of_range;
    return refuse("IMU sample at utime " + utime_str(s.utime) + ": beyond max_gyro_rad_s " + fmt(p.max_gyro_rad_s, 1) +
                  " or max_accel_m_s2 " + fmt(p.max_accel_m_s2, 1));
  }
  if (prev && s.utime <= *prev) {
    ++counters.imu_time_not_increasing;
    return refuse("IMU sample at utime " + utime_str(s.utime) + " is not after the previous one (" + utime_str(*prev) +
                  "): time went back or repeated");
  }
  ++counters.imu_accepted;
  const int64_t max_dt_us = static_cast<int64_t>(std::llround(p.max_imu_dt_s * 1e6));
  Outcome o{true, ""};
  if (prev && s.utime - *prev > max_dt_us) {
    ++counters.imu_gaps;
    o.reason = "IMU gap of " + fmt((s.utime - *prev) * 1e-6) + " s > max_imu_dt_s " + fmt(p.max_imu_dt_s) +
               (aligned ? ": bridged by holding the previous sample" : ": static alignment restarted");
  }
  return o;
}

Outcome Eskf::add_imu(const ImuSample& s) {
  std::optional<int64_t> prev;
  if (initialised()) prev = history_.back().imu.utime;
  else if (!static_.empty()) prev = static_.back().utime;
  const Outcome o = check_imu(p_, s, prev, initialised(), counters_);
  if (!o.accepted) return o;
  if (!initialised()) {
    try_align(s);
    return o;
  }
  history_.push_back(Checkpoint{s, x_, P_, anchor_, last_update_utime_});
  advance(history_.size() - 2);
  trim();
  return o;
}

void Eskf::try_align(const ImuSample& s) {
  const int64_t max_dt_us = static_cast<int64_t>(std::llround(p_.max_imu_dt_s * 1e6));
  if (!static_.empty() && s.utime - static_.back().utime > max_dt_us) static_.clear();
  static_.push_back(s);
  if (static_cast<double>(static_.back().utime - static_.front().utime) < p_.static_window_s * 1e6) return;

  const double n = static_cast<double>(static_.size());
  Vec3 mg = Vec3::Zero(), ma = Vec3::Zero();
  for (const auto& x : static_) {
    mg += x.gyro;
    ma += x.accel;
  }
  mg /= n;
  ma /= n;
  Vec3 vg = Vec3::Zero(), va = Vec3::Zero();
  for (const auto& x : static_) {
    vg += (x.gyro - mg).cwiseAbs2();
    va += (x.accel - ma).cwiseAbs2();
  }
  const Vec3 sg = (vg / n).cwiseSqrt(), sa = (va / n).cwiseSqrt();
  const double g = p_.gravity_m_s2;
  if (sg.maxCoeff() > p_.static_max_gyro_std_rad_s || sa.maxCoeff() > p_.static_max_accel_std_m_s2 ||
      ma.norm() < 0.5 * g || ma.norm() > 1.5 * g) {
    ++counters_.static_windows_rejected;  // moving (or not gravity): start a new window
    static_.clear();
    return;
  }

  // Gravity alignment: at rest the specific force is R^T (0, 0, g), so
  // a = g (-sin(pitch), sin(roll) cos(pitch), cos(roll) cos(pitch)) with R = Rz(yaw) Ry(pitch) Rx(roll).
  Alignment al;
  al.utime = s.utime;
  al.samples = static_cast<int>(static_.size());
  al.mean_gyro = mg;
  al.mean_accel = ma;
  al.std_gyro = sg;
  al.std_accel = sa;
  al.roll_rad = std::atan2(ma.y(), ma.z());
  al.pitch_rad = std::atan2(-ma.x(), std::hypot(ma.y(), ma.z()));

  NominalState x;
  x.utime = s.utime;
  x.q = Eigen::Quaterniond(Eigen::AngleAxisd(p_.initial_yaw_rad, Vec3::UnitZ()) *
                           Eigen::AngleAxisd(al.pitch_rad, Vec3::UnitY()) * Eigen::AngleAxisd(al.roll_rad, Vec3::UnitX()));
  x.bg = mg;  // gyro bias = mean static gyro reading
  x.ba = Vec3::Zero();

  // Initial covariance. An accelerometer bias is indistinguishable from a tilt while static:
  // with u = R^T e_z (up in the body), g [u]x dtheta = -db_a, so dtheta_perp = [u]x db_a / g;
  // yaw (about u) is unobserved and gets its own sigma.
  Mat15 P = Mat15::Zero();
  const Vec3 u = x.q.toRotationMatrix().transpose() * Vec3::UnitZ();
  const Mat3 Sba = std::pow(p_.init_accel_bias_sigma_m_s2, 2) * Mat3::Identity();
  const Mat3 A = hat(u) / g;
  P.block<3, 3>(kP, kP) = std::pow(p_.init_position_sigma_m, 2) * Mat3::Identity();
  P.block<3, 3>(kV, kV) = std::pow(p_.init_velocity_sigma_m_s, 2) * Mat3::Identity();
  P.block<3, 3>(kTheta, kTheta) = A * Sba * A.transpose() + std::pow(p_.init_yaw_sigma_rad, 2) * u * u.transpose();
  P.block<3, 3>(kTheta, kBa) = A * Sba;
  P.block<3, 3>(kBa, kTheta) = (A * Sba).transpose();
  P.block<3, 3>(kBa, kBa) = Sba;
  P.block<3, 3>(kBg, kBg) = std::pow(p_.init_gyro_bias_sigma_rad_s, 2) * Mat3::Identity();

  alignment_ = al;
  static_.clear();
  initialise(x, P, s);
}

void Eskf::initialise(const NominalState& x, const Mat15& P, const ImuSample& first) {
  x_ = x;
  x_.utime = first.utime;
  x_.q.normalize();
  P_ = P;
  anchor_.reset();
  last_update_utime_ = first.utime;
  vo_.clear();
  history_.clear();
  history_.push_back(Checkpoint{first, x_, P_, anchor_, last_update_utime_});
}

void Eskf::resume(const Snapshot& s, const ImuSample& first, const GapNoise& gap) {
  const double dt = static_cast<double>(first.utime - s.x.utime) * 1e-6;
  if (!(dt >= 0.0)) throw std::invalid_argument("the IMU sample to resume at is before the snapshot");
  NominalState x = s.x;
  x.p += x.v * dt;
  x.q = (x.q * ExpQ((first.gyro - x.bg) * dt)).normalized();
  // A constant unknown acceleration a ~ N(0, sa^2 I) over dt adds a dt^2/2 to p and a dt to v;
  // a constant unknown rate w ~ N(0, sw^2 I) adds w dt to the attitude error.
  const double sa2 = gap.accel_sigma_m_s2 * gap.accel_sigma_m_s2, sw2 = gap.rate_sigma_rad_s * gap.rate_sigma_rad_s;
  Mat15 F = Mat15::Identity();  // the coasting's Jacobian: dp += dv dt
  F.block<3, 3>(kP, kV) = dt * Mat3::Identity();
  Mat15 P = F * s.P * F.transpose();
  P.block<3, 3>(kP, kP) += sa2 * std::pow(dt, 4) / 4.0 * Mat3::Identity();
  P.block<3, 3>(kP, kV) += sa2 * std::pow(dt, 3) / 2.0 * Mat3::Identity();
  P.block<3, 3>(kV, kP) += sa2 * std::pow(dt, 3) / 2.0 * Mat3::Identity();
  P.block<3, 3>(kV, kV) += sa2 * dt * dt * Mat3::Identity();
  P.block<3, 3>(kTheta, kTheta) += sw2 * dt * dt * Mat3::Identity();
  initialise(x, P, first);
  anchor_ = s.T_world_vo;
  last_update_utime_ = s.last_update_utime;
  history_.back().anchor = anchor_;
  history_.back().last_update_utime = last_update_utime_;
  ++counters_.resumed;
}

// Propagation from sample a to sample b (b may be an interpolated sample). The nominal state
// follows [S eq. 260] integrated with the mean of the two samples (midpoint / trapezoid, second
// order); the error covariance P <- F P F^T + Q with F of [S eq. 269] and the noise of
// [S eqs. 270-273] from continuous densities (variance = density^2 dt).
bool imu_step(const EskfParams& p, NominalState& x, const ImuSample& a, const ImuSample& b, Mat15& F, Mat15& Q) {
  const double dt = static_cast<double>(b.utime - a.utime) * 1e-6;
  if (dt <= 0.0) return false;
  const Vec3 g(0.0, 0.0, -p.gravity_m_s2);
  const Vec3 wa = a.gyro - x.bg, wb = b.gyro - x.bg;
  const Vec3 fa = a.accel - x.ba, fb = b.accel - x.ba;
  const Vec3 w = 0.5 * (wa + wb);
  const Vec3 f = 0.5 * (fa + fb);
  const Mat3 Ra = x.q.toRotationMatrix();
  const Mat3 dR = Exp(w * dt);

  // Nominal state [S eq. 260]: q <- q (x) q{w dt}; a_world = R (a_m - a_b) + g.
  x.q = (x.q * Eigen::Quaterniond(dR)).normalized();
  const Mat3 Rb = x.q.toRotationMatrix();
  const Vec3 acc = 0.5 * ((Ra * fa + g) + (Rb * fb + g));
  x.p += x.v * dt + 0.5 * acc * dt * dt;
  x.v += acc * dt;
  x.utime = b.utime;

  // Error-state transition [S eq. 269] (local attitude error).
  F = Mat15::Identity();
  F.block<3, 3>(kP, kV) = Mat3::Identity() * dt;
  F.block<3, 3>(kV, kTheta) = -Ra * hat(f) * dt;
  F.block<3, 3>(kV, kBa) = -Ra * dt;
  F.block<3, 3>(kTheta, kTheta) = dR.transpose();
  F.block<3, 3>(kTheta, kBg) = -Mat3::Identity() * dt;
  // Impulse covariances [S eqs. 270-273].
  Q = Mat15::Zero();
  Q.block<3, 3>(kV, kV) = std::pow(p.accel_noise_density, 2) * dt * Mat3::Identity();
  Q.block<3, 3>(kTheta, kTheta) = std::pow(p.gyro_noise_density, 2) * dt * Mat3::Identity();
  Q.block<3, 3>(kBg, kBg) = std::pow(p.gyro_random_walk, 2) * dt * Mat3::Identity();
  Q.block<3, 3>(kBa, kBa) = std::pow(p.accel_random_walk, 2) * dt * Mat3::Identity();
  return true;
}

void Eskf::propagate(const ImuSample& a, const ImuSample& b) {
  Mat15 F, Q;
  if (!imu_step(p_, x_, a, b, F, Q)) return;
  P_ = F * P_ * F.transpose() + Q;
  P_ = 0.5 * (P_ + P_.transpose());
}

void Eskf::advance(size_t j) {
  const ImuSample a = history_[j].imu;
  const ImuSample b = history_[j + 1].imu;
  const bool hold = static_cast<double>(b.utime - a.utime) > p_.max_imu_dt_s * 1e6;  // a gap
  const ImuSample b_used = hold ? interpolate_imu(a, b, b.utime, true) : b;
  ImuSample cur = a;
  if (hold) cur = interpolate_imu(a, b, a.utime, true);
  // VO poses strictly between the two samples: propagate to each, update.
  for (auto it = vo_.upper_bound(a.utime); it != vo_.end() && it->first < b.utime; ++it) {
    const ImuSample c = interpolate_imu(a, b, it->first, hold);
    propagate(cur, c);
    cur = c;
    apply(it->second);
  }
  propagate(cur, b_used);
  x_.utime = b.utime;
  history_[j + 1] = Checkpoint{b, x_, P_, anchor_, last_update_utime_};
  apply_vo_at(b.utime);
}

void Eskf::apply_vo_at(int64_t utime) {
  const auto it = vo_.find(utime);
  if (it != vo_.end()) apply(it->second);
}

void Eskf::replay_from(size_t i) {
  const Checkpoint& c = history_[i];
  x_ = c.x;
  P_ = c.P;
  anchor_ = c.anchor;
  last_update_utime_ = c.last_update_utime;
  apply_vo_at(c.imu.utime);
  for (size_t j = i; j + 1 < history_.size(); ++j) advance(j);
}

void Eskf::trim() {
  const int64_t limit = history_.back().imu.utime - static_cast<int64_t>(std::llround(p_.buffer_s * 1e6));
  while (history_.size() > 1 && history_[1].imu.utime <= limit) history_.pop_front();
  const int64_t front = history_.front().imu.utime;
  while (!vo_.empty() && vo_.begin()->first < front) vo_.erase(vo_.begin());
}

// ---------------------------------------------------------------------------------------------
// VO

geometry::SE3 Eskf::camera_pose() const { return geometry::SE3(x_.q, x_.p) * p_.T_body_cam; }

Mat6 Eskf::measurement_covariance(const VoMeasurement& m) const {
  const Mat3 Rwv = (p_.vo_frame == VoFrame::Fixed ? p_.T_world_vo : *anchor_).rotation_matrix();
  if (p_.vo_noise == VoNoise::Message && m.covariance) {
    const Mat6 S = 0.5 * (*m.covariance + m.covariance->transpose());
    if (Eigen::LLT<Mat6>(S).info() == Eigen::Success) {
      // pose_t's xi = [phi; rho] is a left SE(3) perturbation: to first order the position
      // error is dp = rho + phi x t = rho - [t]x phi. Then both rotate from V into W.
      Mat6 J = Mat6::Identity();
      J.block<3, 3>(3, 0) = -hat(m.T_vo_cam.translation());
      Mat6 A = Mat6::Zero();
      A.block<3, 3>(0, 0) = Rwv;
      A.block<3, 3>(3, 3) = Rwv;
      const Mat6 JA = A * J;
      return JA * S * JA.transpose();
    }
  }
  Mat6 R = Mat6::Zero();
  R.block<3, 3>(0, 0) = std::pow(p_.vo_rotation_sigma_rad, 2) * Mat3::Identity();
  R.block<3, 3>(3, 3) = std::pow(p_.vo_position_sigma_m, 2) * Mat3::Identity();
  return R;
}

void Eskf::set_outcome(VoRecord& r, VoOutcome o) {
  auto counter = [this](VoOutcome k) -> int64_t* {
    switch (k) {
      case VoOutcome::Applied: return &counters_.vo_applied;
      case VoOutcome::Gated: return &counters_.vo_gated;
      case VoOutcome::Anchored: return &counters_.vo_anchors;
      case VoOutcome::Pending: return nullptr;
    }
    return nullptr;
  };
  if (int64_t* c = counter(r.outcome)) --*c;
  if (int64_t* c = counter(o)) ++*c;
  r.outcome = o;
}

// The VO update: measurement h(x) = T_world_vo^-1 T_world_body(x) T_body_cam, residual on
// SE(3) in the world frame: r_theta = Log(R_wc_meas R_wc^T), r_p = p_wc_meas - p_wc.
// With q_true = q (x) Exp(dtheta): R_wc_true R_wc^T = Exp(R dtheta) and
// p_wc_true = p + dp + R Exp(dtheta) p_bc ~ p_wc + dp - R [p_bc]x dtheta, which gives H.
// Update [S eqs. 274-276] (Joseph form), injection [S eq. 283], reset [S eqs. 285-287].
void Eskf::apply(VoRecord& rec) {
  const VoMeasurement& m = rec.m;
  if (p_.vo_frame == VoFrame::Anchor && (!anchor_ || m.restart)) {
    // T_world_vo such that this pose agrees with the current estimate.
    anchor_ = camera_pose() * m.T_vo_cam.inverse();
    set_outcome(rec, VoOutcome::Anchored);
    return;
  }
  const geometry::SE3& T_wv = p_.vo_frame == VoFrame::Fixed ? p_.T_world_vo : *anchor_;
  const geometry::SE3 T_wc_meas = T_wv * m.T_vo_cam;
  const geometry::SE3 T_wc = camera_pose();
  const Mat3 R = x_.q.toRotationMatrix();
  const Vec3 p_bc = p_.T_body_cam.translation();

  Vec6 r;
  r.head<3>() = geometry::so3_log(T_wc_meas.rotation_matrix() * T_wc.rotation_matrix().transpose());
  r.tail<3>() = T_wc_meas.translation() - T_wc.translation();
  Mat6x15 H = Mat6x15::Zero();
  H.block<3, 3>(0, kTheta) = R;
  H.block<3, 3>(3, kP) = Mat3::Identity();
  H.block<3, 3>(3, kTheta) = -R * hat(p_bc);

  const Mat6 Rn = measurement_covariance(m);
  const Mat6 S = H * P_ * H.transpose() + Rn;
  const Eigen::LLT<Mat6> llt(S);
  const double d2 = llt.info() == Eigen::Success ? r.dot(llt.solve(r)) : INFINITY;
  last_d2_ = d2;
  if (!std::isfinite(d2) || (p_.gate_chi2 > 0.0 && d2 > p_.gate_chi2)) {  // Mahalanobis gate
    set_outcome(rec, VoOutcome::Gated);
    return;
  }
  const Eigen::Matrix<double, 15, 6> K = P_ * H.transpose() * llt.solve(Mat6::Identity());  // [S eq. 274]
  const Eigen::Matrix<double, 15, 1> dx = K * r;                                             // [S eq. 275]
  const Mat15 IKH = Mat15::Identity() - K * H;
  P_ = IKH * P_ * IKH.transpose() + K * Rn * K.transpose();  // [S eq. 276], Joseph form

  // Injection [S eq. 283].
  const Vec3 dtheta = dx.segment<3>(kTheta);
  x_.p += dx.segment<3>(kP);
  x_.v += dx.segment<3>(kV);
  x_.q = (x_.q * ExpQ(dtheta)).normalized();
  x_.bg += dx.segment<3>(kBg);
  x_.ba += dx.segment<3>(kBa);
  // Reset [S eq. 287]: G = diag(I, I, I - [dtheta/2]x, I, I).
  Mat15 G = Mat15::Identity();
  G.block<3, 3>(kTheta, kTheta) = Mat3::Identity() - hat(0.5 * dtheta);
  P_ = G * P_ * G.transpose();
  P_ = 0.5 * (P_ + P_.transpose());
  last_update_utime_ = std::max(last_update_utime_, m.utime);
  set_outcome(rec, VoOutcome::Applied);
}

Outcome Eskf::add_vo(const VoMeasurement& m) {
  const std::string what = "VO pose at utime " + utime_str(m.utime);
  if (!initialised()) {
    ++counters_.vo_before_alignment;
    return refuse(what + ": before the static alignment has finished");
  }
  const Eigen::Quaterniond& q = m.T_vo_cam.rotation();
  if (!m.T_vo_cam.translation().allFinite() || !q.coeffs().allFinite() ||
      (m.covariance && !m.covariance->allFinite())) {
    ++counters_.vo_invalid;
    return refuse(what + ": non-finite position, orientation or covariance");
  }
  const int64_t front = history_.front().imu.utime;
  if (m.utime < front) {
    ++counters_.vo_too_old;
    return refuse(what + ": older than the buffer (starts at " + utime_str(front) + ", buffer_s " + fmt(p_.buffer_s, 2) +
                  ")");
  }
  if (vo_.count(m.utime)) {
    ++counters_.vo_duplicate;
    return refuse(what + ": a pose with this utime was already received");
  }
  const int64_t newest = history_.back().imu.utime;
  if (m.utime > newest) {
    const auto pending = std::distance(vo_.upper_bound(newest), vo_.end());
    if (pending >= p_.max_pending_vo) {
      ++counters_.vo_pending_dropped;
      return refuse(what + ": ahead of the IMU (newest sample " + utime_str(newest) + ") with " +
                    std::to_string(pending) + " poses already waiting (max_pending_vo)");
    }
  }
  if (m.utime < newest_vo_utime_) ++counters_.vo_out_of_order;
  newest_vo_utime_ = std::max(newest_vo_utime_, m.utime);
  vo_.emplace(m.utime, VoRecord{m, VoOutcome::Pending});
  if (m.utime > newest) return {true, ""};  // applied when the IMU reaches it
  if (m.utime < newest) ++counters_.vo_delayed;
  // The last checkpoint at or before the pose: restore it, re-run everything after it.
  const auto it = std::upper_bound(history_.begin(), history_.end(), m.utime,
                                   [](int64_t t, const Checkpoint& c) { return t < c.imu.utime; });
  replay_from(static_cast<size_t>(std::distance(history_.begin(), it)) - 1);
  return {true, ""};
}

// ---------------------------------------------------------------------------------------------
// Status

double Eskf::time_since_update_s() const {
  if (!initialised()) return 0.0;
  return static_cast<double>(history_.back().imu.utime - last_update_utime_) * 1e-6;
}

NavStatus Eskf::status() const {
  if (!initialised()) return NavStatus::Initialising;
  const double age = time_since_update_s();
  if (age > p_.lost_after_s) return NavStatus::Lost;
  if (age > p_.imu_only_after_s) return NavStatus::ImuOnly;
  return NavStatus::Ok;
}

std::string Eskf::status_reason() const {
  if (!initialised()) {
    const double have = static_.empty() ? 0.0 : (static_.back().utime - static_.front().utime) * 1e-6;
    return "static alignment: " + fmt(have, 2) + " of " + fmt(p_.static_window_s, 2) + " s still" +
           (counters_.static_windows_rejected ? " (" + std::to_string(counters_.static_windows_rejected) +
                                                     " windows rejected as moving)"
                                               : "");
  }
  const double age = time_since_update_s();
  if (counters_.vo_applied == 0 && status() == NavStatus::Ok)
    return counters_.resumed ? "resumed from a snapshot, last VO update " + fmt(age, 2) + " s ago"
                             : "aligned " + fmt(age, 2) + " s ago, no VO update yet";
  switch (status()) {
    case NavStatus::Ok: return "last VO update " + fmt(age, 2) + " s ago";
    case NavStatus::ImuOnly: return "no VO update for " + fmt(age, 2) + " s: IMU only";
    case NavStatus::Lost:
      return "no VO update for " + fmt(age, 2) + " s > lost_after_s " + fmt(p_.lost_after_s, 2) + ": lost";
    case NavStatus::Initialising: break;
  }
  return "";
}

Mat15 Eskf::covariance_world_attitude() const {
  Mat15 G = Mat15::Identity();
  G.block<3, 3>(kTheta, kTheta) = x_.q.toRotationMatrix();
  return G * P_ * G.transpose();
}

}  // namespace aerie::nav
