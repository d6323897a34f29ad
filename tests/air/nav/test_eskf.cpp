// The error-state EKF on a synthetic flight (tests/air/nav/synthetic.hpp): exact IMU -> the
// truth up to the integrator's truncation error; noisy IMU + VO -> NEES within the chi-square
// bounds over Monte-Carlo runs; delayed and out-of-order VO poses -> the in-order result;
// outage, jumps and bad input -> the documented status and counters.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <limits>
#include <vector>

#include "air/nav/eskf.hpp"
#include "tests/air/nav/synthetic.hpp"

using namespace aerie;
using namespace aerie::nav;
using namespace aerie::nav::test;

namespace {

constexpr int64_t kT0 = 1'000'000;  // utime of t = 0

int64_t utime_of(double t) { return kT0 + static_cast<int64_t>(std::llround(t * 1e6)); }

EskfParams synthetic_params() {
  EskfParams p;
  // A camera off the IMU, looking forward and down (the simulator's rig), and a VO frame that is
  // neither the world nor level, so that every transform of the update is exercised.
  Eigen::Matrix3d R0;
  R0.col(0) = Vec3(0, -1, 0);
  R0.col(1) = Vec3(0, 0, -1);
  R0.col(2) = Vec3(1, 0, 0);
  p.T_body_cam = geometry::SE3(Eigen::AngleAxisd(0.35, Vec3::UnitY()).toRotationMatrix() * R0, Vec3(0.10, 0.06, -0.03));
  p.vo_frame = VoFrame::Fixed;
  p.T_world_vo = geometry::SE3(Eigen::Quaterniond(Eigen::AngleAxisd(0.5, Vec3(0.2, -0.3, 1.0).normalized())),
                               Vec3(2.0, -1.0, 0.5));
  p.vo_noise = VoNoise::Message;
  return p;
}

Mat15 diag15(double p, double v, double th, double bg, double ba) {
  Eigen::Matrix<double, 15, 1> d;
  d << Vec3::Constant(p * p), Vec3::Constant(v * v), Vec3::Constant(th * th), Vec3::Constant(bg * bg),
      Vec3::Constant(ba * ba);
  return d.asDiagonal();
}

// A VO covariance with unequal axes and correlations (rotation-translation too).
Mat6 vo_covariance() {
  Mat6 L = Mat6::Zero();
  L.diagonal() << 0.004, 0.003, 0.005, 0.010, 0.008, 0.012;
  L(3, 0) = 0.003;
  L(4, 1) = -0.002;
  L(5, 3) = 0.004;
  L(1, 0) = 0.001;
  return L * L.transpose();
}

struct DeadReckoningError {
  double p = 0, v = 0, theta = 0;
};

// Exact IMU at `rate_hz` from the exact initial state, no VO: the largest error over `duration` s.
DeadReckoningError dead_reckoning(double rate_hz, double duration) {
  EskfParams p = synthetic_params();
  Eskf f(p);
  const double dt = 1.0 / rate_hz;
  f.initialise(truth_state(0.0, utime_of(0.0)), diag15(0.01, 0.01, 0.01, 0.001, 0.01), exact_imu(0.0, utime_of(0.0)));
  DeadReckoningError e;
  const int n = static_cast<int>(std::lround(duration * rate_hz));
  for (int k = 1; k <= n; ++k) {
    const double t = k * dt;
    EXPECT_TRUE(f.add_imu(exact_imu(t, utime_of(t))).accepted);
    const TruthSample s = truth_at(t);
    const auto err = error_state(f.state(), s.p, s.v, s.q, Vec3::Zero(), Vec3::Zero());
    e.p = std::max(e.p, err.segment<3>(kP).norm());
    e.v = std::max(e.v, err.segment<3>(kV).norm());
    e.theta = std::max(e.theta, err.segment<3>(kTheta).norm());
  }
  return e;
}

}  // namespace

