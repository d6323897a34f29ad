#include "air/track/landing/pad_design.hpp"

#include <opencv2/imgcodecs.hpp>
#include <opencv2/imgproc.hpp>

#include <algorithm>
#include <cmath>
#include <stdexcept>
#include <vector>

#include "air/track/landing/pad_fit.hpp"
#include "air/track/tracker.hpp"

namespace aerie::track {

namespace {

constexpr int kSide = 64;  // side of the top views the drawing is compared in (px)
// Least correlation of a quad's top view with the drawing: a dark floor tile holding the pad
// gives a quad whose view correlates 0.4-0.6 with it (a quad on the pad itself above 0.9).
constexpr double kMinDesignScore = 0.75;

using detail::Quad;

[[noreturn]] void bad(const std::string& who, const std::string& what) { throw std::invalid_argument(who + ": " + what); }

// 8-bit gray; transparent pixels over white (an SVG rasterised without a background).
cv::Mat drawing_gray(const cv::Mat& image) {
  cv::Mat gray;
  if (image.channels() == 4) {
    std::vector<cv::Mat> ch;
    cv::split(image, ch);
    cv::Mat bgr, a;
    cv::merge(std::vector<cv::Mat>{ch[0], ch[1], ch[2]}, bgr);
    cv::cvtColor(bgr, gray, cv::COLOR_BGR2GRAY);
    ch[3].convertTo(a, CV_32F, 1 / 255.0);
    gray.convertTo(gray, CV_32F);
    gray = gray.mul(a) + 255 * (1 - a);
    gray.convertTo(gray, CV_8U);
    return gray;
  }
  return to_gray(image);
}

// Pixels outside the disc inscribed in a side x side view set to 0 (the ring's inside only).
cv::Mat disc(const cv::Mat& view, double radius_fraction) {
  cv::Mat m = cv::Mat::zeros(view.size(), CV_32F), out;
  cv::circle(m, {view.cols / 2, view.rows / 2}, static_cast<int>(radius_fraction * view.cols / 2), 1.0, cv::FILLED);
  cv::multiply(view, m, out);
  return out;
}

// The inside of an ellipse (px) warped to a kSide x kSide view, the ellipse on its inscribed circle.
cv::Mat ellipse_view(const cv::Mat& gray, const cv::RotatedRect& e) {
  const double a = e.angle * CV_PI / 180;
  const cv::Point2f u(static_cast<float>(std::cos(a)), static_cast<float>(std::sin(a))), v(-u.y, u.x);
  const float h = kSide / 2.0f;
  const cv::Point2f from[3] = {{h, h}, {2 * h, h}, {h, 2 * h}};
  const cv::Point2f to[3] = {e.center, e.center + u * (e.size.width / 2), e.center + v * (e.size.height / 2)};
  cv::Mat view;
  cv::warpAffine(gray, view, cv::getAffineTransform(from, to), {kSide, kSide}, cv::INTER_AREA | cv::WARP_INVERSE_MAP,
                 cv::BORDER_REPLICATE);
  view.convertTo(view, CV_32F);
  return view;
}

cv::Mat rotated(const cv::Mat& t, double deg) {
  cv::Mat out;
  cv::warpAffine(t, out, cv::getRotationMatrix2D({(t.cols - 1) / 2.0f, (t.rows - 1) / 2.0f}, deg, 1.0), t.size(),
                 cv::INTER_LINEAR, cv::BORDER_REPLICATE);
  return out;
}

// 4 when the drawing is the same turned by 90 deg, 2 by 180 deg, else 1.
int symmetry_of(const cv::Mat& t) {
  cv::Mat r90, r180;
  cv::rotate(t, r90, cv::ROTATE_90_CLOCKWISE);
  cv::rotate(t, r180, cv::ROTATE_180);
  if (detail::correlation(t, r90) > 0.9) return 4;
  return detail::correlation(t, r180) > 0.9 ? 2 : 1;
}

struct Ring {
  cv::RotatedRect outer, inner;
  double ratio = 0;
};

double major(const cv::RotatedRect& e) { return std::max(e.size.width, e.size.height); }
double minor(const cv::RotatedRect& e) { return std::min(e.size.width, e.size.height); }

// A contour that an ellipse fits: its area within 12 % of the ellipse's.
std::optional<cv::RotatedRect> elliptic(const std::vector<cv::Point>& c) {
  if (c.size() < 12) return std::nullopt;
  const cv::RotatedRect e = cv::fitEllipse(c);
  const double fill = cv::contourArea(c) / (CV_PI / 4 * e.size.width * e.size.height);
  if (!(fill > 0.88 && fill < 1.12) || minor(e) < 0.5 * major(e)) return std::nullopt;
  return e;
}

// Dark rings of a binary image (255 = dark): outer contours with a concentric elliptic hole.
std::vector<Ring> rings(const cv::Mat& dark, double min_diameter) {
  std::vector<std::vector<cv::Point>> contours;
  std::vector<cv::Vec4i> tree;
  cv::findContours(dark, contours, tree, cv::RETR_CCOMP, cv::CHAIN_APPROX_NONE);
  std::vector<Ring> out;
  for (size_t i = 0; i < contours.size(); ++i) {
    if (tree[i][3] >= 0 || cv::contourArea(contours[i]) < CV_PI / 4 * min_diameter * min_diameter * 0.8) continue;
    const auto outer = elliptic(contours[i]);
    if (!outer) continue;
    int hole = -1;  // the largest hole
    for (int h = tree[i][2]; h >= 0; h = tree[h][0])
      if (hole < 0 || cv::contourArea(contours[h]) > cv::contourArea(contours[hole])) hole = h;
    if (hole < 0) continue;
    const auto inner = elliptic(contours[hole]);
    if (!inner || cv::norm(inner->center - outer->center) > 0.06 * major(*outer)) continue;
    out.push_back({*outer, *inner, major(*inner) / major(*outer)});
  }
  return out;
}

// Otsu's level of the histogram's bins [lo, hi): the grey level that best splits them in two.
int otsu_level(const int* hist, int lo, int hi) {
  double n = 0, sum = 0;
  for (int g = lo; g < hi; ++g) n += hist[g], sum += static_cast<double>(g) * hist[g];
  double n0 = 0, sum0 = 0, best = -1;
  int level = lo;
  for (int g = lo; g < hi - 1; ++g) {
    n0 += hist[g], sum0 += static_cast<double>(g) * hist[g];
    if (n0 == 0 || n0 == n) continue;
    const double m0 = sum0 / n0, m1 = (sum - sum0) / (n - n0), between = n0 * (n - n0) * (m0 - m1) * (m0 - m1);
    if (between > best) best = between, level = g;
  }
  return level;
}

}  // namespace

PadDesign make_pad_design(const cv::Mat& image, double size_m, const std::string& name) {
  if (image.empty()) bad(name, "empty image");
  if (!(size_m > 0) || !std::isfinite(size_m)) bad(name, "pad size_m must be > 0 metres (got " + std::to_string(size_m) + ")");
  PadDesign d;
  d.name = name;
  d.image = drawing_gray(image);
  d.size_m = size_m;
  cv::Mat dark = d.image < 128;
  // Square: the drawing's edge is dark all round (the pad's square is the drawing).
  const int e = std::max(1, std::min(d.image.cols, d.image.rows) / 50);
  cv::Mat frame = dark.clone();
  frame(cv::Rect(e, e, d.image.cols - 2 * e, d.image.rows - 2 * e)).setTo(0);
  const double frame_px = 2.0 * e * (d.image.cols + d.image.rows - 2 * e);
  if (cv::countNonZero(frame) > 0.9 * frame_px) {
    if (std::abs(d.image.cols - d.image.rows) > 0.01 * d.image.cols)
      bad(name, "the drawing of a square pad must be square (got " + std::to_string(d.image.cols) + "x" +
                    std::to_string(d.image.rows) + ")");
    d.outline = PadDesign::Outline::Square;
    d.outline_box = cv::Rect(0, 0, d.image.cols, d.image.rows);
    cv::resize(d.image, d.templ, {kSide, kSide}, 0, 0, cv::INTER_AREA);
    d.templ.convertTo(d.templ, CV_32F);
    d.symmetry = symmetry_of(d.templ);
    return d;
  }
  // Round: the largest dark ring of the drawing.
  const std::vector<Ring> found = rings(dark, 8);
  if (found.empty())
    bad(name, "no outline: the drawing must be a dark square (its edge dark all round) or hold a dark ring on a light ground");
  const Ring& r = *std::max_element(found.begin(), found.end(),
                                    [](const Ring& a, const Ring& b) { return major(a.outer) < major(b.outer); });
  d.outline = PadDesign::Outline::Round;
  d.outline_box = r.outer.boundingRect();
  d.ring_inner_ratio = r.ratio;
  d.ring_diameter_m = major(r.outer) * size_m / d.image.cols;
  d.templ = disc(ellipse_view(d.image, r.inner), 0.92);
  d.symmetry = symmetry_of(d.templ);
  return d;
}

PadDesign load_pad_design(const std::string& path, double size_m) {
  const std::string who = "pad image '" + path + "'";
  if (path.size() >= 4 && path.compare(path.size() - 4, 4, ".svg") == 0)
    bad(who, "SVG is not read at run time: rasterise it (rsvg-convert -b white -w 1024 " + path + " -o pad.png)");
  const cv::Mat img = cv::imread(path, cv::IMREAD_UNCHANGED);
  if (img.empty()) bad(who, "cannot be read (missing, or not an image)");
  cv::Mat img8 = img;
  if (img.depth() != CV_8U) img.convertTo(img8, CV_8U, img.depth() == CV_16U ? 1 / 257.0 : 1.0);
  return make_pad_design(img8, size_m, who);
}

std::optional<PadObservation> observe_design(const cv::Mat& frame, const cv::Rect2d& search, const camera::CameraModel& camera,
                                             const PadDesign& design, const PadOptions& opt, PadMiss* miss) {
  detail::check_frame("observe_design", frame, camera);
  if (design.outline != PadDesign::Outline::Square || design.templ.empty())
    bad("observe_design", design.name + " is not a square design (observe_round_pad finds round ones)");
  auto missed = [&](PadMiss why) -> std::optional<PadObservation> {
    if (miss) *miss = why;
    return std::nullopt;
  };
  const cv::Mat gray = to_gray(frame);
  const cv::Rect win = detail::window_in(search, gray);
  if (!std::isfinite(search.area()) || win.width < 2 * opt.min_side_px || win.height < 2 * opt.min_side_px)
    return missed(PadMiss::EmptyWindow);
  // Candidates: the dark regions of the window at Otsu's level, as quads (the convex hull's
  // polygon when it has four corners, else its minimal box); large and central first.
  // Two levels: Otsu's, and Otsu's among the pixels darker than that (the window holds bright
  // paint, mid-grey ground and the dark pad: at the first level the ground's dark patches and
  // lines join the pad); each opened by a 5 x 5 disc (thin dark lines touching the pad).
  cv::Mat roi, dark;
  cv::GaussianBlur(gray(win), roi, {3, 3}, 0);
  int hist[256] = {};
  for (int r = 0; r < roi.rows; ++r)
    for (int c = 0; c < roi.cols; ++c) ++hist[roi.at<uint8_t>(r, c)];
  const int otsu = otsu_level(hist, 0, 256);
  const cv::Mat disc5 = cv::getStructuringElement(cv::MORPH_ELLIPSE, {5, 5});
  std::vector<std::vector<cv::Point>> contours;
  for (const int level : {otsu, otsu_level(hist, 0, otsu + 1)}) {
    std::vector<std::vector<cv::Point>> found;
    cv::threshold(roi, dark, level, 255, cv::THRESH_BINARY_INV);
    cv::morphologyEx(dark, dark, cv::MORPH_OPEN, disc5);
    cv::findContours(dark, found, cv::RETR_EXTERNAL, cv::CHAIN_APPROX_SIMPLE);
    contours.insert(contours.end(), found.begin(), found.end());
  }
  const cv::Point2f centre(win.width / 2.0f, win.height / 2.0f);
  std::vector<std::pair<double, Quad>> candidates;
  for (const auto& c : contours) {
    const double area = cv::contourArea(c);
    if (area < opt.min_side_px * opt.min_side_px) continue;
    std::vector<cv::Point> hull, poly;
    cv::convexHull(c, hull);
    cv::approxPolyDP(hull, poly, 0.04 * cv::arcLength(hull, true), true);
    Quad q;
    if (poly.size() == 4) {
      for (int i = 0; i < 4; ++i) q[i] = cv::Point2f(poly[i]) + cv::Point2f(win.tl());
    } else {
      cv::Point2f p[4];
      cv::minAreaRect(hull).points(p);
      for (int i = 0; i < 4; ++i) q[i] = p[i] + cv::Point2f(win.tl());
    }
    const cv::Moments m = cv::moments(hull);
    const cv::Point2f mid(static_cast<float>(m.m10 / m.m00), static_cast<float>(m.m01 / m.m00));
    candidates.push_back({std::sqrt(area) * (1 - cv::norm(mid - centre) / std::hypot(win.width, win.height)), q});
  }
  std::sort(candidates.begin(), candidates.end(), [](const auto& a, const auto& b) { return a.first > b.first; });
  PadMiss why = PadMiss::NoQuad;
  const double h = design.size_m / 2;
  for (size_t k = 0; k < std::min<size_t>(candidates.size(), 6); ++k) {
    Quad q = candidates[k].second;
    detail::make_clockwise(q);
    const bool fitted = detail::in_image(q, gray, opt) && detail::refine_dark_quad(gray, q, 0.06) &&
                        detail::in_image(q, gray, opt) && detail::refine_dark_quad(gray, q, 0.025);
    if (!fitted || !detail::in_image(q, gray, opt)) {
      why = std::max(why, detail::in_image(q, gray, opt) ? PadMiss::NoQuad : PadMiss::TouchesBorder);
      continue;
    }
    // The corner order: the rotation of the quad whose top view is most like the drawing.
    int best = 0;
    double score = -1;
    for (int r = 0; r < 4; ++r) {
      Quad t = q;
      std::rotate(t.begin(), t.begin() + r, t.end());
      const double s = detail::correlation(detail::top_view(gray, t, kSide), design.templ);
      if (s > score) score = s, best = r;
    }
    if (score < std::max(opt.min_marking_score, kMinDesignScore)) {
      why = std::max(why, PadMiss::NoMarking);
      continue;
    }
    std::rotate(q.begin(), q.begin() + best, q.end());
    std::optional<PadObservation> o = detail::rectangle_pose(q, h, h, camera, opt);
    if (!o) {
      why = std::max(why, PadMiss::Reprojection);
      continue;
    }
    const double period = 2 * CV_PI / design.symmetry;  // the drawing's own symmetry
    o->yaw = std::remainder(std::atan2(o->rotation(1, 0), o->rotation(0, 0)), period);
    if (o->yaw <= -period / 2) o->yaw += period;
    for (int i = 0; i < 4; ++i) o->corners[i] = q[i];
    const cv::Rect2f box = cv::boundingRect(std::vector<cv::Point2f>(q.begin(), q.end()));
    o->box = cv::Rect2d(box.x, box.y, box.width, box.height);
    o->marking_score = score;
    if (miss) *miss = PadMiss::None;
    return o;
  }
  return missed(why);
}

std::optional<RoundSighting> observe_round_pad(const cv::Mat& frame, const PadDesign& design, const cv::Mat& mask,
                                               const RoundOptions& opt) {
  if (frame.empty()) bad("observe_round_pad", "empty frame");
  if (design.outline != PadDesign::Outline::Round) bad("observe_round_pad", design.name + " is not a round design");
  if (!mask.empty() && (mask.size() != frame.size() || mask.type() != CV_8UC1))
    bad("observe_round_pad", "the mask is " + std::to_string(mask.cols) + "x" + std::to_string(mask.rows) +
                                 (mask.type() == CV_8UC1 ? "" : " and not 8-bit gray") + ", the frame " +
                                 std::to_string(frame.cols) + "x" + std::to_string(frame.rows));
  const cv::Mat gray = to_gray(frame);
  // Dark: below the local mean (a block of an eighth of the image: wider than the ring's stroke
  // at every height where the ring fits) by threshold_c grey levels; the blocked view is not dark.
  cv::Mat blurred, dark;
  cv::GaussianBlur(gray, blurred, {3, 3}, 0);
  const int block = 2 * (std::min(gray.cols, gray.rows) / 16) + 1;
  cv::adaptiveThreshold(blurred, dark, 255, cv::ADAPTIVE_THRESH_MEAN_C, cv::THRESH_BINARY_INV, std::max(3, block),
                        opt.threshold_c);
  if (!mask.empty()) dark.setTo(0, mask == 0);
  std::optional<RoundSighting> best;
  for (const Ring& r : rings(dark, opt.min_diameter_px)) {
    if (std::abs(r.ratio - design.ring_inner_ratio) > opt.ratio_tolerance) continue;
    // Fully visible: inside the image and clear of the mask (grown by 2 px).
    const cv::Rect box = r.outer.boundingRect();
    const cv::Rect inner_image(2, 2, gray.cols - 4, gray.rows - 4);
    if ((box & inner_image) != box) continue;
    if (!mask.empty()) {
      cv::Mat ring_area = cv::Mat::zeros(box.size(), CV_8U);
      cv::RotatedRect e = r.outer;
      e.center -= cv::Point2f(box.tl());
      e.size += cv::Size2f(4, 4);
      cv::ellipse(ring_area, e, 255, cv::FILLED);
      if (cv::countNonZero(ring_area & (mask(box) == 0)) > 0) continue;
    }
    // The inside against the drawing at every rotation (5 deg steps).
    const cv::Mat view = disc(ellipse_view(gray, r.inner), 0.92);
    RoundSighting s;
    s.outer = r.outer;
    s.score = -1;
    for (int deg = 0; deg < 360; deg += 5) {
      const double c = detail::correlation(view, disc(rotated(design.templ, deg), 0.92));
      if (c > s.score) s.score = c, s.rotation_deg = deg;
    }
    if (s.score < opt.min_score) continue;
    // The view's x axis is the inner ellipse's first axis: back to the image's.
    s.rotation_deg = std::fmod(s.rotation_deg - r.inner.angle + 720, 360);
    // The outer diameter from both edges of the ring (a threshold that widens the dark stroke
    // moves them apart: their mean cancels it).
    s.diameter_px = (major(r.outer) + major(r.inner)) / (1 + design.ring_inner_ratio);
    if (!best || s.score > best->score) best = s;
  }
  return best;
}

}  // namespace aerie::track
