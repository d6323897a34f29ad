// Static alignment on real data: the EuRoC V1_01 excerpt (../shared/data/stereo_seq), where the
// MAV stands on the ground with imu0 at 200 Hz. Roll and pitch must agree with the ground truth's
// orientation within 1 deg, the gyro bias must be the mean static gyro reading, and with VO-like
// pose updates (the ground-truth camera poses) over the rest of the excerpt the estimate must stay
// there.
#include <gtest/gtest.h>
#include <yaml-cpp/yaml.h>

#include <algorithm>
#include <cmath>
#include <fstream>
#include <sstream>
#include <string>
#include <vector>

#include "air/nav/eskf.hpp"
#include "common/camera/calibration_io.hpp"
#include "tests/support/test_support.hpp"

using namespace aerie;
using namespace aerie::nav;

namespace {

constexpr const char* kSeq = "stereo_seq/EuRoC_V1_01_easy_f000-094";
constexpr double kPi = 3.14159265358979323846;
constexpr int64_t kLastFrameNs = 1403715277962142976;  // the excerpt's last camera frame

std::vector<ImuSample> read_imu(const std::string& csv) {
  std::ifstream in(csv);
  EXPECT_TRUE(in.good()) << csv;
  std::vector<ImuSample> out;
  std::string line;
  while (std::getline(in, line)) {
    if (line.empty() || line[0] == '#') continue;
    std::replace(line.begin(), line.end(), ',', ' ');
    std::istringstream s(line);
    int64_t ns = 0;
    ImuSample m;
    s >> ns >> m.gyro.x() >> m.gyro.y() >> m.gyro.z() >> m.accel.x() >> m.accel.y() >> m.accel.z();
    if (ns > kLastFrameNs) break;
    m.utime = ns / 1000;
    out.push_back(m);
  }
  return out;
}

struct GtPose {
  int64_t utime;
  geometry::SE3 T_world_body;
};

std::vector<GtPose> read_tum(const std::string& path) {
  std::ifstream in(path);
  EXPECT_TRUE(in.good()) << path;
  std::vector<GtPose> out;
  std::string line;
  while (std::getline(in, line)) {
    if (line.empty() || line[0] == '#') continue;
    std::istringstream s(line);
    double t, x, y, z, qx, qy, qz, qw;
    s >> t >> x >> y >> z >> qx >> qy >> qz >> qw;
    const int64_t utime = static_cast<int64_t>(std::llround(t * 1e6));
    if (utime > kLastFrameNs / 1000 + 1) break;
    out.push_back({utime, geometry::SE3(Eigen::Quaterniond(qw, qx, qy, qz), Vec3(x, y, z))});
  }
  return out;
}

// EuRoC's sensor.yaml starts with OpenCV's "%YAML:1.0", which yaml-cpp does not take.
YAML::Node read_opencv_yaml(const std::string& path) {
  std::ifstream in(path);
  std::stringstream text;
  std::string line;
  while (std::getline(in, line))
    if (line.rfind("%YAML", 0) != 0) text << line << "\n";
  return YAML::Load(text.str());
}

// ZYX Euler roll and pitch of R (independent of yaw); differences wrapped to (-pi, pi].
double wrap(double a) { return std::remainder(a, 2.0 * kPi); }
double roll_of(const Mat3& R) { return std::atan2(R(2, 1), R(2, 2)); }
double pitch_of(const Mat3& R) { return std::asin(-R(2, 0)); }

// Tilt error of R against R_gt, deg: the estimated body "up" R^T e_z seen with the true attitude,
// w = R_gt R^T e_z, as rotations about the world x and y axes, and the total angle to e_z.
Vec3 tilt_error_deg(const Mat3& R, const Mat3& R_gt) {
  const Vec3 w = R_gt * R.transpose() * Vec3::UnitZ();
  const double k = 180.0 / kPi;
  return Vec3(std::atan2(-w.y(), w.z()) * k, std::atan2(w.x(), w.z()) * k,
              std::acos(std::clamp(w.z(), -1.0, 1.0)) * k);
}

const GtPose& nearest(const std::vector<GtPose>& gt, int64_t utime) {
  size_t best = 0;
  for (size_t i = 1; i < gt.size(); ++i)
    if (std::llabs(gt[i].utime - utime) < std::llabs(gt[best].utime - utime)) best = i;
  return gt[best];
}

}  // namespace