// (1) Exact IMU (no noise, no bias): the state follows the truth up to the integrator's
// truncation error. The propagation is second order (midpoint attitude, trapezoidal velocity),
// so after 10 s of this flight at 200 Hz the error is ~1e-5 m and must shrink 4x when the rate
// doubles; an error in any Jacobian-free part of the propagation (gravity sign, frame of the
// specific force, quaternion order) gives metres instead.
TEST(Eskf, ExactImuFollowsTheTruthToTheIntegrationError) {
  const DeadReckoningError e200 = dead_reckoning(200.0, 10.0);
  const DeadReckoningError e400 = dead_reckoning(400.0, 10.0);
  std::printf("exact IMU, 10 s dead reckoning: 200 Hz p %.3g m v %.3g m/s theta %.3g rad; 400 Hz p %.3g v %.3g theta %.3g\n",
              e200.p, e200.v, e200.theta, e400.p, e400.v, e400.theta);
  EXPECT_LT(e200.p, 1e-4);
  EXPECT_LT(e200.v, 2e-5);
  EXPECT_LT(e200.theta, 1e-6);
  // Second order: halving dt divides the error by ~4.
  EXPECT_GT(e200.p / e400.p, 3.0);
  EXPECT_LT(e200.p / e400.p, 5.0);
  EXPECT_GT(e200.theta / e400.theta, 3.0);
  EXPECT_LT(e200.theta / e400.theta, 5.0);
}

// (1b) Exact IMU and exact VO poses: the updates keep the state on the truth (the innovations are
// the integration error alone) and the biases stay at zero to the same order.
TEST(Eskf, ExactImuAndExactVoStayOnTheTruth) {
  EskfParams p = synthetic_params();
  Eskf f(p);
  f.initialise(truth_state(0.0, utime_of(0.0)), diag15(0.01, 0.01, 0.01, 0.001, 0.01), exact_imu(0.0, utime_of(0.0)));
  double max_p = 0, max_theta = 0;
  for (int k = 1; k <= 4000; ++k) {  // 20 s at 200 Hz
    const double t = k * 0.005;
    ASSERT_TRUE(f.add_imu(exact_imu(t, utime_of(t))).accepted);
    if (k % 10 == 0) {
      VoMeasurement m;
      m.utime = utime_of(t);
      m.T_vo_cam = true_vo_pose(t, p);
      m.covariance = vo_covariance();
      ASSERT_TRUE(f.add_vo(m).accepted);
    }
    const TruthSample s = truth_at(t);
    const auto err = error_state(f.state(), s.p, s.v, s.q, Vec3::Zero(), Vec3::Zero());
    max_p = std::max(max_p, err.segment<3>(kP).norm());
    max_theta = std::max(max_theta, err.segment<3>(kTheta).norm());
  }
  std::printf("exact IMU + VO, 20 s: max |dp| %.3g m, |dtheta| %.3g rad, |b_g| %.3g, |b_a| %.3g\n", max_p, max_theta,
              f.state().bg.norm(), f.state().ba.norm());
  EXPECT_EQ(f.counters().vo_applied, 400);
  EXPECT_EQ(f.counters().vo_gated, 0);
  EXPECT_LT(max_p, 1e-4);
  EXPECT_LT(max_theta, 1e-5);
  EXPECT_LT(f.state().bg.norm(), 1e-5);
  EXPECT_LT(f.state().ba.norm(), 1e-3);
  EXPECT_EQ(f.status(), NavStatus::Ok);
}

