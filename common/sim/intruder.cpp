#include "common/sim/intruder.hpp"

#include <opencv2/imgproc.hpp>

#include <algorithm>
#include <cmath>
#include <stdexcept>
#include <string>

#include "common/sim/texture.hpp"

namespace aerie::sim {

namespace {

// Aircraft seen from below, in units of its wingspan, nose towards +x, y to the left wing.
using Polygon = std::vector<cv::Point2d>;

std::vector<Polygon> aircraft_parts() {
  std::vector<Polygon> parts;
  Polygon fuselage;
  for (int i = 0; i < 48; ++i) {
    const double a = 2 * CV_PI * i / 48.0;
    const double x = 0.42 * std::cos(a);
    // blunter tail than nose
    const double y = (x > 0 ? 0.05 : 0.045) * std::sin(a) * (x < -0.3 ? 0.7 : 1.0);
    fuselage.emplace_back(x, y);
  }
  parts.push_back(fuselage);
  parts.push_back({{0.12, 0.0}, {0.0, 0.5}, {-0.1, 0.5}, {-0.05, 0.0}, {-0.1, -0.5}, {0.0, -0.5}});  // wings
  parts.push_back({{-0.30, 0.0}, {-0.37, 0.17}, {-0.43, 0.17}, {-0.41, 0.0}, {-0.43, -0.17}, {-0.37, -0.17}});  // tail
  for (double side : {-1.0, 1.0}) {  // engine nacelles
    Polygon n;
    for (int i = 0; i < 24; ++i) {
      const double a = 2 * CV_PI * i / 24.0;
      n.emplace_back(0.08 + 0.09 * std::cos(a), side * 0.2 + 0.03 * std::sin(a));
    }
    parts.push_back(n);
  }
  return parts;
}

}  // namespace

cv::RNG IntruderScene::build(const std::vector<IntruderPose>& path) {
  const IntruderConfig& cfg = config_;
  auto check = [](bool ok, const std::string& what) {
    if (!ok) throw std::invalid_argument("sim::IntruderConfig: " + what);
  };
  check(cfg.width >= 64 && cfg.height >= 64, "width and height must be >= 64");
  check(cfg.frames >= 1, "frames must be >= 1");
  check(cfg.rate_hz > 0, "rate_hz must be > 0");
  check(cfg.vibration_px >= 0 && cfg.noise_sigma >= 0, "vibration_px and noise_sigma must be >= 0");
  check(cfg.wingspan_px >= 8 && cfg.wingspan_px < 0.8 * cfg.width, "wingspan_px must be in [8, 0.8 width)");
  check(cfg.scale_change > 0.2 && cfg.scale_change < 5, "scale_change must be in (0.2, 5)");

  cv::RNG rng(mix_seed(cfg.seed, 11));

  // Camera vibration: a mean-reverting random walk of the whole image.
  std::vector<cv::Point2d> jitter(cfg.frames);
  cv::Point2d j(0, 0);
  for (int k = 0; k < cfg.frames; ++k) {
    // One draw per statement: a call's arguments are evaluated in an unspecified order (x86-64
    // GCC right to left, arm64 left to right); this is x86's order, now on every architecture.
    const double jy = rng.gaussian(cfg.vibration_px);
    j = 0.9 * j + cv::Point2d(rng.gaussian(cfg.vibration_px), jy);
    jitter[k] = j;
  }
  double max_jitter = 0;
  for (const auto& p : jitter) max_jitter = std::max({max_jitter, std::abs(p.x), std::abs(p.y)});
  const int margin = static_cast<int>(std::ceil(max_jitter)) + 4;

  // Sky: brighter towards the horizon, clouds from thresholded multi-scale noise; it spans
  // the image, the vibration and every pan of the path.
  cv::Point2d lo(0, 0), hi(0, 0);
  for (const auto& p : path) {
    lo = {std::min(lo.x, p.pan.x), std::min(lo.y, p.pan.y)};
    hi = {std::max(hi.x, p.pan.x), std::max(hi.y, p.pan.y)};
  }
  const cv::Size sky_size(cfg.width + 2 * margin + cvCeil(hi.x - lo.x), cfg.height + 2 * margin + cvCeil(hi.y - lo.y));
  sky_origin_ = cv::Point2d(margin, margin) - lo;
  const cv::Mat n = value_noise(sky_size, 0.5 * (cfg.width + 2 * margin), 7, 0.55, mix_seed(cfg.seed, 12));
  sky_.create(sky_size, CV_32FC3);
  const double cover = rng.uniform(0.38, 0.5);
  for (int y = 0; y < sky_size.height; ++y) {
    const double h = static_cast<double>(y) / sky_size.height;
    const cv::Vec3f blue(static_cast<float>(200 + 40 * h), static_cast<float>(140 + 60 * h),
                         static_cast<float>(80 + 80 * h));
    for (int x = 0; x < sky_size.width; ++x) {
      const double c = std::clamp((n.at<float>(y, x) - cover) * 6.0, 0.0, 1.0);  // cloud density
      const float white = static_cast<float>(235 - 70 * std::pow(n.at<float>(y, x), 3.0));
      const cv::Vec3f cloud(white, white, white);
      sky_.at<cv::Vec3f>(y, x) = (1.0f - static_cast<float>(c)) * blue + static_cast<float>(c) * cloud;
    }
  }

  // Sprite: the aircraft at a high resolution, textured (panel noise, markings).
  const double span = 400.0;
  const int side = static_cast<int>(span * 1.1);
  sprite_ref_ = {0.5 * side, 0.5 * side};
  sprite_span_px_ = span;
  const auto parts = aircraft_parts();
  auto to_sprite = [&](const cv::Point2d& p) {  // nose to the right, left wing up
    return cv::Point2d(sprite_ref_.x + span * p.x, sprite_ref_.y - span * p.y);
  };
  cv::Mat alpha8 = cv::Mat::zeros(side, side, CV_8U);
  constexpr int kShift = 3;
  outline_.clear();
  for (const auto& part : parts) {
    std::vector<cv::Point> poly;
    for (const auto& p : part) {
      const cv::Point2d q = to_sprite(p);
      outline_.push_back(q);
      poly.emplace_back(cvRound(q.x * (1 << kShift)), cvRound(q.y * (1 << kShift)));
    }
    cv::fillPoly(alpha8, std::vector<std::vector<cv::Point>>{poly}, cv::Scalar(255), cv::LINE_AA, kShift);
  }
  alpha8.convertTo(sprite_alpha_, CV_32F, 1.0 / 255.0);
  const cv::Mat body = value_noise(cv::Size(side, side), 60, 5, 0.6, mix_seed(cfg.seed, 13));
  cv::Mat paint(side, side, CV_32FC3);
  for (int y = 0; y < side; ++y)
    for (int x = 0; x < side; ++x) {
      const float g = static_cast<float>(40 + 110 * body.at<float>(y, x));
      paint.at<cv::Vec3f>(y, x) = cv::Vec3f(g, g, g);
    }
  // Markings: a dark stripe along the fuselage, roundels on the wings, a dark tail band.
  cv::line(paint, to_sprite({-0.4, 0.0}), to_sprite({0.4, 0.0}), cv::Scalar(60, 40, 150), 10, cv::LINE_AA);
  for (double s : {-1.0, 1.0}) {
    cv::circle(paint, to_sprite({-0.04, s * 0.36}), 22, cv::Scalar(150, 60, 30), cv::FILLED, cv::LINE_AA);
    cv::circle(paint, to_sprite({-0.04, s * 0.36}), 10, cv::Scalar(230, 230, 230), cv::FILLED, cv::LINE_AA);
    cv::line(paint, to_sprite({0.0, s * 0.5}), to_sprite({0.1, s * 0.08}), cv::Scalar(40, 40, 40), 6, cv::LINE_AA);
  }
  cv::rectangle(paint, to_sprite({-0.43, 0.17}), to_sprite({-0.39, -0.17}), cv::Scalar(40, 40, 40), cv::FILLED);
  cv::circle(paint, to_sprite({0.36, 0.0}), 12, cv::Scalar(30, 30, 30), cv::FILLED, cv::LINE_AA);  // cockpit
  sprite_ = paint;
  if (!cfg.color) {  // compose in the output format
    cv::cvtColor(sprite_, sprite_, cv::COLOR_BGR2GRAY);
    cv::cvtColor(sky_, sky_, cv::COLOR_BGR2GRAY);
  }
  jitter_ = std::move(jitter);
  return rng;
}

IntruderScene::IntruderScene(const IntruderConfig& cfg) : config_(cfg) {
  cv::RNG rng = build({});

  // Motion: crossing the image (direction from the seed) on a gentle arc, approaching
  // (growing), with a slow bank.
  const bool left_to_right = rng.uniform(0, 2) == 0;
  const double y0 = rng.uniform(0.35, 0.65) * cfg.height, arc = rng.uniform(-0.12, 0.12) * cfg.height;
  const double phase = rng.uniform(0.0, 2 * CV_PI);
  motion_.resize(cfg.frames);
  for (int k = 0; k < cfg.frames; ++k) {
    const double f = cfg.frames > 1 ? static_cast<double>(k) / (cfg.frames - 1) : 0.0;
    Motion& m = motion_[k];
    m.scale = std::pow(cfg.scale_change, f);
    const double x = (0.18 + 0.64 * f) * cfg.width;
    m.center = {left_to_right ? x : cfg.width - x, y0 + arc * std::sin(CV_PI * f)};
    m.angle = cfg.max_roll_deg * CV_PI / 180.0 * std::sin(2 * CV_PI * 0.8 * f + phase);
    if (!left_to_right) m.angle += CV_PI;  // nose to the left
    m.jitter = jitter_[k];
  }
}

IntruderScene::IntruderScene(const IntruderConfig& cfg, const std::vector<IntruderPose>& path) : config_(cfg) {
  config_.frames = static_cast<int>(path.size());
  build(path);
  motion_.resize(path.size());
  for (size_t k = 0; k < path.size(); ++k)
    motion_[k] = {path[k].center, path[k].scale, path[k].angle, jitter_[k], path[k].pan};
}

MonoFrame IntruderScene::frame(int k) const {
  if (k < 0 || k >= config_.frames)
    throw std::out_of_range("sim::IntruderScene::frame: " + std::to_string(k) + " not in [0, " +
                            std::to_string(config_.frames) + ")");
  const Motion& m = motion_[k];
  const cv::Size size(config_.width, config_.height);
  // Background shifted by the vibration (sub-pixel).
  const cv::Matx23d Mb(1, 0, m.jitter.x - m.pan.x - sky_origin_.x, 0, 1, m.jitter.y - m.pan.y - sky_origin_.y);
  cv::Mat img;
  cv::warpAffine(sky_, img, Mb, size, cv::INTER_LINEAR, cv::BORDER_REFLECT);
  // Aircraft: similarity sprite -> image.
  const double s = config_.wingspan_px * m.scale / sprite_span_px_;
  const double c = s * std::cos(m.angle), sn = s * std::sin(m.angle);
  const cv::Point2d t = m.center - m.pan + m.jitter;
  // image = [c -sn; sn c] (p - ref) + t   (counter-clockwise on screen is -angle in y-down)
  const cv::Matx23d M(c, sn, t.x - c * sprite_ref_.x - sn * sprite_ref_.y,
                      -sn, c, t.y + sn * sprite_ref_.x - c * sprite_ref_.y);
  // Ground truth: bounding box of the transformed silhouette outline.
  double x0 = 1e18, y0 = 1e18, x1 = -1e18, y1 = -1e18;
  for (const auto& p : outline_) {
    const double u = M(0, 0) * p.x + M(0, 1) * p.y + M(0, 2), v = M(1, 0) * p.x + M(1, 1) * p.y + M(1, 2);
    x0 = std::min(x0, u);
    x1 = std::max(x1, u);
    y0 = std::min(y0, v);
    y1 = std::max(y1, v);
  }
  // Warp the sprite only into the region it covers and blend it by its alpha.
  const cv::Rect roi = cv::Rect(cvFloor(x0) - 2, cvFloor(y0) - 2, cvCeil(x1 - x0) + 5, cvCeil(y1 - y0) + 5) &
                       cv::Rect(0, 0, size.width, size.height);
  if (config_.draw_target && roi.area() > 0) {
    cv::Matx23d Mr = M;
    Mr(0, 2) -= roi.x;
    Mr(1, 2) -= roi.y;
    cv::Mat plane, alpha;
    cv::warpAffine(sprite_, plane, Mr, roi.size(), cv::INTER_LINEAR, cv::BORDER_CONSTANT);
    cv::warpAffine(sprite_alpha_, alpha, Mr, roi.size(), cv::INTER_LINEAR, cv::BORDER_CONSTANT);
    cv::Mat dst = img(roi);
    const int cn = img.channels();
    for (int y = 0; y < roi.height; ++y) {
      float* d = dst.ptr<float>(y);
      const float* src = plane.ptr<float>(y);
      const float* a = alpha.ptr<float>(y);
      for (int x = 0; x < roi.width; ++x)
        for (int ch = 0; ch < cn; ++ch) d[cn * x + ch] += a[x] * (src[cn * x + ch] - d[cn * x + ch]);
    }
  }
  MonoFrame f;
  f.seq = k;
  f.utime = config_.start_utime + static_cast<int64_t>(std::llround(k / config_.rate_hz * 1e6));
  if (config_.noise_sigma > 0) {
    cv::Mat noise(img.size(), img.type());
    cv::RNG rng(mix_seed(config_.seed, 1000 + static_cast<uint64_t>(k)));
    rng.fill(noise, cv::RNG::NORMAL, 0.0, config_.noise_sigma);
    img += noise;
  }
  img.convertTo(f.image, config_.color ? CV_8UC3 : CV_8UC1);
  f.target_box = cv::Rect2d(x0, y0, x1 - x0, y1 - y0);
  f.target_visible = x0 >= 0 && y0 >= 0 && x1 <= size.width && y1 <= size.height;
  f.target_center = t;
  f.target_scale = m.scale;
  f.target_angle = m.angle;
  return f;
}

bool IntruderScene::next(MonoFrame& f) {
  if (next_ >= config_.frames) return false;
  f = frame(next_++);
  return true;
}

}  // namespace aerie::sim
