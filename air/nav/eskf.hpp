#pragma once
// Error-state extended Kalman filter (ESKF) fusing an IMU with visual-odometry poses, the
// MSF/ROVIO family. Equations: J. Solà, "Quaternion kinematics for the error-state Kalman
// filter", arXiv:1711.02508, 2017 (cited below as [S] with its equation numbers).
//
// Frames (docs/nav.md): world W is gravity-aligned, z up (gravity = (0, 0, -g)); body B is
// the IMU frame (FLU in the simulator); the camera C is the left camera's optical frame; VO
// poses T_vo_cam are in the VO's own odometry frame V, which is tied to W by T_world_vo
// (fixed by configuration, or anchored on the filter's estimate at the first VO pose).
//
// Nominal state x = [p, v, q, b_g, b_a] (p, v of B in W; q = q_world_body; gyro and
// accelerometer biases). Error state dx = [dp, dv, dtheta, db_g, db_a] (15), with the
// attitude error local (body frame): q_true = q (x) Exp(dtheta)  [S eq. 282c].
//
// Time: every input carries utime (µs, message time). A buffer of IMU samples and
// checkpoints of the state after each of them lets a delayed or out-of-order VO pose be
// applied at its own utime, the later samples re-propagated (and later VO poses re-applied).
// No wall clock, no I/O, no LCM.
#include <Eigen/Core>
#include <Eigen/Geometry>

#include <cstdint>
#include <deque>
#include <map>
#include <numbers>
#include <optional>
#include <string>
#include <vector>

#include "common/geometry/se3.hpp"