TEST(NavEuroc, StaticAlignmentMatchesGroundTruthAndGyroMean) {
  AERIE_REQUIRE_DATA(kSeq);
  const auto dir = test::shared_data(kSeq);
  const std::vector<ImuSample> imu = read_imu((dir / "mav0/imu0/data.csv").string());
  const std::vector<GtPose> gt = read_tum((dir / "groundtruth/V101_gt.txt").string());
  ASSERT_GT(imu.size(), 900u);  // 4.7 s at 200 Hz
  ASSERT_EQ(gt.size(), 95u);

  // The filter configured from the dataset: imu0's noise densities, cam0's T_BS (body.yaml only
  // names the vehicle; imu0's T_BS is the identity: the body frame is the IMU's).
  const YAML::Node imu_yaml = read_opencv_yaml((dir / "mav0/imu0/sensor.yaml").string());
  EskfParams p;
  p.gyro_noise_density = imu_yaml["gyroscope_noise_density"].as<double>();
  p.gyro_random_walk = imu_yaml["gyroscope_random_walk"].as<double>();
  p.accel_noise_density = imu_yaml["accelerometer_noise_density"].as<double>();
  p.accel_random_walk = imu_yaml["accelerometer_random_walk"].as<double>();
  p.T_body_cam = camera::read_euroc_camera((dir / "mav0/cam0/sensor.yaml").string()).T_body_sensor;
  p.static_window_s = 1.0;
  p.vo_noise = VoNoise::Config;
  p.vo_rotation_sigma_rad = 0.5 * kPi / 180.0;
  p.vo_position_sigma_m = 0.005;
  Eskf f(p);

  size_t k = 0;
  while (k < imu.size() && !f.initialised()) ASSERT_TRUE(f.add_imu(imu[k++]).accepted);
  ASSERT_TRUE(f.initialised()) << f.status_reason();
  const Alignment& al = *f.alignment();
  EXPECT_EQ(f.counters().static_windows_rejected, 0);  // the MAV is still: the first window is taken

  // The gyro bias is the mean gyro reading over the window (the same samples, summed here).
  Vec3 mean_gyro = Vec3::Zero();
  for (size_t i = 0; i < k; ++i) mean_gyro += imu[i].gyro;
  mean_gyro /= static_cast<double>(k);
  EXPECT_EQ(al.samples, static_cast<int>(k));
  EXPECT_LT((f.state().bg - mean_gyro).cwiseAbs().maxCoeff(), 1e-12);

  // Roll and pitch against the ground truth's body orientation at the alignment time. EuRoC's body
  // (IMU) frame has x pointing up, so ZYX Euler angles of it sit at pitch -68 deg, where a tilt
  // error shows in Euler "roll" amplified by 1/cos(pitch) = 2.7: they are printed, not asserted.
  // Asserted: the roll and pitch errors as the estimate's tilt about the world's horizontal axes
  // (the estimated "up" of the body, expressed with the true attitude), and the tilt as a whole.
  const Mat3 R_gt = nearest(gt, al.utime).T_world_body.rotation_matrix();
  const Mat3 R = f.state().q.toRotationMatrix();
  const Vec3 e_al = tilt_error_deg(R, R_gt);
  std::printf("alignment over %d samples: tilt error about world x %.3f deg, y %.3f deg, total %.3f deg; "
              "IMU-frame ZYX Euler roll %.3f (GT %.3f), pitch %.3f (GT %.3f) deg; b_g (%.5f %.5f %.5f) rad/s\n",
              al.samples, e_al.x(), e_al.y(), e_al.z(), roll_of(R) * 180 / kPi, roll_of(R_gt) * 180 / kPi,
              pitch_of(R) * 180 / kPi, pitch_of(R_gt) * 180 / kPi, f.state().bg.x(), f.state().bg.y(), f.state().bg.z());
  EXPECT_LT(std::abs(e_al.x()), 1.0);
  EXPECT_LT(std::abs(e_al.y()), 1.0);
  EXPECT_LT(e_al.z(), 1.0);
  // Euler pitch is well conditioned even here.
  EXPECT_LT(std::abs(wrap(pitch_of(R) - pitch_of(R_gt))) * 180.0 / kPi, 1.0);

  // The rest of the excerpt with the ground-truth camera poses as VO at 20 Hz (VO frame = the
  // Vicon frame, anchored on the first pose): still OK, tilt still within 1 deg, and the gyro bias
  // stays at the mean static reading of the whole excerpt within 2e-3 rad/s: the mean of ~940
  // samples with a 0.02-0.04 rad/s std (the rotors' vibration) is known to ~1.5e-3 rad/s, and the
  // MAV turns by at most 0.22 deg (< 1e-3 rad/s on average) meanwhile.
  size_t next_gt = 0;
  while (next_gt < gt.size() && gt[next_gt].utime <= al.utime) ++next_gt;
  for (; k < imu.size(); ++k) {
    ASSERT_TRUE(f.add_imu(imu[k]).accepted);
    while (next_gt < gt.size() && gt[next_gt].utime <= imu[k].utime) {
      VoMeasurement m;
      m.utime = gt[next_gt].utime;
      m.T_vo_cam = gt[next_gt].T_world_body * p.T_body_cam;
      ASSERT_TRUE(f.add_vo(m).accepted);
      ++next_gt;
    }
  }
  Vec3 mean_all = Vec3::Zero();
  for (const auto& s : imu) mean_all += s.gyro;
  mean_all /= static_cast<double>(imu.size());
  const Mat3 R_end = f.state().q.toRotationMatrix();
  const Mat3 R_gt_end = gt.back().T_world_body.rotation_matrix();
  const Vec3 e_end = tilt_error_deg(R_end, R_gt_end);
  std::printf("after %.2f s: VO applied %lld gated %lld, b_g (%.5f %.5f %.5f), mean gyro (%.5f %.5f %.5f), "
              "tilt error x %.3f y %.3f deg (Euler roll err %.3f pitch err %.3f deg)\n",
              (imu.back().utime - imu.front().utime) * 1e-6, static_cast<long long>(f.counters().vo_applied),
              static_cast<long long>(f.counters().vo_gated), f.state().bg.x(), f.state().bg.y(), f.state().bg.z(),
              mean_all.x(), mean_all.y(), mean_all.z(), e_end.x(), e_end.y(), wrap(roll_of(R_end) - roll_of(R_gt_end)) * 180 / kPi,
              wrap(pitch_of(R_end) - pitch_of(R_gt_end)) * 180 / kPi);
  EXPECT_EQ(f.status(), NavStatus::Ok);
  EXPECT_EQ(f.counters().vo_gated, 0);
  EXPECT_GE(f.counters().vo_applied, 70);
  EXPECT_LT((f.state().bg - mean_all).cwiseAbs().maxCoeff(), 2e-3);
  EXPECT_LT(std::abs(e_end.x()), 1.0);
  EXPECT_LT(std::abs(e_end.y()), 1.0);
  EXPECT_LT(f.state().v.norm(), 0.05);  // still standing
}