// (2) Noisy IMU (the filter's own noise model) and VO poses with a correlated covariance, 50
// Monte-Carlo runs from initial errors drawn from P0: the mean NEES over the runs lies within the
// two-sided 95 % bounds of chi2(50 * 15) / 50 at the end of the run, and at most 2 of the 10
// checks (one per second) fall outside (expected 0.5 at 5 % each).
TEST(Eskf, NeesIsConsistentOverMonteCarloRuns) {
  constexpr int kRuns = 50;
  constexpr int kChecks = 10;
  const EskfParams p = synthetic_params();
  const Mat15 P0 = diag15(0.05, 0.05, 0.02, 0.003, 0.05);
  const Eigen::Matrix<double, 15, 15> L0 = P0.llt().matrixL();
  std::vector<double> nees_sum(kChecks, 0.0);
  std::mt19937_64 vo_rng(4242);
  for (int run = 0; run < kRuns; ++run) {
    // Truth at t = 0: the estimate is the truth minus an error drawn from P0.
    std::mt19937_64 init_rng(1000 + run);
    std::normal_distribution<double> n01(0.0, 1.0);
    Eigen::Matrix<double, 15, 1> z;
    for (int i = 0; i < 15; ++i) z[i] = n01(init_rng);
    const Eigen::Matrix<double, 15, 1> e0 = L0 * z;
    NoisyImu imu_run(p, e0.segment<3>(kBg), e0.segment<3>(kBa), 2000 + run);
    NominalState x0 = truth_state(0.0, utime_of(0.0));
    x0.p -= e0.segment<3>(kP);
    x0.v -= e0.segment<3>(kV);
    x0.q = x0.q * Eigen::Quaterniond(geometry::so3_exp<double>(-e0.segment<3>(kTheta)));  // q_true = q (x) Exp(e)
    Eskf f(p);
    f.initialise(x0, P0, imu_run.sample(0.0, utime_of(0.0), 0.0));
    int check = 0;
    for (int k = 1; k <= 2000; ++k) {  // 10 s at 200 Hz, VO at 20 Hz
      const double t = k * 0.005;
      ASSERT_TRUE(f.add_imu(imu_run.sample(t, utime_of(t), 0.005)).accepted);
      if (k % 10 == 0) {
        VoMeasurement m;
        m.utime = utime_of(t);
        m.covariance = vo_covariance();
        m.T_vo_cam = perturb(true_vo_pose(t, p), *m.covariance, vo_rng);
        ASSERT_TRUE(f.add_vo(m).accepted);
      }
      if (k % 200 == 0) {
        const TruthSample s = truth_at(t);
        const auto e = error_state(f.state(), s.p, s.v, s.q, imu_run.bg(), imu_run.ba());
        nees_sum[check++] += e.dot(f.covariance().ldlt().solve(e));
      }
    }
  }
  const double lo = chi2_quantile(kRuns * 15.0, -1.959964) / kRuns;
  const double hi = chi2_quantile(kRuns * 15.0, 1.959964) / kRuns;
  int outside = 0;
  for (int c = 0; c < kChecks; ++c) {
    const double mean = nees_sum[c] / kRuns;
    std::printf("t = %2d s: mean NEES %.2f (95 %% bounds [%.2f, %.2f])\n", c + 1, mean, lo, hi);
    outside += (mean < lo || mean > hi);
  }
  const double final_mean = nees_sum.back() / kRuns;
  EXPECT_GT(final_mean, lo);
  EXPECT_LT(final_mean, hi);
  EXPECT_LE(outside, 2);
}

