#pragma once
// The monocular pose source in the ESKF (MSF): S. Weiss, M. Achtelik, M. Chli, R. Siegwart,
// "Versatile distributed pose estimation and sensor self-calibration for an autonomous MAV",
// ICRA 2012, and Weiss' thesis (ETH 2012) ([W] below): a pose sensor whose position is in an
// arbitrary scale and whose frame drifts against the world, fused with the IMU by adding the
// scale and the vision frame to the state. docs/nav.md "Monocular source: scale and drift (MSF)"
// holds the derivation; equations (M1)-(M6) below are numbered there.
//
// Nominal state: the IMU filter's [p, v, q, b_g, b_a] (air/nav/eskf.hpp) plus
//   l = log(lambda)   lambda = VO units per metre (the mono VO's scale; > 0 by construction)
//   R_wv, p_wa        the vision frame V in the world W: its rotation, and the world position
//                     (metric) of V's point a = the anchor pose's camera position p_a (VO units,
//                     a constant). V's origin is p_wv = p_wa - R_wv p_a / lambda. Holding p_wa
//                     rather than p_wv keeps the model linear in the scale error (docs/nav.md).
// Error state (22): [dp, dv, dtheta, db_g, db_a, dl, dtheta_v, dp_a] with
//   q_true = q (x) Exp(dtheta) (local, as the IMU filter), l_true = l + dl,
//   R_wv_true = Exp(dtheta_v) R_wv (world frame), p_wa_true = p_wa + dp_a.
// The camera-IMU extrinsic T_body_cam is fixed from the configuration (not a state).
//
// Measurement (M1): the camera's pose in V, T_vc = (R_wv^T R R_bc, p_a + lambda R_wv^T (p + R p_bc - p_wa)).
// The vision frame is set at the first pose (and at each VO re-initialisation) as a function of the
// state, so that pose agrees with the estimate (M4); its uncertainty and its correlation with the
// state come with it. No wall clock, no I/O, no LCM.
#include <Eigen/Core>
#include <Eigen/Geometry>

#include <cstdint>
#include <deque>
#include <map>
#include <optional>
#include <string>

#include "air/nav/eskf.hpp"
#include "common/geometry/se3.hpp"

namespace aerie::nav {

inline constexpr int kLogScale = 15, kThetaV = 16, kPa = 19, kMsfDim = 22;
using Mat22 = Eigen::Matrix<double, kMsfDim, kMsfDim>;
using Vec22 = Eigen::Matrix<double, kMsfDim, 1>;
using Mat6x22 = Eigen::Matrix<double, 6, kMsfDim>;

enum class ScaleStatus { Unknown, Ok };
const char* to_string(ScaleStatus s);

struct MonoParams {
  double scale_prior = 1.0;        // lambda at the start and after a VO re-initialisation (VO units per m)
  double scale_prior_sigma = 1.0;  // 1 sigma of log(lambda) then (1.0: a factor e either way)
  double scale_sigma_ok = 0.02;    // SCALE OK once sigma(log lambda) (~ the relative sigma of lambda) is below
  double scale_random_walk = 0.0;  // log(lambda) random walk, 1/sqrt(s) (a VO whose scale drifts)
  double frame_rotation_random_walk_rad = 0.0;  // vision-frame drift, rad/sqrt(s)
  double frame_position_random_walk_m = 0.0;    // m/sqrt(s)
  // Measurement noise. Config: these sigmas, the position one in metres (scaled by lambda into VO
  // units); Message: pose_t's covariance, in VO units (the config's where not positive definite).
  VoNoise noise = VoNoise::Config;
  double rotation_sigma_rad = 0.017453292519943295;  // 1 deg
  double position_sigma_m = 0.02;
  // This many consecutive poses beyond the gate are a VO re-initialisation that was not flagged
  // (a jump): the scale's uncertainty and the vision frame are reset at the last of them.
  int jump_poses = 3;
  // The observability condition: lambda is seen only through a change of velocity (an
  // acceleration); SCALE OK also needs the IMU-integrated velocity to have changed by this much
  // since the vision frame was set (a constant velocity leaves lambda and v inseparable).
  double min_velocity_change_m_s = 0.3;
  void validate() const;  // throws std::invalid_argument naming the mono.* key
};

struct MonoMeasurement {
  int64_t utime = 0;
  Eigen::Quaterniond q_vis_cam = Eigen::Quaterniond::Identity();  // as received: refused unless unit (1e-3)
  Vec3 p_vis_cam = Vec3::Zero();                                   // VO units
  // Over xi = [rotation; translation (VO units)], left perturbation in V as pose_t (docs/nav.md).
  std::optional<Mat6> covariance;
  bool reset = false;  // the VO (re)initialised its map: a new frame and a new scale
};

struct MonoCounters : EskfCounters {
  int64_t vo_negative_time = 0;
  int64_t vo_not_unit = 0;     // orientation not a unit quaternion (also counted in vo_invalid)
  int64_t vision_resets = 0;   // re-initialisations flagged by the VO (per pose, latest outcome)
  int64_t jump_resets = 0;     // re-initialisations detected from jump_poses gated poses
};

// The vision frame: R_wv, p_wa, p_a (above).
struct VisionFrame {
  Eigen::Quaterniond q_world_vis = Eigen::Quaterniond::Identity();
  Vec3 p_world_anchor = Vec3::Zero();  // m, world
  Vec3 p_vis_anchor = Vec3::Zero();    // VO units, V
  // T_world_vis with V's origin p_wv = p_wa - R_wv p_a / lambda.
  geometry::SE3 T_world_vis(double lambda) const {
    return geometry::SE3(q_world_vis, p_world_anchor - q_world_vis * p_vis_anchor / lambda);
  }
};

// The filter's state: what a checkpoint keeps and what the measurement model needs.
struct MsfState {
  NominalState x;
  double log_scale = 0.0;
  VisionFrame frame;
  bool anchored = false;      // the vision frame is set
  Mat22 P = Mat22::Zero();
  int64_t last_update_utime = 0;
  int gated_run = 0;          // consecutive gated poses (the jump detector)
  Vec3 imu_dv = Vec3::Zero();  // velocity change integrated from the IMU since the frame was set
  double excitation_m_s = 0.0; // the largest |imu_dv| so far (MonoParams::min_velocity_change_m_s)
};

// (M1)-(M3): the predicted pose of the camera in V, the residual r = [Log(R_vc,m R_vc^T);
// p_vc,m - p_vc] and its Jacobian H = dr/d(dx) (the minus sign of r = z - h folded in: H = dh/d(dx)).
struct MonoPrediction {
  geometry::SE3 T_vis_cam;
  Mat6x22 H = Mat6x22::Zero();
};
MonoPrediction predict_mono(const MsfState& s, const geometry::SE3& T_body_cam);
Eigen::Matrix<double, 6, 1> mono_residual(const MonoMeasurement& m, const geometry::SE3& predicted);
// x (+) dx with the error definitions above (the injection, [S eq. 283] extended).
MsfState boxplus(const MsfState& s, const Vec22& dx);
// (M4)-(M5): the vision frame that makes pose m agree with the state, and the Jacobians of its
// error [dtheta_v; dp_a] with respect to the state's error (J_state; zero on the frame's own
// columns) and to the pose's noise [phi; dp_vc] (J_noise; the residual's coordinates).
struct MonoAnchor {
  VisionFrame frame;
  Eigen::Matrix<double, 6, kMsfDim> J_state = Eigen::Matrix<double, 6, kMsfDim>::Zero();
  Mat6 J_noise = Mat6::Zero();
};
MonoAnchor anchor_vision_frame(const MsfState& s, const MonoMeasurement& m, const geometry::SE3& T_body_cam);

class MonoEskf {
 public:
  MonoEskf(EskfParams params, MonoParams mono);

