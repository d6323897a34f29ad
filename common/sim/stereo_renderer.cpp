#include "common/sim/stereo_renderer.hpp"

#include <algorithm>
#include <array>
#include <bit>
#include <cstdint>
#include <cmath>
#include <limits>
#include <stdexcept>
#include <string>

#include "common/sim/texture.hpp"

namespace aerie::sim {

namespace {

constexpr double kPi = 3.14159265358979323846;

using Vec3f = std::array<float, 3>;

// min/max without the NaN rules of std::fmin (which the compiler cannot inline).
inline float min_f(float a, float b) { return a < b ? a : b; }
inline float max_f(float a, float b) { return a > b ? a : b; }

// log2 to within 0.005 (mantissa by a quadratic), plenty for choosing a mip level.
inline float fast_log2(float x) {
  const uint32_t bits = std::bit_cast<uint32_t>(x);
  const float e = static_cast<float>(static_cast<int>(bits >> 23) - 127);
  const float m = std::bit_cast<float>((bits & 0x007FFFFFu) | 0x3F800000u);  // [1, 2)
  return e + (-0.34484843f * m + 2.02466578f) * m - 0.67487759f;
}

}  // namespace

camera::StereoCalibration Intrinsics::calibration() const {
  camera::StereoCalibration c;
  c.left.width = c.right.width = width;
  c.left.height = c.right.height = height;
  c.left.fx = c.right.fx = fx;
  c.left.fy = c.right.fy = fy;
  c.left.cx = c.right.cx = cx;
  c.left.cy = c.right.cy = cy;
  c.T_right_left = geometry::SE3(Eigen::Quaterniond::Identity(), Eigen::Vector3d(-baseline, 0, 0));
  c.source = "aerie::sim rig";
  return c;
}

geometry::SE3 body_to_left(const RigConfig& rig) {
  // Optical axes in the body frame before the tilt: x_cam = -y_body, y_cam = -z_body,
  // z_cam = x_body; then pitch down about the body y axis.
  Eigen::Matrix3d R0;
  R0.col(0) = Eigen::Vector3d(0, -1, 0);
  R0.col(1) = Eigen::Vector3d(0, 0, -1);
  R0.col(2) = Eigen::Vector3d(1, 0, 0);
  const Eigen::Matrix3d R =
      Eigen::AngleAxisd(rig.pitch_deg * kPi / 180.0, Eigen::Vector3d::UnitY()).toRotationMatrix() * R0;
  return {R, R * Eigen::Vector3d(-0.5 * rig.baseline, 0, 0)};
}

StereoRenderer::StereoRenderer(const World& world, const RigConfig& rig) : world_(world), rig_(rig) {
  auto check = [](bool ok, const std::string& what) {
    if (!ok) throw std::invalid_argument("sim::RigConfig: " + what);
  };
  check(rig.width >= 8 && rig.height >= 8 && rig.width <= 8192 && rig.height <= 8192,
        "width and height must be in [8, 8192]");
  check(rig.hfov_deg > 1 && rig.hfov_deg < 179 && rig.vfov_deg > 1 && rig.vfov_deg < 179,
        "hfov_deg and vfov_deg must be in (1, 179)");
  check(rig.baseline > 0, "baseline must be > 0");
  check(rig.noise_sigma >= 0, "noise_sigma must be >= 0");
  check(rig.exposure > 0 && rig.right_gain > 0, "exposure and right_gain must be > 0");
  check(rig.illumination_amplitude >= 0 && rig.illumination_amplitude < 1,
        "illumination_amplitude must be in [0, 1)");
  check(rig.illumination_period > 0, "illumination_period must be > 0");
  check(rig.motion_blur_samples >= 0 && rig.motion_blur_samples <= 64, "motion_blur_samples must be in [0, 64]");
  check(rig.exposure_time > 0, "exposure_time must be > 0");
  K_.width = rig.width;
  K_.height = rig.height;
  K_.fx = 0.5 * rig.width / std::tan(0.5 * rig.hfov_deg * kPi / 180.0);
  K_.fy = 0.5 * rig.height / std::tan(0.5 * rig.vfov_deg * kPi / 180.0);
  K_.cx = 0.5 * (rig.width - 1);
  K_.cy = 0.5 * (rig.height - 1);
  K_.baseline = rig.baseline;
}

void StereoRenderer::render_view(const geometry::SE3& T_world_cam, cv::Mat& radiance, cv::Mat* depth) const {
  const int W = K_.width, H = K_.height;
  const bool color = rig_.color;
  radiance.create(H, W, color ? CV_32FC3 : CV_32FC1);
  if (depth) depth->create(H, W, CV_32F);

  const Eigen::Matrix3d R = T_world_cam.rotation_matrix();
  const Eigen::Vector3d o = T_world_cam.translation();
  auto to3 = [](const Eigen::Vector3d& v) {
    return Vec3f{static_cast<float>(v.x()), static_cast<float>(v.y()), static_cast<float>(v.z())};
  };
  // Ray of pixel (u, v): d = r2 + x r0 + y r1 with x = (u - cx) / fx, y = (v - cy) / fy;
  // its camera z component is 1, so the hit parameter t is the depth.
  const Vec3f r0 = to3(R.col(0)), r1 = to3(R.col(1)), r2 = to3(R.col(2));
  // Pixel steps of the ray, for the texture footprint (ray differentials).
  const Vec3f du = to3(R.col(0) / K_.fx), dv = to3(R.col(1) / K_.fy);
  const Vec3f of = to3(o);

  const auto& room = world_.bounds();
  const auto& surfaces = world_.surfaces();
  const auto& textures = world_.textures().surfaces;
  const auto& obstacles = world_.obstacles();

  // Per obstacle: its corners relative to the camera, and the image rows/columns it can
  // cover (whole image when part of it is behind the camera).
  struct Box {
    float lo[3], hi[3];
    int u0, u1, v0, v1;
    int index;
  };
  std::vector<Box> boxes;
  const geometry::SE3 T_cam_world = T_world_cam.inverse();
  for (size_t i = 0; i < obstacles.size(); ++i) {
    const Aabb& b = obstacles[i].box;
    Box bx;
    for (int a = 0; a < 3; ++a) {
      bx.lo[a] = static_cast<float>(b.min[a] - o[a]);
      bx.hi[a] = static_cast<float>(b.max[a] - o[a]);
    }
    bx.index = static_cast<int>(i);
    double umin = 1e18, umax = -1e18, vmin = 1e18, vmax = -1e18;
    bool behind = false, all_behind = true;
    for (int c = 0; c < 8; ++c) {
      const Eigen::Vector3d p(c & 1 ? b.max.x() : b.min.x(), c & 2 ? b.max.y() : b.min.y(),
                              c & 4 ? b.max.z() : b.min.z());
      const Eigen::Vector3d q = T_cam_world * p;
      if (q.z() <= 1e-6) {
        behind = true;
        continue;
      }
      all_behind = false;
      const double u = K_.fx * q.x() / q.z() + K_.cx, v = K_.fy * q.y() / q.z() + K_.cy;
      umin = std::min(umin, u);
      umax = std::max(umax, u);
      vmin = std::min(vmin, v);
      vmax = std::max(vmax, v);
    }
    if (all_behind) continue;
    if (behind) {
      bx.u0 = 0;
      bx.u1 = W - 1;
      bx.v0 = 0;
      bx.v1 = H - 1;
    } else {
      bx.u0 = static_cast<int>(std::max(0.0, std::floor(umin) - 1));
      bx.u1 = static_cast<int>(std::min(W - 1.0, std::ceil(umax) + 1));
      bx.v0 = static_cast<int>(std::max(0.0, std::floor(vmin) - 1));
      bx.v1 = static_cast<int>(std::min(H - 1.0, std::ceil(vmax) + 1));
      if (bx.u0 > bx.u1 || bx.v0 > bx.v1) continue;
    }
    boxes.push_back(bx);
  }

  float room_lo[3], room_hi[3];
  for (int a = 0; a < 3; ++a) {
    room_lo[a] = static_cast<float>(room.min[a] - o[a]);
    room_hi[a] = static_cast<float>(room.max[a] - o[a]);
  }
  const float inv_fx = static_cast<float>(1.0 / K_.fx), inv_fy = static_cast<float>(1.0 / K_.fy);
  const float cx = static_cast<float>(K_.cx), cy = static_cast<float>(K_.cy);
  const float nan = std::numeric_limits<float>::quiet_NaN();

  // Rows are independent: stripes may run in parallel (cv::setNumThreads(1) for one core);
  // the result does not depend on the split.
  cv::parallel_for_(cv::Range(0, H), [&](const cv::Range& rows) {
    std::vector<const Box*> row_boxes;
    row_boxes.reserve(boxes.size());
    for (int v = rows.start; v < rows.end; ++v) {
      row_boxes.clear();
      for (const auto& b : boxes)
        if (v >= b.v0 && v <= b.v1) row_boxes.push_back(&b);
      const float y = (static_cast<float>(v) - cy) * inv_fy;
      float* out = radiance.ptr<float>(v);
      float* zrow = depth ? depth->ptr<float>(v) : nullptr;
      for (int u = 0; u < W; ++u) {
        const float x = (static_cast<float>(u) - cx) * inv_fx;
        const float d[3] = {r2[0] + x * r0[0] + y * r1[0], r2[1] + x * r0[1] + y * r1[1], r2[2] + x * r0[2] + y * r1[2]};
        const float inv[3] = {1.f / d[0], 1.f / d[1], 1.f / d[2]};
        // Room: the exit face.
        float t = std::numeric_limits<float>::infinity();
        int surface = -1;
        for (int a = 0; a < 3; ++a) {
          const bool pos = d[a] > 0.f;
          const float ta = (pos ? room_hi[a] : room_lo[a]) * inv[a];
          if (ta < t) {
            t = ta;
            surface = 2 * a + pos;
          }
        }
        // Obstacles: the entry face of the nearest one.
        for (const Box* b : row_boxes) {
          if (u < b->u0 || u > b->u1) continue;
          // Slab test, branch-free; the entry axis is only worked out for a nearer hit.
          const float ax1 = b->lo[0] * inv[0], ax2 = b->hi[0] * inv[0];
          const float ay1 = b->lo[1] * inv[1], ay2 = b->hi[1] * inv[1];
          const float az1 = b->lo[2] * inv[2], az2 = b->hi[2] * inv[2];
          const float nx = min_f(ax1, ax2), ny = min_f(ay1, ay2), nz = min_f(az1, az2);
          const float t_near = max_f(nx, max_f(ny, nz));
          const float t_far = min_f(max_f(ax1, ax2), min_f(max_f(ay1, ay2), max_f(az1, az2)));
          if (t_near <= t_far && t_near > 0.f && t_near < t) {
            t = t_near;
            const int axis = t_near == nx ? 0 : (t_near == ny ? 1 : 2);
            surface = 6 + 6 * b->index + 2 * axis + (d[axis] > 0.f ? 0 : 1);
          }
        }
        if (surface < 0 || !std::isfinite(t)) {
          if (color) {
            out[3 * u] = out[3 * u + 1] = out[3 * u + 2] = 0.f;
          } else {
            out[u] = 0.f;
          }
          if (zrow) zrow[u] = nan;
          continue;
        }
        const Surface& s = surfaces[surface];
        const MipTexture& tex = textures[surface];
        const int k = s.axis;
        // Texture coordinates (level-0 texels, centres on integers).
        const float density = tex.texels_per_metre();
        const float pu = of[s.u_axis] + t * d[s.u_axis], pv = of[s.v_axis] + t * d[s.v_axis];
        const float tu = (pu - static_cast<float>(s.u0)) * density - 0.5f;
        const float tv = static_cast<float>(s.v_sign) * (pv - static_cast<float>(s.v0)) * density - 0.5f;
        // Footprint: dP/du = t (du - d du_k / d_k) (plane x_k = const), same for v.
        // Only the two in-plane axes: the k component is zero by construction.
        const float ku = du[k] * inv[k], kv = dv[k] * inv[k];
        const int a1 = s.u_axis, a2 = s.v_axis;
        const float eu1 = du[a1] - d[a1] * ku, eu2 = du[a2] - d[a2] * ku;
        const float ev1 = dv[a1] - d[a1] * kv, ev2 = dv[a2] - d[a2] * kv;
        const float fu2 = eu1 * eu1 + eu2 * eu2, fv2 = ev1 * ev1 + ev2 * ev2;
        const float f2 = max_f(fu2, fv2) * t * t * density * density;
        const float lod = f2 > 1.f ? 0.5f * fast_log2(f2) : 0.f;
        const float value = s.shade * tex.trilinear(tu, tv, lod);
        if (color) {
          out[3 * u] = value * s.tint[0];
          out[3 * u + 1] = value * s.tint[1];
          out[3 * u + 2] = value * s.tint[2];
        } else {
          out[u] = value;
        }
        if (zrow) zrow[u] = t;
      }
    }
  });
}

void StereoRenderer::project_helipad(const geometry::SE3& T_world_left, StereoFrame& f) const {
  const Helipad& pad = world_.helipad();
  const auto corners = pad.corners();
  const geometry::SE3 T_cam_world = T_world_left.inverse();
  const Eigen::Vector3d o = T_world_left.translation();
  bool visible = true;
  double umin = 1e18, umax = -1e18, vmin = 1e18, vmax = -1e18;
  const double nan = std::numeric_limits<double>::quiet_NaN();
  for (int i = 0; i < 4; ++i) {
    const Eigen::Vector3d q = T_cam_world * corners[i];
    if (q.z() <= 1e-6) {
      f.target_corners[i] = {nan, nan};
      visible = false;
      continue;
    }
    const double u = K_.fx * q.x() / q.z() + K_.cx, v = K_.fy * q.y() / q.z() + K_.cy;
    f.target_corners[i] = {u, v};
    umin = std::min(umin, u);
    umax = std::max(umax, u);
    vmin = std::min(vmin, v);
    vmax = std::max(vmax, v);
    // Inside the image (pixel centres at integers: the image spans [-0.5, size - 0.5]).
    if (u < -0.5 || v < -0.5 || u > K_.width - 0.5 || v > K_.height - 0.5) visible = false;
    // Not hidden by an obstacle: the line of sight reaches the corner.
    const auto hit = world_.raycast(o, corners[i] - o);
    if (hit && hit->t < 1.0 - 1e-6) visible = false;
  }
  f.target_visible = visible;
  f.target_box = umin <= umax ? cv::Rect2d(umin, vmin, umax - umin, vmax - vmin) : cv::Rect2d();
  if (!visible && std::isnan(f.target_corners[0].x + f.target_corners[1].x + f.target_corners[2].x +
                             f.target_corners[3].x))
    f.target_box = cv::Rect2d();
}

StereoFrame StereoRenderer::render(const geometry::SE3& T_world_left, int64_t utime, int64_t seq,
                                   const std::vector<geometry::SE3>& blur_poses) const {
  return render_views(T_world_left, utime, seq, blur_poses, true);
}

StereoFrame StereoRenderer::render_mono(const geometry::SE3& T_world_cam, int64_t utime, int64_t seq,
                                        const std::vector<geometry::SE3>& blur_poses) const {
  return render_views(T_world_cam, utime, seq, blur_poses, false);
}

StereoFrame StereoRenderer::render_views(const geometry::SE3& T_world_left, int64_t utime, int64_t seq,
                                         const std::vector<geometry::SE3>& blur_poses, bool with_right) const {
  StereoFrame f;
  f.utime = utime;
  f.seq = seq;
  f.T_world_left = T_world_left;
  cv::Mat rad_left, rad_right;
  const geometry::SE3 T_left_right(Eigen::Quaterniond::Identity(), Eigen::Vector3d(rig_.baseline, 0, 0));
  if (blur_poses.empty()) {
    render_view(T_world_left, rad_left, &f.depth);
    if (with_right) render_view(T_world_left * T_left_right, rad_right, nullptr);
  } else {
    // Motion blur: the sensor integrates the radiance over the exposure.
    render_view(T_world_left, rad_left, &f.depth);
    rad_left.setTo(0);
    if (with_right) rad_right = cv::Mat::zeros(rad_left.size(), rad_left.type());
    cv::Mat l, r;
    for (const auto& T : blur_poses) {
      render_view(T, l, nullptr);
      rad_left += l;
      if (!with_right) continue;
      render_view(T * T_left_right, r, nullptr);
      rad_right += r;
    }
    rad_left /= static_cast<double>(blur_poses.size());
    if (with_right) rad_right /= static_cast<double>(blur_poses.size());
  }

  // Photometry: exposure, slow illumination change, right camera gain, noise.
  const double t = utime * 1e-6;
  const double gain =
      rig_.exposure * (1.0 + rig_.illumination_amplitude * std::sin(2 * kPi * t / rig_.illumination_period));
  const int type = rig_.color ? CV_8UC3 : CV_8UC1;
  auto finish = [&](cv::Mat& rad, double g, uint64_t stream, cv::Mat& out) {
    if (rig_.noise_sigma > 0) {
      cv::Mat noise(rad.size(), rad.type());
      cv::RNG rng(mix_seed(rig_.noise_seed, 2 * static_cast<uint64_t>(seq) + stream));
      rng.fill(noise, cv::RNG::NORMAL, 0.0, rig_.noise_sigma / g);
      rad += noise;
    }
    rad.convertTo(out, type, g);
  };
  finish(rad_left, gain, 0, f.left);
  if (with_right) finish(rad_right, gain * rig_.right_gain, 1, f.right);
  if (rig_.disparity) {
    f.disparity.create(f.depth.size(), CV_32F);
    const float fb = static_cast<float>(K_.fx * rig_.baseline);
    cv::divide(fb, f.depth, f.disparity);
  }
  project_helipad(T_world_left, f);
  return f;
}

}  // namespace aerie::sim