namespace aerie::nav {

using Vec3 = Eigen::Vector3d;
using Mat3 = Eigen::Matrix3d;
using Mat6 = Eigen::Matrix<double, 6, 6>;
using Mat15 = Eigen::Matrix<double, 15, 15>;

// Offsets of the error-state blocks.
inline constexpr int kP = 0, kV = 3, kTheta = 6, kBg = 9, kBa = 12, kErrorDim = 15;

struct NominalState {
  int64_t utime = 0;
  Vec3 p = Vec3::Zero();
  Vec3 v = Vec3::Zero();
  Eigen::Quaterniond q = Eigen::Quaterniond::Identity();  // body -> world
  Vec3 bg = Vec3::Zero();
  Vec3 ba = Vec3::Zero();
};

struct ImuSample {
  int64_t utime = 0;
  Vec3 gyro = Vec3::Zero();   // rad/s, body
  Vec3 accel = Vec3::Zero();  // m/s^2, specific force, body
};

struct VoMeasurement {
  int64_t utime = 0;
  geometry::SE3 T_vo_cam;  // left-camera pose in the VO frame
  // Over xi = [rotation (rad); translation (m)] as aerie.pose_t: a left (VO-frame) perturbation,
  // T_measured = Exp(xi) T_true, xi ~ N(0, covariance) (docs/nav.md). nullopt: the configured noise.
  std::optional<Mat6> covariance;
  bool restart = false;  // the VO (re)started its frame: re-anchor T_world_vo (anchor mode)
};

enum class NavStatus { Initialising, Ok, ImuOnly, Lost };
const char* to_string(NavStatus s);

enum class VoNoise { Message, Config };
enum class VoFrame { Anchor, Fixed };

struct EskfParams {
  double gravity_m_s2 = 9.81;
  // IMU noise, continuous time (Kalibr / EuRoC sensor.yaml convention; ADIS16448 defaults).
  double gyro_noise_density = 1.6968e-4;   // rad/s/sqrt(Hz)
  double gyro_random_walk = 1.9393e-5;     // rad/s^2/sqrt(Hz)
  double accel_noise_density = 2.0e-3;     // m/s^2/sqrt(Hz)
  double accel_random_walk = 3.0e-3;       // m/s^3/sqrt(Hz)
  // Input checks.
  double max_imu_dt_s = 0.05;     // a longer step is a gap: coasted on the last sample, counted
  double max_gyro_rad_s = 35.0;   // beyond: refused as out of range
  double max_accel_m_s2 = 160.0;
  // Static alignment: a window of this length with the IMU still.
  double static_window_s = 1.0;
  double static_max_gyro_std_rad_s = 0.1;
  double static_max_accel_std_m_s2 = 2.0;
  double initial_yaw_rad = 0.0;
  // Initial uncertainty after the alignment (1 sigma).
  double init_position_sigma_m = 0.0;
  double init_velocity_sigma_m_s = 0.02;
  double init_yaw_sigma_rad = 0.1;
  double init_gyro_bias_sigma_rad_s = 0.003;
  double init_accel_bias_sigma_m_s2 = 0.1;  // also sets the roll/pitch uncertainty (tilt = bias / g)
  // Camera-IMU extrinsic: the left camera's pose in the body frame.
  geometry::SE3 T_body_cam;
  // VO measurement noise.
  // Config: the sigmas below (default; aerie-vo's accumulated covariance is overconfident, docs/nav.md).
  // Message: pose_t's covariance (the configured noise where it is not positive definite).
  VoNoise vo_noise = VoNoise::Config;
  double vo_rotation_sigma_rad = 0.0175;    // configured noise, 1 sigma per axis
  double vo_position_sigma_m = 0.02;
  VoFrame vo_frame = VoFrame::Anchor;
  geometry::SE3 T_world_vo;                 // used when vo_frame == Fixed
  double gate_chi2 = 22.458;                // Mahalanobis gate, chi-square 6 dof (22.458: p = 0.999); <= 0: none
  // Outage: no accepted VO update for this long -> IMU_ONLY, then LOST (message time).
  double imu_only_after_s = 0.25;
  double lost_after_s = 2.0;
  // How far back (behind the newest IMU sample) a VO pose can still be applied.
  double buffer_s = 1.0;
  int max_pending_vo = 20;  // VO poses ahead of the IMU held until the IMU catches up
  void validate() const;    // throws std::invalid_argument naming the field
};

// What happened to one input: accepted, or refused with the reason.
struct Outcome {
  bool accepted = false;
  std::string reason;  // empty when accepted
};

struct EskfCounters {
  int64_t imu_accepted = 0, imu_non_finite = 0, imu_out_of_range = 0, imu_time_not_increasing = 0, imu_gaps = 0;
  int64_t imu_negative_time = 0;
  int64_t static_windows_rejected = 0;  // alignment windows that were not still
  int64_t vo_applied = 0, vo_gated = 0, vo_anchors = 0;  // per VO pose, its latest outcome
  int64_t vo_invalid = 0, vo_too_old = 0, vo_duplicate = 0, vo_before_alignment = 0, vo_pending_dropped = 0;
  int64_t vo_delayed = 0;      // poses older than the newest IMU sample (re-propagation needed)
  int64_t vo_out_of_order = 0; // poses older than an already received VO pose
  int64_t resumed = 0;         // starts from a snapshot (resume) instead of the alignment
};

// What a restarted filter resumes from (aerie-nav's state file): the nominal state, its
// covariance, the VO frame's anchor T_world_vo and the time of the last applied update.
struct Snapshot {
  NominalState x;
  Mat15 P = Mat15::Zero();
  std::optional<geometry::SE3> T_world_vo;
  int64_t last_update_utime = 0;
};

// The growth of the uncertainty over a gap the filter did not see (the restart): an unknown
// acceleration and turn rate, each constant over the gap with these sigmas per axis.
struct GapNoise {
  double accel_sigma_m_s2 = 3.0;
  double rate_sigma_rad_s = 30.0 * std::numbers::pi / 180.0;
};

// Result of the static alignment.
struct Alignment {
  int64_t utime = 0;        // the last sample of the window (the filter starts there)
  int samples = 0;
  Vec3 mean_gyro = Vec3::Zero(), mean_accel = Vec3::Zero();
  Vec3 std_gyro = Vec3::Zero(), std_accel = Vec3::Zero();
  double roll_rad = 0, pitch_rad = 0;
};

// Shared with the monocular filter (air/nav/msf.hpp):
// The IMU sample at time t inside [a, b]: linear interpolation, or a held (when the step is a gap).
ImuSample interpolate_imu(const ImuSample& a, const ImuSample& b, int64_t t, bool hold);
// The input checks of Eskf::add_imu against the previous accepted sample's time (nullopt: none);
// counts the refusals and the accepted sample; the outcome's reason names a gap (aligned: bridged).
Outcome check_imu(const EskfParams& p, const ImuSample& s, std::optional<int64_t> prev, bool aligned,
                  EskfCounters& counters);
// One propagation step from sample a to b (b may be interpolated): the nominal state x follows
// [S eq. 260] with midpoint integration; F is the error-state transition [S eq. 269] and Q the
// impulse covariances [S eqs. 270-273] over it. False (x unchanged) when b is not after a.
bool imu_step(const EskfParams& p, NominalState& x, const ImuSample& a, const ImuSample& b, Mat15& F, Mat15& Q);

class Eskf {
 public:
  explicit Eskf(EskfParams params);