  // As Eskf::add_imu: the static alignment first (an Eskf does it), then propagation.
  Outcome add_imu(const ImuSample& s);
  // One mono pose, applied at its utime as Eskf::add_vo; refused when utime < 0, not finite, the
  // quaternion not unit, before the alignment, older than the buffer, duplicate, too many ahead.
  Outcome add_vo(const MonoMeasurement& m);
  // A known start: the 15-state part as Eskf::initialise; the scale at its prior.
  void initialise(const NominalState& x, const Mat15& P, const ImuSample& first);

  bool initialised() const { return !history_.empty(); }
  NavStatus status() const;
  ScaleStatus scale_status() const;
  std::string status_reason() const;
  const NominalState& state() const { return s_.x; }
  const MsfState& full_state() const { return s_; }
  const Mat22& covariance() const { return s_.P; }
  double scale() const { return std::exp(s_.log_scale); }
  double log_scale_sigma() const { return std::sqrt(s_.P(kLogScale, kLogScale)); }
  double excitation_m_s() const { return s_.excitation_m_s; }
  const MonoCounters& counters() const { return counters_; }
  const EskfParams& params() const { return p_; }
  const MonoParams& mono_params() const { return m_; }
  double time_since_update_s() const;
  double last_mahalanobis2() const { return last_d2_; }
  // The IMU states' covariance with the attitude error in the world frame (as Eskf's, for NAV_STATE).
  Mat15 covariance_world_attitude() const;

 private:
  enum class Outcome_ { Pending, Applied, Gated, Anchored, Reset, JumpReset };
  struct Record {
    MonoMeasurement m;
    Outcome_ outcome = Outcome_::Pending;
  };
  struct Checkpoint {
    ImuSample imu;
    MsfState s;
  };
  void propagate(const ImuSample& a, const ImuSample& b);
  void advance(size_t j);
  void apply_at(int64_t utime);
  void apply(Record& r);
  void anchor(const MonoMeasurement& m, bool reset_scale);
  void replay_from(size_t i);
  void set_outcome(Record& r, Outcome_ o);
  Mat6 noise(const MonoMeasurement& m) const;
  void trim();

  EskfParams p_;
  MonoParams m_;
  Eskf aligner_;  // the static alignment (and the IMU checks before it)
  MsfState s_;
  std::deque<Checkpoint> history_;
  std::map<int64_t, Record> vo_;
  MonoCounters counters_;
  int64_t newest_vo_utime_ = INT64_MIN;
  double last_d2_ = 0.0;
};

}  // namespace aerie::nav
