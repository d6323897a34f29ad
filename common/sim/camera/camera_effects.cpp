#include "common/sim/camera/camera_effects.hpp"

#include <opencv2/calib3d.hpp>
#include <opencv2/imgcodecs.hpp>
#include <opencv2/imgproc.hpp>

#include <algorithm>
#include <cmath>
#include <limits>
#include <stdexcept>

namespace aerie::sim {

namespace {

constexpr double kPi = 3.14159265358979323846;

// Normalised rays (x, y) of the given distorted pixels of `m`, to 1e-12 (the real camera's
// inverse projection, as camera::CameraModel::unproject).
std::vector<cv::Point2d> rays_of(const camera::CameraModel& m, const std::vector<cv::Point2d>& px) {
  std::vector<cv::Point2d> out;
  const cv::TermCriteria crit(cv::TermCriteria::COUNT | cv::TermCriteria::EPS, 50, 1e-12);
  if (m.distortion == camera::Distortion::Equidistant) {
    cv::fisheye::undistortPoints(px, out, m.K(), m.D(), cv::noArray(), cv::noArray(), crit);
  } else {
    cv::undistortPoints(px, out, m.K(), m.D(), cv::noArray(), cv::noArray(), crit);
  }
  return out;
}

// One Poisson draw: Knuth's product of uniforms below 30 electrons, the normal
// approximation N(lambda, lambda) above (its skewness 1/sqrt(lambda) < 0.19 there).
double poisson(cv::RNG& rng, double lambda) {
  if (lambda <= 0) return 0;
  if (lambda >= 30) return std::max(0.0, lambda + std::sqrt(lambda) * rng.gaussian(1.0));
  const double limit = std::exp(-lambda);
  double p = 1.0;
  int k = -1;
  do {
    ++k;
    p *= rng.uniform(0.0, 1.0);
  } while (p > limit);
  return k;
}

}  // namespace

void CameraEffectsConfig::validate(const std::string& what) const {
  auto need = [&](bool ok, const std::string& msg) {
    if (!ok) throw std::invalid_argument(what + ": " + msg);
  };
  if (lens.enabled && lens.model.width > 0) lens.model.validate(what + " lens");
  need(motion.max_blur_samples >= 1 && motion.max_blur_samples <= 256, "motion_blur.max_samples must be in [1, 256]");
  need(motion.line_delay_s >= 0 && motion.line_delay_s < 1e-2, "rolling_shutter.line_delay_s must be in [0, 0.01)");
  need(motion.readout_time_s >= 0 && motion.readout_time_s < 1, "rolling_shutter.readout_time_s must be in [0, 1)");
  need(!motion.rolling_shutter || motion.line_delay_s > 0 || motion.readout_time_s > 0,
       "rolling_shutter needs line_delay_s or readout_time_s > 0");
  const auto& e = exposure;
  need(e.exposure_time_s > 0 && e.exposure_time_s < 1, "exposure.exposure_time_s must be in (0, 1)");
  need(e.min_exposure_time_s > 0 && e.min_exposure_time_s <= e.max_exposure_time_s && e.max_exposure_time_s < 1,
       "exposure: need 0 < min_exposure_time_s <= max_exposure_time_s < 1");
  need(e.gain >= 1 && e.max_gain >= 1 && e.gain <= e.max_gain, "exposure: need 1 <= gain <= max_gain");
  need(e.target_mean > 0 && e.target_mean < 1, "exposure.target_mean must be in (0, 1)");
  need(e.time_constant_s > 0, "exposure.time_constant_s must be > 0");
  need(noise.full_well_e >= 100 && noise.full_well_e <= 1e6, "noise.full_well_e must be in [100, 1e6]");
  need(noise.read_noise_e >= 0 && noise.read_noise_e <= 1000, "noise.read_noise_e must be in [0, 1000]");
  need(jpeg.quality >= 1 && jpeg.quality <= 100, "jpeg.quality must be in [1, 100]");
}

Eigen::Vector2d image_flow(const CameraMotion& m, double fx, double fy, double cx, double cy, double u, double v,
                           double z) {
  const double x = (u - cx) / fx, y = (v - cy) / fy;
  const double iz = std::isfinite(z) && z > 0 ? 1.0 / z : 0.0;
  const Eigen::Vector3d& t = m.velocity;
  const Eigen::Vector3d& w = m.angular_velocity;
  // Chaumette & Hutchinson, "Visual servo control I" (2006), eq. 11.
  const double xd = (-t.x() + x * t.z()) * iz + x * y * w.x() - (1 + x * x) * w.y() + y * w.z();
  const double yd = (-t.y() + y * t.z()) * iz + (1 + y * y) * w.x() - x * y * w.y() - x * w.z();
  return {fx * xd, fy * yd};
}

std::pair<double, double> CameraEffects::fov_to_cover(const camera::CameraModel& lens) {
  std::vector<cv::Point2d> border;
  const double W = lens.width, H = lens.height;
  for (int u = 0; u <= lens.width; ++u) {
    border.emplace_back(u - 0.5, -0.5);
    border.emplace_back(u - 0.5, H - 0.5);
  }
  for (int v = 0; v <= lens.height; ++v) {
    border.emplace_back(-0.5, v - 0.5);
    border.emplace_back(W - 0.5, v - 0.5);
  }
  const double cap = std::tan(89.0 * kPi / 180.0);
  double ax = 0, ay = 0;
  for (const auto& r : rays_of(lens, border)) {
    ax = std::max(ax, std::min(cap, std::abs(r.x)));
    ay = std::max(ay, std::min(cap, std::abs(r.y)));
  }
  return {2 * std::atan(ax) * 180 / kPi, 2 * std::atan(ay) * 180 / kPi};
}

CameraEffects::CameraEffects(const CameraEffectsConfig& config, const camera::CameraModel& ideal,
                             const std::string& what)
    : cfg_(config), ideal_(ideal) {
  cfg_.validate(what);
  ideal_.validate(what + " (ideal camera)");
  if (ideal_.distortion != camera::Distortion::None)
    throw std::invalid_argument(what + ": the ideal camera must be a pinhole without distortion");
  const int W = ideal_.width, H = ideal_.height;
  lens_x_.create(H, W, CV_32F);
  lens_y_.create(H, W, CV_32F);
  if (cfg_.lens.enabled) {
    camera::CameraModel& lens = cfg_.lens.model;
    if (lens.width == 0) {  // coefficients on the ideal intrinsics
      const auto d = lens.distortion;
      const auto c = lens.coeffs;
      lens = ideal_;
      lens.distortion = d;
      lens.coeffs = c;
      lens.validate(what + " lens");
    }
    if (lens.width != W || lens.height != H)
      throw std::invalid_argument(what + ": the lens calibration is for " + std::to_string(lens.width) + "x" +
                                  std::to_string(lens.height) + " but the camera renders " + std::to_string(W) + "x" +
                                  std::to_string(H));
    std::vector<cv::Point2d> px;
    px.reserve(static_cast<size_t>(W) * H);
    for (int v = 0; v < H; ++v)
      for (int u = 0; u < W; ++u) px.emplace_back(u, v);
    const auto rays = rays_of(lens, px);
    size_t inside = 0;
    for (int v = 0; v < H; ++v) {
      float* mx = lens_x_.ptr<float>(v);
      float* my = lens_y_.ptr<float>(v);
      for (int u = 0; u < W; ++u) {
        const cv::Point2d& r = rays[static_cast<size_t>(v) * W + u];
        const double ui = ideal_.fx * r.x + ideal_.cx, vi = ideal_.fy * r.y + ideal_.cy;
        mx[u] = static_cast<float>(ui);
        my[u] = static_cast<float>(vi);
        inside += ui >= -0.5 && vi >= -0.5 && ui <= W - 0.5 && vi <= H - 0.5;
      }
    }
    coverage_ = static_cast<double>(inside) / (static_cast<double>(W) * H);
  } else {
    for (int v = 0; v < H; ++v)
      for (int u = 0; u < W; ++u) {
        lens_x_.at<float>(v, u) = static_cast<float>(u);
        lens_y_.at<float>(v, u) = static_cast<float>(v);
      }
  }
  if (cfg_.motion.rolling_shutter)
    line_delay_ = cfg_.motion.line_delay_s > 0 ? cfg_.motion.line_delay_s : cfg_.motion.readout_time_s / H;
  exposure_time_ = cfg_.exposure.exposure_time_s;
  gain_ = cfg_.exposure.gain;
}

cv::Mat CameraEffects::apply(const cv::Mat& ideal, const cv::Mat& depth, const CameraMotion& motion, int64_t utime,
                             int64_t seq) {
  if (!cfg_.any()) return ideal;
  const int W = ideal_.width, H = ideal_.height;
  if (ideal.cols != W || ideal.rows != H || ideal.depth() != CV_8U || (ideal.channels() != 1 && ideal.channels() != 3))
    throw std::invalid_argument("camera effects: the frame is " + std::to_string(ideal.cols) + "x" +
                                std::to_string(ideal.rows) + " with " + std::to_string(ideal.channels()) +
                                " channels; expected 8-bit gray or BGR " + std::to_string(W) + "x" + std::to_string(H));
  if (!depth.empty() && (depth.size() != ideal.size() || depth.type() != CV_32F))
    throw std::invalid_argument("camera effects: the depth map must be CV_32F of the frame's size");
  const auto& E = cfg_.exposure;

  // Auto-exposure from the previous frame's statistics: the total exposure (time x gain)
  // follows log(E*) = log(E * target / mean) through a first-order lag of time constant tau,
  // exactly discretised over the frame interval; time first, then gain, within their limits.
  if (E.auto_exposure && has_last_) {
    const double dt = std::max(0.0, (utime - last_utime_) * 1e-6);
    const double alpha = 1.0 - std::exp(-dt / E.time_constant_s);
    const double total = exposure_time_ * gain_;
    const double wanted = total * E.target_mean / std::max(last_mean_, 1.0 / 255);
    const double next = std::exp(std::log(total) + alpha * (std::log(wanted) - std::log(total)));
    exposure_time_ = std::clamp(next, E.min_exposure_time_s, E.max_exposure_time_s);
    gain_ = std::clamp(next / exposure_time_, 1.0, E.max_gain);
  }

  // Geometry: lens, then the shift of each sub-exposure sample along the flow.
  cv::Mat src;
  ideal.convertTo(src, CV_32FC(ideal.channels()));
  cv::Mat geo;
  const bool moving = cfg_.motion.motion_blur || cfg_.motion.rolling_shutter;
  if (!moving && !cfg_.lens.enabled) {
    geo = src;
  } else if (!moving) {
    cv::remap(src, geo, lens_x_, lens_y_, cv::INTER_LINEAR, cv::BORDER_REPLICATE);
  } else {
    // Flow at the ideal pixel each output pixel sees (depth at the nearest ideal pixel).
    cv::Mat fx(H, W, CV_32F), fy(H, W, CV_32F);
    float max_flow = 0.f;
    for (int v = 0; v < H; ++v) {
      const float* lx = lens_x_.ptr<float>(v);
      const float* ly = lens_y_.ptr<float>(v);
      float* ox = fx.ptr<float>(v);
      float* oy = fy.ptr<float>(v);
      for (int u = 0; u < W; ++u) {
        double z = std::numeric_limits<double>::infinity();
        if (!depth.empty()) {
          const int iu = std::clamp(static_cast<int>(std::lround(lx[u])), 0, W - 1);
          const int iv = std::clamp(static_cast<int>(std::lround(ly[u])), 0, H - 1);
          z = depth.at<float>(iv, iu);
        }
        const Eigen::Vector2d f = image_flow(motion, ideal_.fx, ideal_.fy, ideal_.cx, ideal_.cy, lx[u], ly[u], z);
        ox[u] = static_cast<float>(f.x());
        oy[u] = static_cast<float>(f.y());
        max_flow = std::max(max_flow, static_cast<float>(f.norm()));
      }
    }
    // Row r's exposure is centred (r - r_c) * line delay after the frame time (r_c: the
    // centre row, so the frame time stays the mid-exposure of the image centre); samples
    // split the exposure time into equal parts, at most a pixel of blur apart.
    const double T = cfg_.motion.motion_blur ? exposure_time_ : 0.0;
    const int n = cfg_.motion.motion_blur
                      ? std::clamp(static_cast<int>(std::ceil(max_flow * T)) + 1, 1, cfg_.motion.max_blur_samples)
                      : 1;
    const double rc = 0.5 * (H - 1);
    cv::Mat mx(H, W, CV_32F), my(H, W, CV_32F), sample;
    geo = cv::Mat::zeros(H, W, src.type());
    for (int j = 0; j < n; ++j) {
      const double frac = n > 1 ? (j + 0.5) / n - 0.5 : 0.0;
      for (int v = 0; v < H; ++v) {
        const float s = static_cast<float>((v - rc) * line_delay_ + T * frac);
        const float* lx = lens_x_.ptr<float>(v);
        const float* ly = lens_y_.ptr<float>(v);
        const float* ox = fx.ptr<float>(v);
        const float* oy = fy.ptr<float>(v);
        float* ax = mx.ptr<float>(v);
        float* ay = my.ptr<float>(v);
        for (int u = 0; u < W; ++u) {
          ax[u] = lx[u] - ox[u] * s;  // the point there at time s was here at the frame time
          ay[u] = ly[u] - oy[u] * s;
        }
      }
      cv::remap(src, sample, mx, my, cv::INTER_LINEAR, cv::BORDER_REPLICATE);
      geo += sample;
    }
    if (n > 1) geo /= static_cast<double>(n);
  }

  // Photometry: the ideal frame is the scene at exposure_time_s and unity gain, 255 DN =
  // full well. Electrons e = DN / 255 * full_well * t / t0; DN = e * gain * 255 / full_well.
  const double exposure_scale = exposure_time_ / E.exposure_time_s;
  cv::Mat out;
  if (!cfg_.noise.enabled) {
    geo.convertTo(out, ideal.type(), exposure_scale * gain_);
  } else {
    const auto& N = cfg_.noise;
    cv::RNG rng(N.seed ^ (0x9E3779B97F4A7C15ull * (static_cast<uint64_t>(seq) + 1)));
    out.create(H, W, ideal.type());
    const double to_e = N.full_well_e / 255.0 * exposure_scale, to_dn = gain_ * 255.0 / N.full_well_e;
    const int row_values = W * ideal.channels();
    for (int v = 0; v < H; ++v) {
      const float* g = geo.ptr<float>(v);
      uint8_t* o = out.ptr<uint8_t>(v);
      for (int i = 0; i < row_values; ++i) {
        double e = std::min(poisson(rng, std::max(0.0, static_cast<double>(g[i])) * to_e), N.full_well_e);
        if (N.read_noise_e > 0) e += N.read_noise_e * rng.gaussian(1.0);
        o[i] = cv::saturate_cast<uint8_t>(e * to_dn);
      }
    }
  }
  last_mean_ = cv::mean(out).dot(cv::Scalar::all(1.0 / ideal.channels())) / 255.0;
  last_utime_ = utime;
  has_last_ = true;

  if (cfg_.jpeg.enabled) {
    std::vector<uint8_t> buf;
    cv::imencode(".jpg", out, buf, {cv::IMWRITE_JPEG_QUALITY, cfg_.jpeg.quality});
    out = cv::imdecode(buf, ideal.channels() == 1 ? cv::IMREAD_GRAYSCALE : cv::IMREAD_COLOR);
  }
  return out;
}

}  // namespace aerie::sim