// (4) Delayed and out-of-order VO poses (off the IMU grid): the same state and covariance as the
// poses applied in order, to rounding.
TEST(Eskf, DelayedAndOutOfOrderVoGiveTheInOrderResult) {
  const EskfParams p = synthetic_params();
  const double kVoOffset = 0.0012;  // camera 1.2 ms after an IMU sample: the update interpolates
  // One noisy data set, fed three ways.
  NoisyImu imu(p, Vec3(0.002, -0.001, 0.0015), Vec3(0.03, -0.02, 0.04), 7);
  std::vector<ImuSample> samples;
  for (int k = 0; k <= 1200; ++k) samples.push_back(imu.sample(k * 0.005, utime_of(k * 0.005), k ? 0.005 : 0.0));
  std::mt19937_64 rng(99);
  std::vector<VoMeasurement> vo;
  for (int k = 10; k <= 1180; k += 10) {
    const double t = k * 0.005 + kVoOffset;
    VoMeasurement m;
    m.utime = utime_of(t);
    m.covariance = vo_covariance();
    m.T_vo_cam = perturb(true_vo_pose(t, p), *m.covariance, rng);
    vo.push_back(m);
  }
  const NominalState x0 = truth_state(0.0, utime_of(0.0));
  const Mat15 P0 = diag15(0.05, 0.05, 0.02, 0.003, 0.05);

  // delay_samples: a pose is given after the IMU sample this many samples past its time;
  // swap: poses given in pairs, the later one first.
  auto run = [&](int delay_samples, bool swap, bool with_vo) {
    Eskf f(p);
    f.initialise(x0, P0, samples[0]);
    std::vector<std::pair<int, VoMeasurement>> schedule;  // (sample index after which to give it, pose)
    for (size_t i = 0; i < vo.size(); ++i) {
      const int after = static_cast<int>((vo[i].utime - kT0) / 5000) + delay_samples;
      schedule.emplace_back(after, vo[i]);
    }
    if (swap)
      for (size_t i = 0; i + 1 < schedule.size(); i += 2) {
        std::swap(schedule[i].second, schedule[i + 1].second);
        schedule[i].first = schedule[i + 1].first;  // both given together, the later first
      }
    size_t next = 0;
    for (size_t k = 1; k < samples.size(); ++k) {
      EXPECT_TRUE(f.add_imu(samples[k]).accepted);
      while (with_vo && next < schedule.size() && schedule[next].first <= static_cast<int>(k)) {
        EXPECT_TRUE(f.add_vo(schedule[next].second).accepted);
        ++next;
      }
    }
    return f;
  };
  // In order: each pose is given before the IMU passes its time (held, applied on the way).
  const Eskf in_order = run(-1, false, true);
  const Eskf delayed = run(12, false, true);   // 60 ms late
  const Eskf shuffled = run(20, true, true);   // 100 ms late and pairwise out of order
  const Eskf no_vo = run(0, false, false);

  EXPECT_EQ(in_order.counters().vo_delayed, 0);
  EXPECT_EQ(delayed.counters().vo_delayed, static_cast<int64_t>(vo.size()));
  EXPECT_GT(shuffled.counters().vo_out_of_order, 50);
  for (const Eskf* f : {&in_order, &delayed, &shuffled}) EXPECT_EQ(f->counters().vo_applied, static_cast<int64_t>(vo.size()));
  auto diff = [](const Eskf& a, const Eskf& b) {
    const auto e = error_state(a.state(), b.state().p, b.state().v, b.state().q, b.state().bg, b.state().ba);
    return std::max(e.cwiseAbs().maxCoeff(), (a.covariance() - b.covariance()).cwiseAbs().maxCoeff());
  };
  std::printf("max difference to in order: delayed %.3g, out of order %.3g; without VO %.3g\n", diff(in_order, delayed),
              diff(in_order, shuffled), diff(in_order, no_vo));
  EXPECT_LT(diff(in_order, delayed), 1e-9);
  EXPECT_LT(diff(in_order, shuffled), 1e-9);
  EXPECT_GT(diff(in_order, no_vo), 1e-2);  // the poses did matter
  // The in-order result is right, too: near the truth.
  const TruthSample s = truth_at(1200 * 0.005);
  EXPECT_LT((in_order.state().p - s.p).norm(), 0.05);
}

