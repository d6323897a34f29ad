#include "air/nav/msf.hpp"

#include <algorithm>
#include <cmath>
#include <stdexcept>

#include "common/geometry/so3.hpp"

namespace aerie::nav {
namespace {

using Vec6 = Eigen::Matrix<double, 6, 1>;

Mat3 hat(const Vec3& w) { return geometry::hat<double>(w); }
Mat3 Exp(const Vec3& w) { return geometry::so3_exp<double>(w); }

std::string fmt(double v, int prec = 3) {
  char buf[64];
  std::snprintf(buf, sizeof(buf), "%.*f", prec, v);
  return buf;
}

}  // namespace

const char* to_string(ScaleStatus s) { return s == ScaleStatus::Ok ? "SCALE_OK" : "SCALE_UNKNOWN"; }

void MonoParams::validate() const {
  auto positive = [](double v, const char* name) {
    if (!(v > 0.0) || !std::isfinite(v)) throw std::invalid_argument(std::string("nav: mono.") + name + " must be > 0");
  };
  auto non_negative = [](double v, const char* name) {
    if (!(v >= 0.0) || !std::isfinite(v)) throw std::invalid_argument(std::string("nav: mono.") + name + " must be >= 0");
  };
  positive(scale_prior, "scale_prior");
  positive(scale_prior_sigma, "scale_prior_sigma");
  positive(scale_sigma_ok, "scale_sigma_ok");
  non_negative(scale_random_walk, "scale_random_walk");
  non_negative(frame_rotation_random_walk_rad, "frame_rotation_random_walk_deg");
  non_negative(frame_position_random_walk_m, "frame_position_random_walk_m");
  positive(rotation_sigma_rad, "rotation_sigma_deg");
  positive(position_sigma_m, "position_sigma_m");
  if (jump_poses < 1) throw std::invalid_argument("nav: mono.jump_poses must be >= 1");
  non_negative(min_velocity_change_m_s, "min_velocity_change_m_s");
}

// ---------------------------------------------------------------------------------------------
// Measurement model (docs/nav.md "Monocular source", [W] pose sensor: z_p = lambda C(q_wv)^T
// (p + C(q) p_ic - p_wv), z_q = q_wv^-1 (x) q (x) q_ic, with our frame names).

MonoPrediction predict_mono(const MsfState& s, const geometry::SE3& T_body_cam) {
  const Mat3 R = s.x.q.toRotationMatrix();
  const Mat3 RvwT = s.frame.q_world_vis.toRotationMatrix().transpose();
  const Vec3 p_bc = T_body_cam.translation();
  const double lambda = std::exp(s.log_scale);
  const Vec3 u = s.x.p + R * p_bc - s.frame.p_world_anchor;  // the camera from the anchor point, W, metres
  MonoPrediction out;
  // (M1) T_vc = (R_wv^T R R_bc, p_a + lambda R_wv^T u).
  out.T_vis_cam = geometry::SE3(Eigen::Quaterniond(RvwT * R * T_body_cam.rotation_matrix()),
                                s.frame.p_vis_anchor + lambda * (RvwT * u));
  // (M2) rotation rows: R_vc_true R_vc^T = R_wv^T Exp(-dtheta_v) Exp(R dtheta) R_wv ~ Exp(R_wv^T (R dtheta - dtheta_v)).
  out.H.block<3, 3>(0, kTheta) = RvwT * R;
  out.H.block<3, 3>(0, kThetaV) = -RvwT;
  // (M3) position rows: lambda e^dl R_wv^T (I - [dtheta_v]x) (u + dp - R [p_bc]x dtheta - dp_a), first order.
  out.H.block<3, 3>(3, kP) = lambda * RvwT;
  out.H.block<3, 3>(3, kTheta) = -lambda * RvwT * R * hat(p_bc);
  out.H.block<3, 1>(3, kLogScale) = lambda * (RvwT * u);
  out.H.block<3, 3>(3, kThetaV) = lambda * RvwT * hat(u);
  out.H.block<3, 3>(3, kPa) = -lambda * RvwT;
  return out;
}

Eigen::Matrix<double, 6, 1> mono_residual(const MonoMeasurement& m, const geometry::SE3& predicted) {
  Vec6 r;
  r.head<3>() = geometry::so3_log(m.q_vis_cam.normalized().toRotationMatrix() * predicted.rotation_matrix().transpose());
  r.tail<3>() = m.p_vis_cam - predicted.translation();
  return r;
}

MsfState boxplus(const MsfState& s, const Vec22& dx) {
  MsfState o = s;
  o.x.p += dx.segment<3>(kP);
  o.x.v += dx.segment<3>(kV);
  o.x.q = (o.x.q * Eigen::Quaterniond(Exp(dx.segment<3>(kTheta)))).normalized();
  o.x.bg += dx.segment<3>(kBg);
  o.x.ba += dx.segment<3>(kBa);
  o.log_scale += dx[kLogScale];
  o.frame.q_world_vis = Eigen::Quaterniond(Exp(dx.segment<3>(kThetaV)) * s.frame.q_world_vis.toRotationMatrix()).normalized();
  o.frame.p_world_anchor += dx.segment<3>(kPa);
  return o;
}

// ---------------------------------------------------------------------------------------------

MonoEskf::MonoEskf(EskfParams params, MonoParams mono) : p_(std::move(params)), m_(mono), aligner_(p_) { m_.validate(); }

void MonoEskf::initialise(const NominalState& x, const Mat15& P, const ImuSample& first) {
  s_ = MsfState{};
  s_.x = x;
  s_.x.utime = first.utime;
  s_.x.q.normalize();
  s_.P.topLeftCorner<15, 15>() = P;
  s_.log_scale = std::log(m_.scale_prior);
  s_.P(kLogScale, kLogScale) = m_.scale_prior_sigma * m_.scale_prior_sigma;
  s_.last_update_utime = first.utime;
  vo_.clear();
  history_.clear();
  history_.push_back(Checkpoint{first, s_});
}

Outcome MonoEskf::add_imu(const ImuSample& s) {
  if (!initialised()) {  // the IMU filter's static alignment, then its state and covariance
    const Outcome o = aligner_.add_imu(s);
    static_cast<EskfCounters&>(counters_) = aligner_.counters();
    if (aligner_.initialised()) initialise(aligner_.state(), aligner_.covariance(), s);
    return o;
  }
  const Outcome o = check_imu(p_, s, history_.back().imu.utime, true, counters_);
  if (!o.accepted) return o;
  history_.push_back(Checkpoint{s, s_});
  advance(history_.size() - 2);
  trim();
  return o;
}

// The IMU states as Eskf::propagate (imu_step); lambda and the vision frame are constant up to
// their random walks (F = I on them).
void MonoEskf::propagate(const ImuSample& a, const ImuSample& b) {
  Mat15 F15, Q15;
  const Vec3 v0 = s_.x.v;
  if (!imu_step(p_, s_.x, a, b, F15, Q15)) return;
  s_.imu_dv += s_.x.v - v0;  // the IMU's part of the velocity change (no updates)
  s_.excitation_m_s = std::max(s_.excitation_m_s, s_.imu_dv.norm());
  const double dt = static_cast<double>(b.utime - a.utime) * 1e-6;
  Mat22 F = Mat22::Identity();
  F.topLeftCorner<15, 15>() = F15;
  Mat22 Q = Mat22::Zero();
  Q.topLeftCorner<15, 15>() = Q15;
  Q(kLogScale, kLogScale) = m_.scale_random_walk * m_.scale_random_walk * dt;
  Q.block<3, 3>(kThetaV, kThetaV) = std::pow(m_.frame_rotation_random_walk_rad, 2) * dt * Mat3::Identity();
  Q.block<3, 3>(kPa, kPa) = std::pow(m_.frame_position_random_walk_m, 2) * dt * Mat3::Identity();
  s_.P = F * s_.P * F.transpose() + Q;
  s_.P = 0.5 * (s_.P + s_.P.transpose());
}

void MonoEskf::advance(size_t j) {
  const ImuSample a = history_[j].imu;
  const ImuSample b = history_[j + 1].imu;
  const bool hold = static_cast<double>(b.utime - a.utime) > p_.max_imu_dt_s * 1e6;  // a gap
  const ImuSample b_used = hold ? interpolate_imu(a, b, b.utime, true) : b;
  ImuSample cur = hold ? interpolate_imu(a, b, a.utime, true) : a;
  for (auto it = vo_.upper_bound(a.utime); it != vo_.end() && it->first < b.utime; ++it) {
    const ImuSample c = interpolate_imu(a, b, it->first, hold);
    propagate(cur, c);
    cur = c;
    apply(it->second);
  }
  propagate(cur, b_used);
  s_.x.utime = b.utime;
  history_[j + 1] = Checkpoint{b, s_};
  apply_at(b.utime);
}

void MonoEskf::apply_at(int64_t utime) {
  const auto it = vo_.find(utime);
  if (it != vo_.end()) apply(it->second);
}

void MonoEskf::replay_from(size_t i) {
  s_ = history_[i].s;
  apply_at(history_[i].imu.utime);
  for (size_t j = i; j + 1 < history_.size(); ++j) advance(j);
}

void MonoEskf::trim() {
  const int64_t limit = history_.back().imu.utime - static_cast<int64_t>(std::llround(p_.buffer_s * 1e6));
  while (history_.size() > 1 && history_[1].imu.utime <= limit) history_.pop_front();
  const int64_t front = history_.front().imu.utime;
  while (!vo_.empty() && vo_.begin()->first < front) vo_.erase(vo_.begin());
}

void MonoEskf::set_outcome(Record& r, Outcome_ o) {
  auto counter = [this](Outcome_ k) -> int64_t* {
    switch (k) {
      case Outcome_::Applied: return &counters_.vo_applied;
      case Outcome_::Gated: return &counters_.vo_gated;
      case Outcome_::Anchored: return &counters_.vo_anchors;
      case Outcome_::Reset: return &counters_.vision_resets;
      case Outcome_::JumpReset: return &counters_.jump_resets;
      case Outcome_::Pending: return nullptr;
    }
    return nullptr;
  };
  if (int64_t* c = counter(r.outcome)) --*c;
  if (int64_t* c = counter(o)) ++*c;
  r.outcome = o;
}

// Noise over the residual [phi; dp_vc] in V (VO units).
Mat6 MonoEskf::noise(const MonoMeasurement& m) const {
  if (m_.noise == VoNoise::Message && m.covariance) {
    const Mat6 S = 0.5 * (*m.covariance + m.covariance->transpose());
    if (Eigen::LLT<Mat6>(S).info() == Eigen::Success) {
      Mat6 J = Mat6::Identity();  // pose_t's left perturbation: dp = rho - [t]x phi (docs/nav.md)
      J.block<3, 3>(3, 0) = -hat(m.p_vis_cam);
      return J * S * J.transpose();
    }
  }
  const double lambda = std::exp(s_.log_scale);
  Mat6 R = Mat6::Zero();
  R.block<3, 3>(0, 0) = std::pow(m_.rotation_sigma_rad, 2) * Mat3::Identity();
  R.block<3, 3>(3, 3) = std::pow(lambda * m_.position_sigma_m, 2) * Mat3::Identity();
  return R;
}

// (M4) The vision frame from this pose and the state: R_wv = R_wc R_vc,m^T, p_a = p_vc,m,
// p_wa = p_wc. (M5) Its error as a function of the state's and the pose's noise: the world
// position of V's point p_a is the true camera's plus R_wv dp_vc / lambda, so
// dtheta_v = R dtheta + R_wv phi; dp_a = dp - R [p_bc]x dtheta + R_wv dp_vc / lambda (no dl: the
// anchor point is where the camera was, whatever the scale).
MonoAnchor anchor_vision_frame(const MsfState& s, const MonoMeasurement& m, const geometry::SE3& T_body_cam) {
  const double lambda = std::exp(s.log_scale);
  const Mat3 R = s.x.q.toRotationMatrix();
  const geometry::SE3 T_wc = geometry::SE3(s.x.q, s.x.p) * T_body_cam;
  const Mat3 Rwv = T_wc.rotation_matrix() * m.q_vis_cam.normalized().toRotationMatrix().transpose();
  MonoAnchor a;
  a.frame.q_world_vis = Eigen::Quaterniond(Rwv).normalized();
  a.frame.p_world_anchor = T_wc.translation();
  a.frame.p_vis_anchor = m.p_vis_cam;
  a.J_state.block<3, 3>(0, kTheta) = R;
  a.J_state.block<3, 3>(3, kP) = Mat3::Identity();
  a.J_state.block<3, 3>(3, kTheta) = -R * hat(T_body_cam.translation());
  a.J_noise.block<3, 3>(0, 0) = Rwv;
  a.J_noise.block<3, 3>(3, 3) = Rwv / lambda;
  return a;
}

// The frame set at pose m, its covariance and its correlation with the state from (M5). With
// reset_scale (a VO re-initialisation) log(lambda) goes back to its prior first, uncorrelated.
void MonoEskf::anchor(const MonoMeasurement& m, bool reset_scale) {
  if (reset_scale) {
    s_.log_scale = std::log(m_.scale_prior);
    s_.P.row(kLogScale).setZero();
    s_.P.col(kLogScale).setZero();
    s_.P(kLogScale, kLogScale) = m_.scale_prior_sigma * m_.scale_prior_sigma;
  }
  const MonoAnchor a = anchor_vision_frame(s_, m, p_.T_body_cam);
  s_.frame = a.frame;
  s_.anchored = true;
  Mat22 A = Mat22::Identity();
  A.middleRows<6>(kThetaV) = a.J_state;
  Eigen::Matrix<double, kMsfDim, 6> G = Eigen::Matrix<double, kMsfDim, 6>::Zero();
  G.middleRows<6>(kThetaV) = a.J_noise;
  s_.P = A * s_.P * A.transpose() + G * noise(m) * G.transpose();
  s_.P = 0.5 * (s_.P + s_.P.transpose());
  s_.gated_run = 0;
  s_.imu_dv.setZero();
  s_.excitation_m_s = 0.0;
}

// The update [S eqs. 274-276] with (M1)-(M3), injection (boxplus) and reset (M6): G = I with
// I - [dtheta/2]x on the local attitude error and I + [dtheta_v/2]x on the world-frame one
// [S eqs. 285-287].
void MonoEskf::apply(Record& rec) {
  const MonoMeasurement& m = rec.m;
  if (!s_.anchored || m.reset) {
    const bool reset = s_.anchored;  // the first pose only sets the frame: the scale keeps its prior
    anchor(m, reset);
    set_outcome(rec, reset ? Outcome_::Reset : Outcome_::Anchored);
    return;
  }
  const MonoPrediction pr = predict_mono(s_, p_.T_body_cam);
  const Vec6 r = mono_residual(m, pr.T_vis_cam);
  const Mat6 Rn = noise(m);
  const Mat6 S = pr.H * s_.P * pr.H.transpose() + Rn;
  const Eigen::LLT<Mat6> llt(S);
  const double d2 = llt.info() == Eigen::Success ? r.dot(llt.solve(r)) : INFINITY;
  last_d2_ = d2;
  if (!std::isfinite(d2) || (p_.gate_chi2 > 0.0 && d2 > p_.gate_chi2)) {
    if (++s_.gated_run >= m_.jump_poses) {  // the VO jumped to a new map without saying so
      anchor(m, true);
      set_outcome(rec, Outcome_::JumpReset);
    } else {
      set_outcome(rec, Outcome_::Gated);
    }
    return;
  }
  s_.gated_run = 0;
  const Eigen::Matrix<double, kMsfDim, 6> K = s_.P * pr.H.transpose() * llt.solve(Mat6::Identity());
  const Vec22 dx = K * r;
  const Mat22 IKH = Mat22::Identity() - K * pr.H;
  const Mat22 P = IKH * s_.P * IKH.transpose() + K * Rn * K.transpose();
  s_ = boxplus(s_, dx);
  Mat22 G = Mat22::Identity();
  G.block<3, 3>(kTheta, kTheta) = Mat3::Identity() - hat(0.5 * dx.segment<3>(kTheta));
  G.block<3, 3>(kThetaV, kThetaV) = Mat3::Identity() + hat(0.5 * dx.segment<3>(kThetaV));
  s_.P = G * P * G.transpose();
  s_.P = 0.5 * (s_.P + s_.P.transpose());
  s_.last_update_utime = std::max(s_.last_update_utime, m.utime);
  set_outcome(rec, Outcome_::Applied);
}

Outcome MonoEskf::add_vo(const MonoMeasurement& m) {
  const std::string what = "mono pose at utime " + std::to_string(m.utime);
  auto refuse = [](int64_t& counter, std::string why) {
    ++counter;
    return Outcome{false, std::move(why)};
  };
  if (m.utime < 0) return refuse(counters_.vo_negative_time, what + ": negative time");
  if (!initialised()) return refuse(counters_.vo_before_alignment, what + ": before the static alignment has finished");
  if (!m.p_vis_cam.allFinite() || !m.q_vis_cam.coeffs().allFinite() || (m.covariance && !m.covariance->allFinite()))
    return refuse(counters_.vo_invalid, what + ": non-finite position, orientation or covariance");
  if (std::abs(m.q_vis_cam.norm() - 1.0) > 1e-3) {
    ++counters_.vo_not_unit;
    return refuse(counters_.vo_invalid,
                  what + ": orientation is not a unit quaternion (norm " + fmt(m.q_vis_cam.norm(), 6) + ")");
  }
  const int64_t front = history_.front().imu.utime;
  if (m.utime < front)
    return refuse(counters_.vo_too_old, what + ": older than the buffer (starts at " + std::to_string(front) + ")");
  if (vo_.count(m.utime)) return refuse(counters_.vo_duplicate, what + ": a pose with this utime was already received");
  const int64_t newest = history_.back().imu.utime;
  if (m.utime > newest && std::distance(vo_.upper_bound(newest), vo_.end()) >= p_.max_pending_vo)
    return refuse(counters_.vo_pending_dropped, what + ": ahead of the IMU (newest sample " + std::to_string(newest) +
                                                    ") with max_pending_vo poses already waiting");
  if (m.utime < newest_vo_utime_) ++counters_.vo_out_of_order;
  newest_vo_utime_ = std::max(newest_vo_utime_, m.utime);
  vo_.emplace(m.utime, Record{m, Outcome_::Pending});
  if (m.utime > newest) return {true, ""};
  if (m.utime < newest) ++counters_.vo_delayed;
  const auto it = std::upper_bound(history_.begin(), history_.end(), m.utime,
                                   [](int64_t t, const Checkpoint& c) { return t < c.imu.utime; });
  replay_from(static_cast<size_t>(std::distance(history_.begin(), it)) - 1);
  return {true, ""};
}

// ---------------------------------------------------------------------------------------------
// Status

double MonoEskf::time_since_update_s() const {
  if (!initialised()) return 0.0;
  return static_cast<double>(history_.back().imu.utime - s_.last_update_utime) * 1e-6;
}

NavStatus MonoEskf::status() const {
  if (!initialised()) return NavStatus::Initialising;
  const double age = time_since_update_s();
  if (age > p_.lost_after_s) return NavStatus::Lost;
  if (age > p_.imu_only_after_s) return NavStatus::ImuOnly;
  return NavStatus::Ok;
}

ScaleStatus MonoEskf::scale_status() const {
  return initialised() && s_.anchored && log_scale_sigma() < m_.scale_sigma_ok &&
                 s_.excitation_m_s >= m_.min_velocity_change_m_s
             ? ScaleStatus::Ok
             : ScaleStatus::Unknown;
}

std::string MonoEskf::status_reason() const {
  if (!initialised()) return aligner_.status_reason();
  const double age = time_since_update_s();
  std::string nav;
  switch (status()) {
    case NavStatus::Ok:
      nav = counters_.vo_applied ? "last mono update " + fmt(age, 2) + " s ago" : "no mono update yet";
      break;
    case NavStatus::ImuOnly: nav = "no mono update for " + fmt(age, 2) + " s: IMU only"; break;
    case NavStatus::Lost: nav = "no mono update for " + fmt(age, 2) + " s > lost_after_s " + fmt(p_.lost_after_s, 2) + ": lost"; break;
    case NavStatus::Initialising: break;
  }
  const std::string sc = "scale " + fmt(scale(), 4) + " (sigma " + fmt(100.0 * log_scale_sigma(), 1) + " %)";
  if (scale_status() == ScaleStatus::Ok) return nav + "; " + sc + ": SCALE_OK";
  if (!s_.anchored) return nav + "; " + sc + ": SCALE_UNKNOWN (no mono pose yet)";
  if (s_.excitation_m_s < m_.min_velocity_change_m_s)
    return nav + "; " + sc + ": SCALE_UNKNOWN (velocity changed by " + fmt(s_.excitation_m_s, 2) +
           " m/s since the vision frame was set < min_velocity_change_m_s " + fmt(m_.min_velocity_change_m_s, 2) +
           ": the scale needs acceleration)";
  return nav + "; " + sc + " > scale_sigma_ok " + fmt(100.0 * m_.scale_sigma_ok, 1) + " %: SCALE_UNKNOWN";
}

Mat15 MonoEskf::covariance_world_attitude() const {
  Mat15 G = Mat15::Identity();
  G.block<3, 3>(kTheta, kTheta) = s_.x.q.toRotationMatrix();
  return G * s_.P.topLeftCorner<15, 15>() * G.transpose();
}

}  // namespace aerie::nav
