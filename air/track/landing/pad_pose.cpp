#include "air/track/landing/pad_pose.hpp"

#include <opencv2/calib3d.hpp>
#include <opencv2/imgproc.hpp>

#include <algorithm>
#include <cmath>
#include <limits>
#include <stdexcept>
#include <vector>

#include "air/track/landing/pad_fit.hpp"
#include "air/track/tracker.hpp"

namespace aerie::track {

std::string to_string(PadMiss miss) {
  switch (miss) {
    case PadMiss::None: return "none";
    case PadMiss::EmptyWindow: return "empty_window";
    case PadMiss::NoQuad: return "no_quad";
    case PadMiss::TouchesBorder: return "touches_border";
    case PadMiss::NoMarking: return "no_marking";
    case PadMiss::Reprojection: return "reprojection";
  }
  return "unknown";
}

namespace {

constexpr int kTop = 48;  // side of the top view the marking is compared in (px)

using Quad = std::array<cv::Point2f, 4>;

constexpr double kHx = 0.19, kHy = 0.24;  // half extent of the H along pad x and y (fraction of the size)
constexpr double kLegIn = 0.11;           // inner edge of the H's legs along pad x (fraction of the size)

// The marking at pad coordinates normalised by its size (paint_helipad in common/sim/world.cpp):
// 1 white, 0 dark; the H's bar along x.
double marking(double x, double y, double border) {
  const double ax = std::abs(x), ay = std::abs(y), r = std::hypot(x, y);
  const bool ring = r > 0.40 && r < 0.46;
  const bool leg = ay < kHy && ax > kLegIn && ax < kHx;
  const bool bar = ax < kLegIn && ay < 0.035;
  const bool edge = ax > 0.5 - border || ay > 0.5 - border;
  return ring || leg || bar || edge ? 1.0 : 0.0;
}

// Top view of the dark square (kTop x kTop, column = +x, row = -y), 4 x 4 samples per pixel.
cv::Mat marking_template(double border) {
  cv::Mat t(kTop, kTop, CV_32F);
  const double side = 1 - 2 * border;
  for (int r = 0; r < kTop; ++r)
    for (int c = 0; c < kTop; ++c) {
      double sum = 0;
      for (int j = 0; j < 4; ++j)
        for (int i = 0; i < 4; ++i)
          sum += marking(((c + (i + 0.5) / 4) / kTop - 0.5) * side, -((r + (j + 0.5) / 4) / kTop - 0.5) * side, border);
      t.at<float>(r, c) = static_cast<float>(sum / 16);
    }
  return t;
}

// The square's template for this border, made once per thread and border (observe_pad runs on
// every tracked frame, the border does not change; trackers run on several threads).
const cv::Mat& square_template(double border) {
  thread_local double made_for = NAN;
  thread_local cv::Mat templ;
  if (!(border == made_for)) templ = marking_template(border), made_for = border;
  return templ;
}

double correlation(const cv::Mat& a, const cv::Mat& b) {
  cv::Mat score;
  cv::matchTemplate(a, b, score, cv::TM_CCOEFF_NORMED);
  return score.at<float>(0, 0);
}

// The quad (corners clockwise in the image) warped to a kTop x kTop top view, q[0] at its
// top left and q[1] at its top right.
cv::Mat top_view(const cv::Mat& gray, const Quad& q, int side = kTop) {
  const float e = side - 0.5f;
  const std::array<cv::Point2f, 4> top{{{-0.5f, -0.5f}, {e, -0.5f}, {e, e}, {-0.5f, e}}};
  const cv::Mat H = cv::getPerspectiveTransform(top.data(), q.data());
  cv::Mat view;
  cv::warpPerspective(gray, view, H, {side, side}, cv::INTER_LINEAR | cv::WARP_INVERSE_MAP, cv::BORDER_REPLICATE);
  view.convertTo(view, CV_32F);
  return view;
}

// Correlation of the square's top view with the H: its bar along corners[0] -> corners[1]
// (> 0 returned as is) or along corners[1] -> corners[2].
std::pair<double, bool> marking_score(const cv::Mat& gray, const Quad& q, const cv::Mat& templ) {
  const cv::Mat view = top_view(gray, q);
  const double along_x = correlation(view, templ), along_y = correlation(view, templ.t());
  return {std::max(along_x, along_y), along_y > along_x};
}

struct Candidate {
  Quad quad;
  double score = 0;
  cv::Point2f centre, along_x, along_y;  // the H's centre and unit vectors along its bar and legs
  float width = 0, height = 0;           // its box along them (px)
};

// The pad's H: an isolated bright blob (the pad's most distinctive part: at 50-100 px the thin
// white border no longer separates the dark square from dark patches of the floor, but the H
// stays an isolated bright blob inside the dark square). Bright blobs of the window at Otsu's
// level and halfway to its brightest 2 % whose shape is H-like (filling about half of their
// convex hull, aspect about 0.48 / 0.38); quad: the H's bounding rectangle from the blob's
// minimal box, corners[0] -> corners[1] along the bar (pad x); best first: large and central.
std::vector<Candidate> find_hs(const cv::Mat& gray, const cv::Rect& win, const PadOptions& opt) {
  cv::Mat roi, bright;
  cv::GaussianBlur(gray(win), roi, {3, 3}, 0);
  const double otsu = cv::threshold(roi, bright, 0, 255, cv::THRESH_BINARY | cv::THRESH_OTSU);
  int hist[256] = {}, hi = 255;
  for (int r = 0; r < roi.rows; ++r)
    for (int c = 0; c < roi.cols; ++c) ++hist[roi.at<uint8_t>(r, c)];
  for (int n = 0; hi > 0 && (n += hist[hi]) < 0.02 * roi.total();) --hi;
  const cv::Point2f centre(win.x + win.width / 2.0f, win.y + win.height / 2.0f);
  const double min_h = opt.min_side_px * 2 * kHx;  // the H of the smallest pad
  std::vector<Candidate> out;
  for (const double level : {otsu, (otsu + hi) / 2}) {
    cv::threshold(roi, bright, level, 255, cv::THRESH_BINARY);
    std::vector<std::vector<cv::Point>> contours;
    cv::findContours(bright, contours, cv::RETR_LIST, cv::CHAIN_APPROX_SIMPLE);
    for (const auto& c : contours) {
      const double area = cv::contourArea(c);
      if (area < min_h * min_h * 0.5) continue;
      std::vector<cv::Point> hull;
      cv::convexHull(c, hull);
      const cv::RotatedRect box = cv::minAreaRect(c);
      const double solidity = area / cv::contourArea(hull);
      const float shorter = std::min(box.size.width, box.size.height), longer = std::max(box.size.width, box.size.height);
      if (solidity < 0.3 || solidity > 0.75 || longer > 1.7f * shorter || shorter < min_h) continue;
      // Unit vectors along the H's bar (the short side of its box, pad x) and legs (pad y).
      const float a = box.angle * static_cast<float>(M_PI / 180);
      cv::Point2f ux(std::cos(a), std::sin(a)), uy(-std::sin(a), std::cos(a));
      if (box.size.width > box.size.height) std::swap(ux, uy);
      Candidate k;
      const cv::Point2f m = box.center + cv::Point2f(win.tl());
      k.centre = m, k.along_x = ux, k.along_y = uy, k.width = shorter, k.height = longer;
      ux *= shorter / 2;
      uy *= longer / 2;
      k.quad = {m - ux - uy, m + ux - uy, m + ux + uy, m - ux + uy};
      k.score = std::sqrt(area) * (1 - cv::norm(m - centre) / std::hypot(win.width, win.height));
      const bool seen = std::any_of(out.begin(), out.end(), [&](const Candidate& o) {  // at the other level
        return cv::norm(o.centre - m) < 0.2 * shorter;
      });
      if (!seen) out.push_back(k);
    }
  }
  std::sort(out.begin(), out.end(), [](const Candidate& x, const Candidate& y) { return x.score > y.score; });
  return out;
}

// Candidate dark squares: each H's rectangle scaled to the square around it.
std::vector<Candidate> find_squares(const cv::Mat& gray, const cv::Rect& win, const PadGeometry& pad, const PadOptions& opt) {
  std::vector<Candidate> out = find_hs(gray, win, opt);
  const float half = static_cast<float>(0.5 - pad.border);
  for (Candidate& k : out) {
    const cv::Point2f ux = k.along_x * (k.width / 2 * half / static_cast<float>(kHx));
    const cv::Point2f uy = k.along_y * (k.height / 2 * half / static_cast<float>(kHy));
    const cv::Point2f m = k.centre;
    k.quad = {m - ux - uy, m + ux - uy, m + ux + uy, m - ux + uy};
  }
  return out;
}

// Bilinear grey level at (x, y) (inside the image).
double sample(const cv::Mat& g, double x, double y) {
  const int x0 = std::clamp(static_cast<int>(std::floor(x)), 0, g.cols - 2), y0 = std::clamp(static_cast<int>(std::floor(y)), 0, g.rows - 2);
  const double fx = x - x0, fy = y - y0;
  const uint8_t* r0 = g.ptr<uint8_t>(y0);
  const uint8_t* r1 = g.ptr<uint8_t>(y0 + 1);
  return (1 - fy) * ((1 - fx) * r0[x0] + fx * r0[x0 + 1]) + fy * ((1 - fx) * r1[x0] + fx * r1[x0 + 1]);
}

// Offset along n (px) of the dark square's edge from the line through `base` along d (a side
// of `len` px): the side's mean profile across the line is fitted with the model "dark pad,
// white border of width w px, floor", blurred by a Gaussian of unknown sigma. The strongest
// gradient alone lies inside the edge once the border is no wider than the blur (far away).
// The model is linear in the three grey levels: least squares for them on a grid of offsets and sigmas.
double edge_offset(const cv::Mat& gray, cv::Point2d base, cv::Point2d d, cv::Point2d n, double len, double w) {
  // From 2 px inside (clear of the ring where it is sampled: 10-30 % and 70-90 % of the side)
  // to 2.5 px beyond the border.
  constexpr double kStep = 0.25, kIn = 2.0;
  const int m = static_cast<int>((kIn + w + 2.5) / kStep) + 1, samples = std::min(100, static_cast<int>(0.4 * len));
  const cv::Rect2d image(0, 0, gray.cols - 1, gray.rows - 1);
  std::vector<double> profile(m, 0.0);
  int used = 0;
  for (int k = 0; k < samples; ++k) {
    const double t = (k + 0.5) / samples;  // over 0.1..0.3, 0.7..0.9
    const cv::Point2d p = base + d * len * (t < 0.5 ? 0.1 + 0.4 * t : 0.5 + 0.4 * t);
    if (!image.contains(p - n * kIn) || !image.contains(p + n * (m * kStep - kIn))) continue;
    for (int j = 0; j < m; ++j) profile[j] += sample(gray, p.x + n.x * (kStep * j - kIn), p.y + n.y * (kStep * j - kIn));
    ++used;
  }
  if (used < 5) return 0;
  const auto phi = [](double x) { return 0.5 * std::erfc(-x / std::sqrt(2.0)); };
  double best_e = 0, best_sigma = 0.8, best_cost = std::numeric_limits<double>::infinity();
  const auto fit = [&](double e, double sigma) {
    cv::Matx33d A = cv::Matx33d::zeros();
    cv::Vec3d b(0, 0, 0), x;
    double yy = 0;
    for (int j = 0; j < m; ++j) {
      const double s = kStep * j - kIn, y = profile[j] / used;
      const double floor = phi((s - e - w) / sigma);
      const cv::Vec3d g(1, phi((s - e) / sigma) - floor, floor);
      A += g * g.t();
      b += g * y;
      yy += y * y;
    }
    const double cost = cv::solve(A, b, x, cv::DECOMP_CHOLESKY) ? yy - x.dot(b) : INFINITY;  // residual at the best levels
    if (cost < best_cost) best_cost = cost, best_e = e, best_sigma = sigma;
  };
  for (double sigma = 0.3; sigma < 1.8; sigma += 0.2)  // coarse grid, then finer around its best
    for (double e = -1.5; e <= 1.5; e += 0.1) fit(e, sigma);
  const double e0 = best_e, sigma0 = best_sigma;
  for (double sigma = sigma0 - 0.1; sigma <= sigma0 + 0.1; sigma += 0.05)
    for (double e = e0 - 0.1; e <= e0 + 0.1; e += 0.02)
      if (sigma > 0.2) fit(e, sigma);
  return best_e;
}

// Sub-pixel sides of the dark square: along the middle 70 % of each side of the quad
// (clockwise), the strongest dark-to-bright step outwards within reach_fraction x the side (parabola through
// the derivative's peak); a line fitted to these points robustly (Huber) per side; the corners
// are the intersections of adjacent lines. Edges are better located than corners: clutter
// next to a corner or the thin white border do not pull them. False when a side has too
// few edge points. bright_inside: the H's rectangle instead (bright-to-dark steps), its long
// sides (the legs' outer edges) sampled along 94 %, its short sides (q[0] -> q[1] and
// q[2] -> q[3], along the bar: the two legs' ends) only along the legs' ends. The gap between
// the legs has no step of the H's: sampled, its points lock onto whatever lies beyond (a floor
// mark next to the gap gave a second line and a skewed side; docs/arm.md, "PadPose on arm64").
bool refine_sides(const cv::Mat& gray, Quad& q, double reach_fraction, double border = -1, bool bright_inside = false) {
  const double polarity = bright_inside ? -1 : 1;
  constexpr double kLegEnd = (kHx - kLegIn) / (2 * kHx);  // a leg's end, fraction of the short side
  std::array<cv::Vec4f, 4> lines;  // (dx, dy, x0, y0)
  for (int i = 0; i < 4; ++i) {
    const cv::Point2d a(q[i]), b(q[(i + 1) % 4]);
    const double len = cv::norm(b - a);
    const cv::Point2d d = (b - a) / len, n(d.y, -d.x);  // n: outwards for a clockwise quad
    const double reach = std::max(2.0, reach_fraction * len);
    const int steps = static_cast<int>(2 * reach / 0.5);
    std::vector<cv::Point2f> edge;
    int first_third = 0, last_third = 0;  // edge points near each end of the side
    std::vector<double> profile(steps + 1);
    const bool leg_ends = bright_inside && i % 2 == 0;
    // Sampled stretch: [start, start + span], or for the legs' ends its two halves moved apart
    // to [0.03, kLegEnd - 0.03] and [1 - kLegEnd + 0.03, 0.97].
    const double span = leg_ends ? 2 * (kLegEnd - 0.06) : bright_inside ? 0.94 : 0.7;
    const double start = bright_inside ? 0.03 : 0.15, gap = leg_ends ? 1 - 2 * kLegEnd + 0.06 : 0;
    const int samples = std::min(100, static_cast<int>(span * len));
    for (int k = 0; k < samples; ++k) {
      const double t = span * (k + 0.5) / samples;
      const cv::Point2d p = a + d * len * (start + t + (t > span / 2 ? gap : 0));
      bool inside = true;
      for (int j = 0; j <= steps && inside; ++j) {
        const cv::Point2d s = p + n * (-reach + 0.5 * j);
        inside = s.x >= 0 && s.y >= 0 && s.x <= gray.cols - 1 && s.y <= gray.rows - 1;
        if (inside) profile[j] = polarity * sample(gray, s.x, s.y);
      }
      if (!inside) continue;
      int best = -1;
      double best_step = 4.0;  // grey levels per half pixel at least
      for (int j = 1; j < steps; ++j)
        if (profile[j + 1] - profile[j - 1] > best_step) best_step = profile[j + 1] - profile[j - 1], best = j;
      if (best < 2 || best > steps - 2) continue;
      const double l = profile[best] - profile[best - 2], c = best_step, r = profile[best + 2] - profile[best];
      const double off = (l - r) / (2 * (l - 2 * c + r));  // parabola vertex, in half pixels
      edge.emplace_back(p + n * (-reach + 0.5 * (best + (std::isfinite(off) ? std::clamp(off, -1.0, 1.0) : 0))));
      first_third += 3 * k < samples;
      last_third += 3 * k >= 2 * samples;
    }
    if (edge.size() < 5) return false;
    // The H's short sides are two leg ends: a line through one of them alone is not the side.
    if (bright_inside && (first_third < 3 || last_third < 3)) return false;
    cv::fitLine(edge, lines[i], cv::DIST_HUBER, 0, 0.01, 0.01);
    if (border >= 0) {  // the edge's offset from the model of the profile
      cv::Point2d ld(lines[i][0], lines[i][1]);
      if (ld.dot(d) < 0) ld = -ld;
      const cv::Point2d ln(ld.y, -ld.x), l0(lines[i][2], lines[i][3]);
      const double e = edge_offset(gray, l0 + ld * (a - l0).dot(ld), ld, ln, len, border * len / (1 - 2 * border));
      lines[i][2] += static_cast<float>(e * ln.x);
      lines[i][3] += static_cast<float>(e * ln.y);
    }
  }
  for (int i = 0; i < 4; ++i) {  // corner i: sides i - 1 and i
    const cv::Vec4f& u = lines[(i + 3) % 4];
    const cv::Vec4f& v = lines[i];
    const double det = u[0] * -v[1] - u[1] * -v[0];
    if (std::abs(det) < 1e-3) return false;
    const double t = ((v[2] - u[2]) * -v[1] - (v[3] - u[3]) * -v[0]) / det;
    q[i] = cv::Point2f(static_cast<float>(u[2] + t * u[0]), static_cast<float>(u[3] + t * u[1]));
  }
  return true;
}

// Clockwise in the image (x right, y down), which is the order of cv::SOLVEPNP_IPPE_SQUARE's
// object points (-s/2, s/2), (s/2, s/2), (s/2, -s/2), (-s/2, -s/2) seen from their +z side.
void make_clockwise(Quad& q) {
  double area2 = 0;
  for (int i = 0; i < 4; ++i) area2 += q[i].x * q[(i + 1) % 4].y - q[(i + 1) % 4].x * q[i].y;
  if (area2 < 0) std::reverse(q.begin(), q.end());
}

void check(const char* who, const cv::Mat& gray, const camera::CameraModel& cam, const PadGeometry* pad) {
  auto bad = [&](const std::string& what) { throw std::invalid_argument(who + (": " + what)); };
  if (gray.empty()) bad("empty frame");
  if (!(std::isfinite(cam.fx) && std::isfinite(cam.fy) && cam.fx > 0 && cam.fy > 0))
    bad("camera focal lengths must be finite and > 0");
  if (!std::isfinite(cam.cx) || !std::isfinite(cam.cy)) bad("camera principal point is not finite");
  if ((cam.width > 0 || cam.height > 0) && cam.size() != gray.size())
    bad("camera is " + std::to_string(cam.width) + "x" + std::to_string(cam.height) + ", the frame " +
        std::to_string(gray.cols) + "x" + std::to_string(gray.rows));
  if (!pad) return;
  if (!(pad->size > 0) || !std::isfinite(pad->size)) bad("pad size must be > 0 metres");
  if (!(pad->border >= 0 && pad->border < 0.25)) bad("pad border must be in [0, 0.25) of the size");
}

// Top view of the H's rectangle (kTop x kTop, column = +x over the bar, row = -y).
cv::Mat h_template() {
  cv::Mat t(kTop, kTop, CV_32F);
  for (int r = 0; r < kTop; ++r)
    for (int c = 0; c < kTop; ++c) {
      double sum = 0;
      for (int j = 0; j < 4; ++j)
        for (int i = 0; i < 4; ++i)
          sum += marking(((c + (i + 0.5) / 4) / kTop - 0.5) * 2 * kHx, -((r + (j + 0.5) / 4) / kTop - 0.5) * 2 * kHy, 0);
      t.at<float>(r, c) = static_cast<float>(sum / 16);
    }
  return t;
}

// The quad's four corners in the image, clear of its border by the margin.
bool in_image(const Quad& q, const cv::Mat& gray, const PadOptions& opt) {
  const cv::Rect2f inside(opt.border_margin_px, opt.border_margin_px, gray.cols - 1 - 2 * opt.border_margin_px,
                          gray.rows - 1 - 2 * opt.border_margin_px);
  return std::all_of(q.begin(), q.end(), [&](const cv::Point2f& p) { return inside.contains(p); });
}

// Pose of the planar rectangle with corners (-hx, hy), (hx, hy), (hx, -hy), (-hx, -hy) seen at
// q (clockwise in the image, q[0] -> q[1] along +x): IPPE (Collins & Bartoli 2014) on the
// undistorted corners (ideal pinhole pixels of the same K), polished by Levenberg-Marquardt.
// The observation's corners and box are left to the caller.
std::optional<PadObservation> rectangle_pose(const Quad& q, double hx, double hy, const camera::CameraModel& camera,
                                             const PadOptions& opt) {
  const std::vector<cv::Point3d> object{{-hx, hy, 0}, {hx, hy, 0}, {hx, -hy, 0}, {-hx, -hy, 0}};
  std::vector<cv::Point2d> ideal(4);
  for (int i = 0; i < 4; ++i) {
    const Eigen::Vector3d ray = camera.unproject({q[i].x, q[i].y});
    ideal[i] = {camera.fx * ray.x() + camera.cx, camera.fy * ray.y() + camera.cy};
  }
  cv::Vec3d rvec, tvec;
  if (!cv::solvePnP(object, ideal, camera.K(), cv::noArray(), rvec, tvec, false,
                    hx == hy ? cv::SOLVEPNP_IPPE_SQUARE : cv::SOLVEPNP_IPPE))
    return std::nullopt;
  cv::solvePnPRefineLM(object, ideal, camera.K(), cv::noArray(), rvec, tvec);  // IPPE is closed form: polish it
  std::vector<cv::Point2d> reproj;
  cv::projectPoints(object, rvec, tvec, camera.K(), cv::noArray(), reproj);
  double sq = 0;
  for (int i = 0; i < 4; ++i) sq += std::pow(cv::norm(reproj[i] - ideal[i]), 2);
  const double rms = std::sqrt(sq / 4);
  if (rms > opt.max_reprojection_px || tvec[2] <= 0) return std::nullopt;
  PadObservation o;
  cv::Matx33d R;
  cv::Rodrigues(rvec, R);
  for (int r = 0; r < 3; ++r) {
    o.position[r] = tvec[r];
    for (int c = 0; c < 3; ++c) o.rotation(r, c) = R(r, c);
  }
  o.yaw = std::remainder(std::atan2(R(1, 0), R(0, 0)), M_PI);  // modulo pi: the H's symmetry
  if (o.yaw <= -M_PI / 2) o.yaw += M_PI;
  o.reprojection_rms = rms;
  return o;
}

// The axis-aligned box of four points, in their own precision (the fitted quad's is float).
template <class Point>
cv::Rect2d bounding_box(const std::array<Point, 4>& c) {
  const auto [xmin, xmax] = std::minmax({c[0].x, c[1].x, c[2].x, c[3].x});
  const auto [ymin, ymax] = std::minmax({c[0].y, c[1].y, c[2].y, c[3].y});
  return cv::Rect2d(xmin, ymin, xmax - xmin, ymax - ymin);
}

cv::Rect window_in(const cv::Rect2d& search, const cv::Mat& gray) {
  return cv::Rect(cv::Point(std::floor(search.x), std::floor(search.y)),
                  cv::Point(std::ceil(search.x + search.width), std::ceil(search.y + search.height))) &
         cv::Rect(0, 0, gray.cols, gray.rows);
}

// observe_pad (the dark square) or, h_only, observe_marking (the H's rectangle).
std::optional<PadObservation> observe(bool h_only, const cv::Mat& frame, const cv::Rect2d& search,
                                      const camera::CameraModel& camera, const PadGeometry& pad, const PadOptions& opt,
                                      PadMiss* miss) {
  check(h_only ? "observe_marking" : "observe_pad", frame, camera, &pad);
  const cv::Mat gray = to_gray(frame);
  const cv::Rect win = window_in(search, gray);
  if (!std::isfinite(search.area()) || win.width < 2 * opt.min_side_px || win.height < 2 * opt.min_side_px) {
    if (miss) *miss = PadMiss::EmptyWindow;
    return std::nullopt;
  }
  const std::vector<Candidate> candidates = h_only ? find_hs(gray, win, opt) : find_squares(gray, win, pad, opt);
  static const cv::Mat h_templ = h_template();
  const cv::Mat& templ = h_only ? h_templ : square_template(pad.border);
  const double h = pad.size * (1 - 2 * pad.border) / 2;  // half side of the dark square
  PadMiss why = PadMiss::NoQuad;
  for (size_t k = 0; k < std::min<size_t>(candidates.size(), 4); ++k) {
    Quad q = candidates[k].quad;
    make_clockwise(q);
    // From the seed to the edges in two passes (the second one closer), whole quads only.
    const bool fitted = h_only ? in_image(q, gray, opt) && refine_sides(gray, q, 0.08, -1, true) && in_image(q, gray, opt) &&
                                     refine_sides(gray, q, 0.03, -1, true)
                               : in_image(q, gray, opt) && refine_sides(gray, q, 0.06) && in_image(q, gray, opt) &&
                                     refine_sides(gray, q, 0.025, pad.border);
    if (!fitted || !in_image(q, gray, opt)) {
      why = std::max(why, in_image(q, gray, opt) ? PadMiss::NoQuad : PadMiss::TouchesBorder);
      continue;
    }
    // The square's 90 deg ambiguity is resolved by the H; the H's rectangle is not square:
    // q[0] -> q[1] stays along its bar.
    auto [score, rotated] = h_only ? std::pair{correlation(top_view(gray, q), templ), false} : marking_score(gray, q, templ);
    if (score < opt.min_marking_score) {
      why = std::max(why, PadMiss::NoMarking);
      continue;
    }
    if (rotated) std::rotate(q.begin(), q.begin() + 1, q.end());  // the bar along q[0] -> q[1]
    std::optional<PadObservation> o =
        h_only ? rectangle_pose(q, kHx * pad.size, kHy * pad.size, camera, opt) : rectangle_pose(q, h, h, camera, opt);
    if (!o) {
      why = std::max(why, PadMiss::Reprojection);
      continue;
    }
    if (h_only) {  // the dark square's corners where the pose puts them (partly outside the image)
      for (int i = 0; i < 4; ++i) {
        const Eigen::Vector3d c = o->rotation * Eigen::Vector3d(i == 0 || i == 3 ? -h : h, i < 2 ? h : -h, 0) + o->position;
        const Eigen::Vector2d uv = c.z() > 0 ? camera.project(c) : Eigen::Vector2d::Constant(NAN);
        o->corners[i] = {uv.x(), uv.y()};
      }
      o->box = bounding_box(o->corners);
    } else {
      for (int i = 0; i < 4; ++i) o->corners[i] = q[i];
      o->box = bounding_box(q);
    }
    o->marking_score = score;
    o->marking_only = h_only;
    if (miss) *miss = PadMiss::None;
    return o;
  }
  if (miss) *miss = why;
  return std::nullopt;
}

}  // namespace

namespace detail {

bool refine_dark_quad(const cv::Mat& gray, Quad& q, double reach_fraction) { return refine_sides(gray, q, reach_fraction); }
void make_clockwise(Quad& q) { track::make_clockwise(q); }
bool in_image(const Quad& q, const cv::Mat& gray, const PadOptions& options) { return track::in_image(q, gray, options); }
std::optional<PadObservation> rectangle_pose(const Quad& q, double hx, double hy, const camera::CameraModel& camera,
                                             const PadOptions& options) {
  return track::rectangle_pose(q, hx, hy, camera, options);
}
cv::Mat top_view(const cv::Mat& gray, const Quad& q, int side) { return track::top_view(gray, q, side); }
double correlation(const cv::Mat& a, const cv::Mat& b) { return track::correlation(a, b); }
cv::Rect window_in(const cv::Rect2d& search, const cv::Mat& gray) { return track::window_in(search, gray); }
void check_frame(const char* who, const cv::Mat& gray, const camera::CameraModel& camera) { check(who, gray, camera, nullptr); }

}  // namespace detail

std::optional<PadObservation> observe_pad(const cv::Mat& frame, const cv::Rect2d& search, const camera::CameraModel& camera,
                                          const PadGeometry& pad, const PadOptions& opt, PadMiss* miss) {
  return observe(false, frame, search, camera, pad, opt, miss);
}

std::optional<PadObservation> observe_marking(const cv::Mat& frame, const cv::Rect2d& search, const camera::CameraModel& camera,
                                              const PadGeometry& pad, const PadOptions& opt, PadMiss* miss) {
  return observe(true, frame, search, camera, pad, opt, miss);
}

}  // namespace aerie::track