// (5a) A VO outage: OK -> IMU_ONLY after imu_only_after_s -> LOST after lost_after_s, the
// position covariance growing all along; VO back -> OK.
TEST(Eskf, OutageIsBridgedByTheImuThenLost) {
  const EskfParams p = synthetic_params();
  NoisyImu imu(p, Vec3::Zero(), Vec3::Zero(), 11);
  Eskf f(p);
  f.initialise(truth_state(0.0, utime_of(0.0)), diag15(0.05, 0.05, 0.02, 0.003, 0.05), imu.sample(0.0, utime_of(0.0), 0));
  std::mt19937_64 rng(5);
  auto give_vo = [&](double t) {
    VoMeasurement m;
    m.utime = utime_of(t);
    m.covariance = vo_covariance();
    m.T_vo_cam = perturb(true_vo_pose(t, p), *m.covariance, rng);
    return f.add_vo(m);
  };
  int k = 1;
  for (; k <= 600; ++k) {  // 3 s with VO
    const double t = k * 0.005;
    f.add_imu(imu.sample(t, utime_of(t), 0.005));
    if (k % 10 == 0) give_vo(t);
  }
  EXPECT_EQ(f.status(), NavStatus::Ok);
  const double trace0 = f.covariance().block<3, 3>(kP, kP).trace();
  double prev_trace = trace0;
  bool monotonic = true;
  std::vector<std::pair<double, NavStatus>> seen;
  for (; k <= 600 + 600; ++k) {  // 3 s without
    const double t = k * 0.005;
    f.add_imu(imu.sample(t, utime_of(t), 0.005));
    const double tr = f.covariance().block<3, 3>(kP, kP).trace();
    monotonic = monotonic && tr > prev_trace;
    prev_trace = tr;
    if (seen.empty() || seen.back().second != f.status()) seen.emplace_back(f.time_since_update_s(), f.status());
  }
  EXPECT_TRUE(monotonic);
  EXPECT_GT(prev_trace, 100 * trace0);
  ASSERT_EQ(seen.size(), 3u);
  EXPECT_EQ(seen[0].second, NavStatus::Ok);
  EXPECT_EQ(seen[1].second, NavStatus::ImuOnly);
  EXPECT_NEAR(seen[1].first, p.imu_only_after_s, 0.006);
  EXPECT_EQ(seen[2].second, NavStatus::Lost);
  EXPECT_NEAR(seen[2].first, p.lost_after_s, 0.006);
  EXPECT_NE(f.status_reason().find("lost"), std::string::npos);
  // VO back: the (large) covariance lets the pose through the gate; OK again.
  const double t = k * 0.005;
  f.add_imu(imu.sample(t, utime_of(t), 0.005));
  EXPECT_TRUE(give_vo(t).accepted);
  EXPECT_EQ(f.counters().vo_gated, 0);
  EXPECT_EQ(f.status(), NavStatus::Ok);
  EXPECT_LT((f.state().p - truth_at(t).p).norm(), 0.05);
}

// (5b) A VO jump (one bad frame 0.5 m off) fails the Mahalanobis gate, is counted and changes
// nothing; the good poses around it are applied.
TEST(Eskf, VoJumpIsGatedAndCounted) {
  const EskfParams p = synthetic_params();
  NoisyImu imu(p, Vec3::Zero(), Vec3::Zero(), 12);
  Eskf f(p);
  f.initialise(truth_state(0.0, utime_of(0.0)), diag15(0.05, 0.05, 0.02, 0.003, 0.05), imu.sample(0.0, utime_of(0.0), 0));
  std::mt19937_64 rng(6);
  for (int k = 1; k <= 800; ++k) {
    const double t = k * 0.005;
    f.add_imu(imu.sample(t, utime_of(t), 0.005));
    if (k % 10 == 0) {
      VoMeasurement m;
      m.utime = utime_of(t);
      m.covariance = vo_covariance();
      m.T_vo_cam = perturb(true_vo_pose(t, p), *m.covariance, rng);
      if (k == 600) {
        const NominalState before = f.state();
        m.T_vo_cam = geometry::SE3(m.T_vo_cam.rotation(), m.T_vo_cam.translation() + Vec3(0.5, 0.0, 0.0));
        EXPECT_TRUE(f.add_vo(m).accepted);
        EXPECT_EQ(f.counters().vo_gated, 1);
        EXPECT_GT(f.last_mahalanobis2(), p.gate_chi2);
        EXPECT_EQ(f.state().p, before.p);  // nothing changed
      } else {
        f.add_vo(m);
      }
    }
  }
  EXPECT_EQ(f.counters().vo_gated, 1);
  EXPECT_EQ(f.counters().vo_applied, 79);
  EXPECT_LT((f.state().p - truth_at(4.0).p).norm(), 0.05);
}

