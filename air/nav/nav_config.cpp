#include "air/nav/nav_config.hpp"

#include <cmath>
#include <stdexcept>

#include "common/util/section_reader.hpp"

namespace aerie::nav {
namespace {
constexpr double kDeg = 3.14159265358979323846 / 180.0;
}

geometry::SE3 se3_from_row_major(const std::vector<double>& m, const std::string& what) {
  if (m.size() != 16) throw std::runtime_error(what + ": expected 16 numbers (4x4 row-major), got " + std::to_string(m.size()));
  Eigen::Matrix4d T;
  for (int i = 0; i < 16; ++i) {
    if (!std::isfinite(m[i])) throw std::runtime_error(what + ": element " + std::to_string(i) + " is not finite");
    T(i / 4, i % 4) = m[i];
  }
  const Eigen::Matrix3d R = T.topLeftCorner<3, 3>();
  if ((R.transpose() * R - Eigen::Matrix3d::Identity()).cwiseAbs().maxCoeff() > 1e-6 || R.determinant() < 0.0)
    throw std::runtime_error(what + ": the rotation block is not a rotation (orthonormal, det +1) to 1e-6");
  if ((T.row(3) - Eigen::RowVector4d(0, 0, 0, 1)).cwiseAbs().maxCoeff() > 1e-12)
    throw std::runtime_error(what + ": the last row must be 0 0 0 1");
  return geometry::SE3(R, Eigen::Vector3d(T.topRightCorner<3, 1>()));
}

geometry::SE3 sim_forward_rig_T_body_cam() {
  // Columns: the optical axes in the body (x_c = -y_b, y_c = -z_b, z_c = x_b), pitched down
  // about body y (common/sim body_to_left).
  Eigen::Matrix3d R0;
  R0.col(0) = Eigen::Vector3d(0, -1, 0);
  R0.col(1) = Eigen::Vector3d(0, 0, -1);
  R0.col(2) = Eigen::Vector3d(1, 0, 0);
  const Eigen::Matrix3d R = Eigen::AngleAxisd(20.0 * kDeg, Eigen::Vector3d::UnitY()).toRotationMatrix() * R0;
  return geometry::SE3(R, Eigen::Vector3d(0, 0.06, 0));
}

namespace {

// The mono: section (config/nav.yaml documents every key).
void load_mono(const util::Config& cfg, NavConfig& out) {
  MonoParams& m = out.mono;
  struct Mono {
    std::string channel, noise;
    double scale_prior, scale_prior_sigma, scale_sigma_ok, scale_random_walk, frame_rotation_random_walk_deg,
        frame_position_random_walk_m, rotation_sigma_deg, position_sigma_m, min_velocity_change_m_s;
    int jump_poses;
  } v{out.mono_channel, m.noise == VoNoise::Message ? "message" : "config", m.scale_prior, m.scale_prior_sigma,
      m.scale_sigma_ok, m.scale_random_walk, m.frame_rotation_random_walk_rad / kDeg, m.frame_position_random_walk_m,
      m.rotation_sigma_rad / kDeg, m.position_sigma_m, m.min_velocity_change_m_s, m.jump_poses};
  util::SectionReader<Mono>(cfg.section("mono"), v)("channel", &Mono::channel)("noise", &Mono::noise)(
      "scale_prior", &Mono::scale_prior)("scale_prior_sigma", &Mono::scale_prior_sigma)(
      "scale_sigma_ok", &Mono::scale_sigma_ok)("scale_random_walk", &Mono::scale_random_walk)(
      "frame_rotation_random_walk_deg", &Mono::frame_rotation_random_walk_deg)(
      "frame_position_random_walk_m", &Mono::frame_position_random_walk_m)("rotation_sigma_deg", &Mono::rotation_sigma_deg)(
      "position_sigma_m", &Mono::position_sigma_m)("min_velocity_change_m_s", &Mono::min_velocity_change_m_s)(
      "jump_poses", &Mono::jump_poses)
      .finish();
  if (v.channel.empty()) throw std::runtime_error(cfg.origin() + ": mono.channel must not be empty");
  out.mono_channel = v.channel;
  if (v.noise == "message") m.noise = VoNoise::Message;
  else if (v.noise == "config") m.noise = VoNoise::Config;
  else throw std::runtime_error(cfg.origin() + ": mono.noise must be message or config, not '" + v.noise + "'");
  m.scale_prior = v.scale_prior;
  m.scale_prior_sigma = v.scale_prior_sigma;
  m.scale_sigma_ok = v.scale_sigma_ok;
  m.scale_random_walk = v.scale_random_walk;
  m.frame_rotation_random_walk_rad = v.frame_rotation_random_walk_deg * kDeg;
  m.frame_position_random_walk_m = v.frame_position_random_walk_m;
  m.rotation_sigma_rad = v.rotation_sigma_deg * kDeg;
  m.position_sigma_m = v.position_sigma_m;
  m.min_velocity_change_m_s = v.min_velocity_change_m_s;
  m.jump_poses = v.jump_poses;
  try {
    m.validate();
  } catch (const std::invalid_argument& ex) {
    throw std::runtime_error(cfg.origin() + ": " + ex.what());
  }
}

}  // namespace

NavConfig load_nav_config(const util::Config& cfg) {
  NavConfig out;
  EskfParams& e = out.eskf;
  e.T_body_cam = sim_forward_rig_T_body_cam();
  struct Top {
    double gravity_m_s2, publish_rate_hz, buffer_s;
    int max_pending_vo;
    std::string source;
  } top{e.gravity_m_s2, out.publish_rate_hz, e.buffer_s, e.max_pending_vo, "stereo"};
  util::SectionReader<Top>(cfg, top)("gravity_m_s2", &Top::gravity_m_s2)("publish_rate_hz", &Top::publish_rate_hz)(
      "buffer_s", &Top::buffer_s)("max_pending_vo", &Top::max_pending_vo)("source", &Top::source)
      .known("mono")
      .known("imu")
      .known("alignment")
      .known("camera")
      .known("vo")
      .known("outage")
      .known("message_time")
      .known("resume")
      .finish();
  out.message_time = util::MessageClockConfig::from_config(cfg.section("message_time"), out.message_time);
  e.gravity_m_s2 = top.gravity_m_s2;
  out.publish_rate_hz = top.publish_rate_hz;
  e.buffer_s = top.buffer_s;
  e.max_pending_vo = top.max_pending_vo;
  if (top.source == "stereo") out.source = NavConfig::Source::Stereo;
  else if (top.source == "mono") out.source = NavConfig::Source::Mono;
  else throw std::runtime_error(cfg.origin() + ": source must be stereo or mono, not '" + top.source + "'");
  load_mono(cfg, out);
  if (out.source == NavConfig::Source::Mono && cfg.section("resume").has("state_file") &&
      !cfg.section("resume").get<std::string>("state_file", "").empty())
    throw std::runtime_error(cfg.origin() + ": resume.state_file is for source: stereo only (the mono filter does not resume)");
  if (!(out.publish_rate_hz >= 0.0) || !std::isfinite(out.publish_rate_hz))
    throw std::runtime_error(cfg.origin() + ": publish_rate_hz must be >= 0 (0 = every IMU sample)");

  util::SectionReader<EskfParams>(cfg.section("imu"), e)("gyro_noise_density", &EskfParams::gyro_noise_density)(
      "gyro_random_walk", &EskfParams::gyro_random_walk)("accel_noise_density", &EskfParams::accel_noise_density)(
      "accel_random_walk", &EskfParams::accel_random_walk)("max_dt_s", &EskfParams::max_imu_dt_s)(
      "max_gyro_rad_s", &EskfParams::max_gyro_rad_s)("max_accel_m_s2", &EskfParams::max_accel_m_s2)
      .known("max_jump_s")
      .finish();
  out.imu_max_jump_us = static_cast<int64_t>(
      std::llround(cfg.section("imu").get_in("max_jump_s", out.imu_max_jump_us * 1e-6, 1e-6, 3600.0) * 1e6));

  struct Align {
    double window_s, max_gyro_std_rad_s, max_accel_std_m_s2, yaw_deg, position_sigma_m, velocity_sigma_m_s,
        yaw_sigma_deg, gyro_bias_sigma_rad_s, accel_bias_sigma_m_s2;
  } al{e.static_window_s,       e.static_max_gyro_std_rad_s,     e.static_max_accel_std_m_s2,
       e.initial_yaw_rad / kDeg, e.init_position_sigma_m,         e.init_velocity_sigma_m_s,
       e.init_yaw_sigma_rad / kDeg, e.init_gyro_bias_sigma_rad_s, e.init_accel_bias_sigma_m_s2};
  util::SectionReader<Align>(cfg.section("alignment"), al)("window_s", &Align::window_s)(
      "max_gyro_std_rad_s", &Align::max_gyro_std_rad_s)("max_accel_std_m_s2", &Align::max_accel_std_m_s2)(
      "yaw_deg", &Align::yaw_deg)("position_sigma_m", &Align::position_sigma_m)(
      "velocity_sigma_m_s", &Align::velocity_sigma_m_s)("yaw_sigma_deg", &Align::yaw_sigma_deg)(
      "gyro_bias_sigma_rad_s", &Align::gyro_bias_sigma_rad_s)("accel_bias_sigma_m_s2", &Align::accel_bias_sigma_m_s2)
      .finish();
  e.static_window_s = al.window_s;
  e.static_max_gyro_std_rad_s = al.max_gyro_std_rad_s;
  e.static_max_accel_std_m_s2 = al.max_accel_std_m_s2;
  e.initial_yaw_rad = al.yaw_deg * kDeg;
  e.init_position_sigma_m = al.position_sigma_m;
  e.init_velocity_sigma_m_s = al.velocity_sigma_m_s;
  e.init_yaw_sigma_rad = al.yaw_sigma_deg * kDeg;
  e.init_gyro_bias_sigma_rad_s = al.gyro_bias_sigma_rad_s;
  e.init_accel_bias_sigma_m_s2 = al.accel_bias_sigma_m_s2;

  const util::Config camera = cfg.section("camera");
  struct None {} none;
  util::SectionReader<None>(camera, none).known("T_body_cam").finish();
  if (camera.has("T_body_cam"))
    e.T_body_cam = se3_from_row_major(camera.get<std::vector<double>>("T_body_cam", {}), cfg.origin() + ": camera.T_body_cam");

  const util::Config vo = cfg.section("vo");
  struct Vo {
    std::string noise, frame;
    double rotation_sigma_deg, position_sigma_m, gate_chi2;
  } v{e.vo_noise == VoNoise::Message ? "message" : "config", "anchor", e.vo_rotation_sigma_rad / kDeg, e.vo_position_sigma_m, e.gate_chi2};
  util::SectionReader<Vo>(vo, v)("noise", &Vo::noise)("frame", &Vo::frame)("rotation_sigma_deg", &Vo::rotation_sigma_deg)(
      "position_sigma_m", &Vo::position_sigma_m)("gate_chi2", &Vo::gate_chi2)
      .known("T_world_vo")
      .finish();
  if (v.noise == "message") e.vo_noise = VoNoise::Message;
  else if (v.noise == "config") e.vo_noise = VoNoise::Config;
  else throw std::runtime_error(cfg.origin() + ": vo.noise must be message or config, not '" + v.noise + "'");
  if (v.frame == "anchor") e.vo_frame = VoFrame::Anchor;
  else if (v.frame == "fixed") e.vo_frame = VoFrame::Fixed;
  else throw std::runtime_error(cfg.origin() + ": vo.frame must be anchor or fixed, not '" + v.frame + "'");
  e.vo_rotation_sigma_rad = v.rotation_sigma_deg * kDeg;
  e.vo_position_sigma_m = v.position_sigma_m;
  e.gate_chi2 = v.gate_chi2;
  if (vo.has("T_world_vo"))
    e.T_world_vo = se3_from_row_major(vo.get<std::vector<double>>("T_world_vo", {}), cfg.origin() + ": vo.T_world_vo");

  const util::Config rs = cfg.section("resume");
  util::SectionReader<None>(rs, none)
      .known("state_file")
      .known("write_period_s")
      .known("max_age_s")
      .known("gap_accel_sigma_m_s2")
      .known("gap_rate_sigma_deg_s")
      .finish();
  NavConfig::Resume& r = out.resume;
  r.state_file = rs.get<std::string>("state_file", r.state_file);
  r.write_period_s = rs.get_in("write_period_s", r.write_period_s, 1e-3, 60.0);
  r.max_age_s = rs.get_in("max_age_s", r.max_age_s, 0.0, 60.0);
  r.gap.accel_sigma_m_s2 = rs.get_in("gap_accel_sigma_m_s2", r.gap.accel_sigma_m_s2, 0.0, 100.0);
  r.gap.rate_sigma_rad_s = rs.get_in("gap_rate_sigma_deg_s", r.gap.rate_sigma_rad_s / kDeg, 0.0, 3600.0) * kDeg;

  util::SectionReader<EskfParams>(cfg.section("outage"), e)("imu_only_after_s", &EskfParams::imu_only_after_s)(
      "lost_after_s", &EskfParams::lost_after_s)
      .finish();
  try {
    e.validate();
  } catch (const std::invalid_argument& ex) {
    throw std::runtime_error(cfg.origin() + ": " + ex.what());
  }
  return out;
}

}  // namespace aerie::nav
