#include "common/sim/exits.hpp"

#include <opencv2/imgproc.hpp>

#include <algorithm>
#include <cmath>
#include <limits>
#include <stdexcept>

#include "common/sim/texture.hpp"

namespace aerie::sim {

namespace {

constexpr double kNaN = std::numeric_limits<double>::quiet_NaN();
const char* const kKinds[] = {"pan", "drift", "occlusion"};

int kind_index(const std::string& kind) {
  for (int i = 0; i < 3; ++i)
    if (kind == kKinds[i]) return i;
  throw std::invalid_argument("sim::ExitsConfig: unknown exit kind '" + kind + "' (known: pan, drift, occlusion)");
}

// Cosine easing from 0 to 1 over steps 1..n.
double ease(int i, int n) { return 0.5 * (1 - std::cos(CV_PI * i / n)); }

}  // namespace

void validate_exits_config(const ExitsConfig& c) {
  auto check = [](bool ok, const std::string& what) {
    if (!ok) throw std::invalid_argument("sim::ExitsConfig: " + what);
  };
  const IntruderConfig& l = c.look;
  check(l.width >= 64 && l.height >= 64, "width and height must be >= 64");
  check(l.rate_hz > 0, "rate_hz must be > 0");
  check(l.wingspan_px >= 8 && l.wingspan_px * (1 + c.scale_amplitude) <= 0.25 * std::min(l.width, l.height),
        "wingspan_px * (1 + scale_amplitude) must be in [8, 0.25 min(width, height)]");
  check(c.scale_amplitude >= 0 && c.scale_amplitude < 0.5, "scale_amplitude must be in [0, 0.5)");
  check(c.exits >= 0, "exits must be >= 0");
  check(!c.kinds.empty() || c.exits == 0, "kinds must name at least one kind");
  for (const auto& k : c.kinds) kind_index(k);
  check(c.in_frames_min >= 1 && c.in_frames_max >= c.in_frames_min, "need 1 <= in_frames_min <= in_frames_max");
  check(c.out_frames_min >= 1 && c.out_frames_max >= c.out_frames_min,
        "need 1 <= out_frames_min <= out_frames_max");
  check(c.min_visible > 0 && c.min_visible <= 1, "min_visible must be in (0, 1]");
  check(c.pan_speed_px > 0 && c.drift_speed_px > 0, "pan_speed_px and drift_speed_px must be > 0");
  check(c.reenter_elsewhere >= 0 && c.reenter_elsewhere <= 1, "reenter_elsewhere must be in [0, 1]");
}

double visible_fraction(const cv::Rect2d& box, cv::Size image, const cv::Rect2d& occluder) {
  if (box.area() <= 0) return 0;
  const cv::Rect2d in = box & cv::Rect2d(0, 0, image.width, image.height);
  const double hidden = occluder.area() > 0 ? (in & occluder).area() : 0.0;
  return (in.area() - hidden) / box.area();
}

// The path in image coordinates before the vibration: q = centre - pan is where the aircraft
// is seen; a border exit moves q (by the pan or by the aircraft) until the bounding circle
// of radius r plus `margin` (the vibration) is beyond the border, keeps it there, and moves back.
struct ExitsScene::Plan {
  std::vector<IntruderPose> path;
  std::vector<double> mast_x;
  std::vector<int> event;
  double mast_width = 0;
};

ExitsScene::ExitsScene(const ExitsConfig& c, Plan plan)
    : config_(c),
      path_(std::move(plan.path)),
      mast_x_(std::move(plan.mast_x)),
      event_(std::move(plan.event)),
      mast_width_(plan.mast_width),
      scene_(c.look, path_) {
  // The mast: dark value noise (a tower close to the camera).
  const cv::Mat n =
      value_noise(cv::Size(cvCeil(mast_width_) + 2, c.look.height), 12, 4, 0.6, mix_seed(c.look.seed, 21));
  n.convertTo(mast_, CV_8U, 70, 25);
  if (c.look.color) cv::cvtColor(mast_, mast_, cv::COLOR_GRAY2BGR);
  const ExitsFrame first = frame(0);
  if (first.visible_fraction < 1.0)
    throw std::logic_error("sim::ExitsScene: the aircraft is not fully in view at the first frame");
}

ExitsScene::ExitsScene(const ExitsConfig& c) : ExitsScene(c, [&] {
  validate_exits_config(c);
  cv::RNG rng(mix_seed(c.look.seed, 20));
  const double W = c.look.width, H = c.look.height;
  const double r = 0.52 * c.look.wingspan_px * (1 + c.scale_amplitude);  // the silhouette's bounding circle
  const double margin = 4 + 8 * c.look.vibration_px;
  const double phase_scale = rng.uniform(0.0, 2 * CV_PI), phase_roll = rng.uniform(0.0, 2 * CV_PI);
  const double heading = rng.uniform(0, 2) ? 0.0 : CV_PI;  // nose right or left
  const int first_kind = c.kinds.empty() ? 0 : rng.uniform(0, static_cast<int>(c.kinds.size()));

  Plan p;
  p.mast_width = 2 * (r + 1) + 0.2 * c.look.wingspan_px;
  cv::Point2d q(0.5 * W, 0.5 * H), pan(0, 0);  // where the aircraft is seen, the camera's pan
  double mast = kNaN;
  int event = -1;
  auto push = [&] {
    const double k = static_cast<double>(p.path.size());
    IntruderPose pose;
    pose.pan = pan;
    pose.center = q + pan;
    pose.scale = 1 + c.scale_amplitude * std::sin(2 * CV_PI * k / 240 + phase_scale);
    pose.angle = heading + c.look.max_roll_deg * CV_PI / 180 * std::sin(2 * CV_PI * k / 100 + phase_roll);
    p.path.push_back(pose);
    p.mast_x.push_back(mast);
    p.event.push_back(event);
  };
  auto wander = [&](cv::Point2d to, int n) {
    const cv::Point2d from = q;
    for (int i = 1; i <= n; ++i) {
      q = from + ease(i, n) * (to - from);
      push();
    }
  };
  // Moves q along `d` by `dist` in steps of at most `speed` (by the pan when `by_pan`).
  auto move = [&](cv::Point2d d, double dist, double speed, bool by_pan) {
    const int n = std::max(1, cvCeil(dist / speed));
    for (int i = 0; i < n; ++i) {
      q += d * (dist / n);
      if (by_pan) pan -= d * (dist / n);
      push();
    }
  };
  auto in_frames = [&] { return rng.uniform(c.in_frames_min, c.in_frames_max + 1); };

  for (int e = 0; e < c.exits; ++e) {
    const int kind = kind_index(c.kinds[(first_kind + e) % c.kinds.size()]);
    const int out = rng.uniform(c.out_frames_min, c.out_frames_max + 1);
    const bool elsewhere = rng.uniform(0.0, 1.0) < c.reenter_elsewhere;
    const double dir = rng.uniform(0, 2) ? 1.0 : -1.0;
    // One draw per statement: a call's arguments are evaluated in an unspecified order (x86-64
    // GCC right to left, arm64 left to right); this is x86's order, now on every architecture.
    const double to_y = rng.uniform(0.3, 0.7) * H;
    cv::Point2d to(rng.uniform(0.3, 0.7) * W, to_y);
    if (kind == 2) {
      // Occlusion, horizontal. The mast and the aircraft vibrate together, so only the
      // silhouette's circle (plus 1 px) matters: the aircraft waits where its crossing will be
      // centred in the image, the mast slides in from the border ahead and stops `gap` ahead of it.
      const double rc = r + 1, gap = 0.1 * c.look.wingspan_px, travel = 4 * rc + 4 * gap;
      to.x = dir > 0 ? 0.5 * (W - travel) : W - 0.5 * (W - travel);
      wander(to, in_frames());
      event = kind;
      const double stop = dir > 0 ? q.x + rc + gap : q.x - rc - gap - p.mast_width;
      const double start = dir > 0 ? W : -p.mast_width;
      const int n_slide = std::max(1, cvCeil(std::abs(stop - start) / c.pan_speed_px));
      for (int i = 1; i <= n_slide; ++i) {
        mast = start + (stop - start) * i / n_slide;
        push();
      }
      // In until entirely behind, across in `out` frames, out the other side.
      const double cover = 2 * rc + gap, across = p.mast_width - 2 * rc;
      move({dir, 0}, cover, c.drift_speed_px, false);
      for (int i = 0; i < out; ++i) {
        q.x += dir * across / std::max(1, out - 1) * (i > 0);
        push();
      }
      move({dir, 0}, cover, c.drift_speed_px, false);
      const double gone = dir > 0 ? -p.mast_width : W;  // slides out the way the aircraft came from
      const int n_leave = std::max(1, cvCeil(std::abs(gone - mast) / c.pan_speed_px));
      const double from = mast;
      for (int i = 1; i <= n_leave; ++i) {
        mast = from + (gone - from) * i / n_leave;
        push();
      }
      mast = kNaN;
      event = -1;
      continue;
    }
    // Border exits: the border (left, right, top, bottom) from the seed; `d` points out of it.
    const int border = rng.uniform(0, 4);
    const cv::Point2d d = border == 0 ? cv::Point2d(-1, 0) : border == 1 ? cv::Point2d(1, 0)
                        : border == 2 ? cv::Point2d(0, -1) : cv::Point2d(0, 1);
    const cv::Point2d along(std::abs(d.y), std::abs(d.x));
    const double extent = d.x != 0 ? W : H, side = d.x != 0 ? H : W;
    if (kind == 1) {  // a slow drift starts a quarter of the image from the border
      if (d.x != 0) to.x = d.x > 0 ? 0.75 * W : 0.25 * W;
      else to.y = d.y > 0 ? 0.75 * H : 0.25 * H;
    }
    wander(to, in_frames());
    event = kind;
    // Coordinate of q across the border (positive outwards) and the distance to being out.
    auto outwards = [&] { return d.x + d.y > 0 ? q.dot(d) - extent : q.dot(d); };
    const double depth_in = -outwards();
    const double speed = kind == 0 ? c.pan_speed_px : c.drift_speed_px;
    move(d, depth_in + r + margin, speed, kind == 0);
    // Out of view: the aircraft moves along the border to where it will come back.
    const double a0 = q.dot(along);
    const double a1 = elsewhere ? rng.uniform(r + margin, side - r - margin) : a0;
    for (int i = 1; i <= out; ++i) {
      const double a = a0 + ease(i, out) * (a1 - a0);
      q += (a - q.dot(along)) * along;
      push();
    }
    move(-d, r + margin + std::min(depth_in, 0.5 * extent - r - margin), speed, kind == 0);
    event = -1;
  }
  const double start_y = rng.uniform(0.3, 0.7) * H;  // one draw per statement (see above)
  wander(cv::Point2d(rng.uniform(0.3, 0.7) * W, start_y), in_frames());
  // The first frame is the start of the first wander: fully in view by construction.
  return p;
}()) {}

ExitsFrame ExitsScene::frame(int k) const {
  ExitsFrame f;
  f.mono = scene_.frame(k);
  const IntruderPose& pose = path_[k];
  const cv::Point2d jitter = f.mono.target_center - (pose.center - pose.pan);
  const int w = config_.look.width, h = config_.look.height;
  if (!std::isnan(mast_x_[k])) {
    const double x0 = mast_x_[k] + jitter.x;
    f.occluder = cv::Rect2d(x0, 0, mast_width_, h);
    // Pixels whose centres lie within the mast.
    const int c0 = std::max(0, cvCeil(x0)), c1 = std::min(w, cvCeil(x0 + mast_width_));
    if (c1 > c0) mast_(cv::Rect(c0 - cvCeil(x0), 0, c1 - c0, h)).copyTo(f.mono.image(cv::Rect(c0, 0, c1 - c0, h)));
  }
  f.visible_fraction = visible_fraction(f.mono.target_box, cv::Size(w, h), f.occluder);
  f.in_view = f.visible_fraction >= config_.min_visible;
  if (event_[k] >= 0) f.event = kKinds[event_[k]];
  return f;
}

}  // namespace aerie::sim