// (5c) Bad IMU input: NaN/Inf, time going back or repeating, out of range -> refused with a
// reason, counted, state unchanged; a gap -> counted, bridged, covariance grown.
TEST(Eskf, BadImuIsRefusedAndCounted) {
  EskfParams p = synthetic_params();
  Eskf f(p);
  f.initialise(truth_state(0.0, utime_of(0.0)), diag15(0.05, 0.05, 0.02, 0.003, 0.05), exact_imu(0.0, utime_of(0.0)));
  for (int k = 1; k <= 100; ++k) ASSERT_TRUE(f.add_imu(exact_imu(k * 0.005, utime_of(k * 0.005))).accepted);
  const NominalState before = f.state();
  const Mat15 P_before = f.covariance();

  ImuSample nan = exact_imu(0.505, utime_of(0.505));
  nan.gyro.y() = std::numeric_limits<double>::quiet_NaN();
  Outcome o = f.add_imu(nan);
  EXPECT_FALSE(o.accepted);
  EXPECT_NE(o.reason.find("non-finite"), std::string::npos) << o.reason;
  ImuSample inf = exact_imu(0.505, utime_of(0.505));
  inf.accel.x() = std::numeric_limits<double>::infinity();
  EXPECT_FALSE(f.add_imu(inf).accepted);
  o = f.add_imu(exact_imu(0.3, utime_of(0.3)));  // back in time
  EXPECT_FALSE(o.accepted);
  EXPECT_NE(o.reason.find("not after"), std::string::npos) << o.reason;
  EXPECT_FALSE(f.add_imu(exact_imu(0.5, utime_of(0.5))).accepted);  // repeated
  ImuSample wild = exact_imu(0.505, utime_of(0.505));
  wild.gyro.z() = 100.0;
  EXPECT_FALSE(f.add_imu(wild).accepted);
  ImuSample negative = exact_imu(0.505, std::numeric_limits<int64_t>::min());  // the nav fuzzer's first sample
  o = f.add_imu(negative);
  EXPECT_FALSE(o.accepted);
  EXPECT_NE(o.reason.find("negative time"), std::string::npos) << o.reason;
  Eskf fresh(p);  // before the alignment too: a negative first sample never becomes the time reference
  EXPECT_FALSE(fresh.add_imu(negative).accepted);
  EXPECT_TRUE(fresh.add_imu(exact_imu(0.0, utime_of(0.0))).accepted);
  EXPECT_EQ(fresh.counters().imu_negative_time, 1);
  EXPECT_EQ(f.counters().imu_negative_time, 1);
  EXPECT_EQ(f.counters().imu_non_finite, 2);
  EXPECT_EQ(f.counters().imu_time_not_increasing, 2);
  EXPECT_EQ(f.counters().imu_out_of_range, 1);
  EXPECT_EQ(f.counters().imu_accepted, 100);
  EXPECT_EQ(f.state().p, before.p);
  EXPECT_EQ(f.state().q.coeffs(), before.q.coeffs());
  EXPECT_EQ(f.covariance(), P_before);

  // A 0.2 s gap (max_imu_dt_s 0.05): accepted as the new time reference, counted, bridged.
  o = f.add_imu(exact_imu(0.7, utime_of(0.7)));
  EXPECT_TRUE(o.accepted);
  EXPECT_NE(o.reason.find("gap"), std::string::npos) << o.reason;
  EXPECT_EQ(f.counters().imu_gaps, 1);
  EXPECT_GT(f.covariance().trace(), P_before.trace());
  EXPECT_EQ(f.state().utime, utime_of(0.7));
  EXPECT_TRUE(f.add_imu(exact_imu(0.705, utime_of(0.705))).accepted);
  EXPECT_LT((f.state().p - truth_at(0.705).p).norm(), 0.01);  // held samples over 0.2 s: small error
}