  // One IMU sample. Refused (state unchanged, counted) when not finite, out of range or not
  // after the previous accepted sample. A step longer than max_imu_dt_s is a gap: counted,
  // reported in the outcome, and bridged by holding the previous sample.
  Outcome add_imu(const ImuSample& s);
  // One VO pose. Applied at its utime (re-propagating the later IMU samples), held until the
  // IMU reaches it when it is ahead, refused when older than the buffer, invalid, duplicate or
  // before the alignment. Accepted also covers a pose the gate rejected: see counters().vo_gated.
  Outcome add_vo(const VoMeasurement& m);
  // Starts from a known state instead of the static alignment (tests, a known start); the
  // sample becomes the first of the buffer.
  void initialise(const NominalState& x, const Mat15& P, const ImuSample& first);
  // Starts from a snapshot taken before a restart, without the static alignment and in the
  // same world frame (the VO's anchor kept): the state coasted over the gap to `first` (the
  // position at the snapshot's velocity, the attitude at first's bias-corrected rate), the
  // covariance grown by `gap`. Throws std::invalid_argument when `first` is before the snapshot.
  void resume(const Snapshot& s, const ImuSample& first, const GapNoise& gap);
  Snapshot snapshot() const { return Snapshot{x_, P_, anchor_, last_update_utime_}; }

  bool initialised() const { return !history_.empty(); }
  NavStatus status() const;
  std::string status_reason() const;
  const NominalState& state() const { return x_; }
  const Mat15& covariance() const { return P_; }
  const EskfCounters& counters() const { return counters_; }
  const EskfParams& params() const { return p_; }
  const std::optional<Alignment>& alignment() const { return alignment_; }
  const std::optional<geometry::SE3>& T_world_vo() const { return anchor_; }
  // Message time since the last applied VO update (or the alignment), seconds.
  double time_since_update_s() const;
  // Mahalanobis distance squared of the latest processed VO innovation.
  double last_mahalanobis2() const { return last_d2_; }
  // The covariance with the attitude error in the world frame, dtheta_w = R dtheta
  // (q_true = Exp(dtheta_w) (x) q): what NAV_STATE publishes.
  Mat15 covariance_world_attitude() const;

 private:
  enum class VoOutcome { Pending, Applied, Gated, Anchored };
  struct VoRecord {
    VoMeasurement m;
    VoOutcome outcome = VoOutcome::Pending;
  };
  struct Checkpoint {  // the filter right after integrating up to `imu` (before VO poses at its time)
    ImuSample imu;
    NominalState x;
    Mat15 P;
    std::optional<geometry::SE3> anchor;
    int64_t last_update_utime = 0;
  };

  void try_align(const ImuSample& s);
  void propagate(const ImuSample& a, const ImuSample& b);
  void advance(size_t j);           // checkpoint j -> j+1, with VO poses strictly inside
  void apply_vo_at(int64_t utime);  // VO poses at exactly this time (after its IMU sample)
  void apply(VoRecord& r);
  void replay_from(size_t i);
  void set_outcome(VoRecord& r, VoOutcome o);
  Mat6 measurement_covariance(const VoMeasurement& m) const;
  geometry::SE3 camera_pose() const;  // T_world_cam of the nominal state
  void trim();

  EskfParams p_;
  NominalState x_;
  Mat15 P_ = Mat15::Zero();
  std::optional<geometry::SE3> anchor_;
  int64_t last_update_utime_ = 0;
  std::deque<Checkpoint> history_;
  std::map<int64_t, VoRecord> vo_;
  std::deque<ImuSample> static_;  // the alignment window
  std::optional<Alignment> alignment_;
  EskfCounters counters_;
  int64_t newest_vo_utime_ = INT64_MIN;
  double last_d2_ = 0.0;
};

}  // namespace aerie::nav