// (5d) Bad VO input: before the alignment, non-finite, older than the buffer, duplicate, and
// too many ahead of the IMU -> refused with a reason and counted.
TEST(Eskf, BadVoIsRefusedAndCounted) {
  EskfParams p = synthetic_params();
  p.max_pending_vo = 2;
  Eskf f(p);
  VoMeasurement m;
  m.utime = utime_of(0.0);
  EXPECT_FALSE(f.add_vo(m).accepted);
  EXPECT_EQ(f.counters().vo_before_alignment, 1);
  f.initialise(truth_state(0.0, utime_of(0.0)), diag15(0.05, 0.05, 0.02, 0.003, 0.05), exact_imu(0.0, utime_of(0.0)));
  for (int k = 1; k <= 400; ++k) f.add_imu(exact_imu(k * 0.005, utime_of(k * 0.005)));  // 2 s; buffer 1 s
  m.utime = utime_of(1.9);
  m.T_vo_cam = geometry::SE3(Eigen::Quaterniond::Identity(), Vec3(std::nan(""), 0, 0));
  Outcome o = f.add_vo(m);
  EXPECT_FALSE(o.accepted);
  EXPECT_EQ(f.counters().vo_invalid, 1);
  m.T_vo_cam = true_vo_pose(0.5, p);
  m.utime = utime_of(0.5);
  o = f.add_vo(m);
  EXPECT_FALSE(o.accepted);
  EXPECT_NE(o.reason.find("older than the buffer"), std::string::npos) << o.reason;
  EXPECT_EQ(f.counters().vo_too_old, 1);
  m.T_vo_cam = true_vo_pose(1.9, p);
  m.utime = utime_of(1.9);
  EXPECT_TRUE(f.add_vo(m).accepted);
  EXPECT_FALSE(f.add_vo(m).accepted);
  EXPECT_EQ(f.counters().vo_duplicate, 1);
  for (double t : {2.1, 2.2, 2.3}) {
    m.utime = utime_of(t);
    m.T_vo_cam = true_vo_pose(t, p);
    f.add_vo(m);
  }
  EXPECT_EQ(f.counters().vo_pending_dropped, 1);  // the third one ahead of the IMU
  for (int k = 401; k <= 460; ++k) f.add_imu(exact_imu(k * 0.005, utime_of(k * 0.005)));
  EXPECT_EQ(f.counters().vo_applied, 3);  // 1.9, then 2.1 and 2.2 once the IMU got there
}

// Static alignment on a synthetic still IMU with a known tilt and gyro bias; a moving window is
// rejected first.
TEST(Eskf, StaticAlignmentFindsRollPitchAndGyroBias) {
  EskfParams p;
  p.static_window_s = 0.5;
  Eskf f(p);
  const double roll = 0.2, pitch = -0.35;
  const Mat3 R = (Eigen::AngleAxisd(1.0, Vec3::UnitZ()) * Eigen::AngleAxisd(pitch, Vec3::UnitY()) *
                  Eigen::AngleAxisd(roll, Vec3::UnitX())).toRotationMatrix();
  const Vec3 bias(0.01, -0.02, 0.005);
  int64_t t = 0;
  for (int k = 0; k < 150; ++k) {  // moving: rotating at 0.5 rad/s
    ImuSample s;
    s.utime = t += 5000;
    s.gyro = Vec3(0, 0, k < 75 ? 0.5 : -0.5);
    s.accel = R.transpose() * Vec3(0, 0, 9.81) + Vec3(k % 2 ? 2.0 : -2.0, 0, 0);
    f.add_imu(s);
  }
  EXPECT_FALSE(f.initialised());
  EXPECT_EQ(f.status(), NavStatus::Initialising);
  EXPECT_GE(f.counters().static_windows_rejected, 1);
  for (int k = 0; k < 200 && !f.initialised(); ++k) {
    ImuSample s;
    s.utime = t += 5000;
    s.gyro = bias;
    s.accel = R.transpose() * Vec3(0, 0, 9.81);
    f.add_imu(s);
  }
  ASSERT_TRUE(f.initialised());
  ASSERT_TRUE(f.alignment());
  EXPECT_NEAR(f.alignment()->roll_rad, roll, 1e-12);
  EXPECT_NEAR(f.alignment()->pitch_rad, pitch, 1e-12);
  EXPECT_LT((f.state().bg - bias).norm(), 1e-15);
  // The aligned attitude maps the measured specific force onto +z (yaw is the configured 0).
  const Vec3 up = f.state().q * (R.transpose() * Vec3(0, 0, 9.81));
  EXPECT_LT((up - Vec3(0, 0, 9.81)).norm(), 1e-9);
  EXPECT_EQ(f.status(), NavStatus::Ok);
}

// (6) A restart: a second filter resumed from the first one's snapshot after a 0.5 s gap keeps
// the VO's anchor (the same world frame, no re-anchoring), starts within the grown covariance
// of the truth (the gap coasted: position at the snapshot's velocity, attitude at the first
// sample's rate) and is back on the truth after the VO updates that follow.
TEST(Eskf, ResumesFromASnapshotInTheSameFrame) {
  EskfParams p = synthetic_params();
  const geometry::SE3 T_world_vo_true = p.T_world_vo;
  p.vo_frame = VoFrame::Anchor;  // the anchor comes from the filter: it is what a restart would lose
  auto vo_at = [&](double t) {
    VoMeasurement m;
    m.utime = utime_of(t);
    EskfParams truth = p;
    truth.T_world_vo = T_world_vo_true;
    m.T_vo_cam = true_vo_pose(t, truth);
    m.covariance = vo_covariance();
    return m;
  };
  Eskf before(p);
  before.initialise(truth_state(0.0, utime_of(0.0)), diag15(0.001, 0.001, 0.001, 0.001, 0.01), exact_imu(0.0, utime_of(0.0)));
  for (int k = 1; k <= 1000; ++k) {  // 5 s
    const double t = k * 0.005;
    ASSERT_TRUE(before.add_imu(exact_imu(t, utime_of(t))).accepted);
    if (k % 10 == 0) {
      ASSERT_TRUE(before.add_vo(vo_at(t)).accepted);
    }
  }
  ASSERT_TRUE(before.T_world_vo());
  const Snapshot snap = before.snapshot();

  Eskf after(p);
  EXPECT_THROW(after.resume(snap, exact_imu(4.9, utime_of(4.9)), GapNoise{}), std::invalid_argument);
  after.resume(snap, exact_imu(5.5, utime_of(5.5)), GapNoise{});
  EXPECT_EQ(after.counters().resumed, 1);
  ASSERT_TRUE(after.T_world_vo());
  EXPECT_LT((after.T_world_vo()->matrix() - before.T_world_vo()->matrix()).cwiseAbs().maxCoeff(), 1e-15);
  EXPECT_EQ(after.status(), NavStatus::ImuOnly);  // 0.5 s since the last VO update, before the restart
  // Within 3 sigma of the grown covariance, per axis; the coasting does better than holding the
  // snapshot's position (the vehicle moves at ~1 m/s here).
  const TruthSample s = truth_at(5.5);
  const auto err = error_state(after.state(), s.p, s.v, s.q, Vec3::Zero(), Vec3::Zero());
  for (int i = 0; i < 9; ++i) EXPECT_LT(std::abs(err[i]), 3.0 * std::sqrt(after.covariance()(i, i))) << "error-state " << i;
  EXPECT_LT(err.segment<3>(kP).norm(), (s.p - snap.x.p).norm());
  std::printf("resumed after 0.5 s: |dp| %.3f m (held: %.3f m), |dtheta| %.4f rad, sigma_p %.3f m\n",
              err.segment<3>(kP).norm(), (s.p - snap.x.p).norm(), err.segment<3>(kTheta).norm(),
              std::sqrt(after.covariance()(kP, kP)));

  for (int k = 1; k <= 400; ++k) {  // 2 s more, with the VO
    const double t = 5.5 + k * 0.005;
    ASSERT_TRUE(after.add_imu(exact_imu(t, utime_of(t))).accepted);
    if (k % 10 == 0) {
      ASSERT_TRUE(after.add_vo(vo_at(t)).accepted);
    }
  }
  const TruthSample e = truth_at(7.5);
  const auto end = error_state(after.state(), e.p, e.v, e.q, Vec3::Zero(), Vec3::Zero());
  EXPECT_EQ(after.counters().vo_anchors, 0);
  EXPECT_EQ(after.counters().vo_gated, 0);
  EXPECT_EQ(after.status(), NavStatus::Ok);
  EXPECT_LT(end.segment<3>(kP).norm(), 0.01);
  EXPECT_LT(end.segment<3>(kTheta).norm(), 0.005);
}
