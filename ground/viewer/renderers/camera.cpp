#include "ground/viewer/renderers/camera.hpp"

#include <aerie/stereo_image_t.hpp>

#include <cmath>
#include <cstdio>
#include <opencv2/imgproc.hpp>

#include "common/image/image_message.hpp"

namespace aerie::viewer {

CameraRenderer::CameraRenderer(std::string channel) : Renderer("camera"), channel_(std::move(channel)) {}

void CameraRenderer::subscribe(bus::Bus& bus) {
  // Queue of 2: the viewer shows the newest frame; older ones would only add latency.
  if (channel_.rfind("CAM_STEREO", 0) == 0) {
    bus.subscribe<aerie::stereo_image_t>(
        channel_,
        [this](const aerie::stereo_image_t& m, const bus::ReceiveInfo&) {
          image_.set(image::from_message(m.left));
          utime_ = m.utime;
        },
        2);
  } else {
    bus.subscribe<aerie::image_t>(
        channel_,
        [this](const aerie::image_t& m, const bus::ReceiveInfo&) {
          image_.set(image::from_message(m));
          utime_ = m.utime;
        },
        2);
  }
}

bool CameraRenderer::take_image(cv::Mat& out) { return image_.take_if_newer(seen_, out); }

const cv::Scalar TrackOverlay::kBoxColor(0, 0, 255);    // red
const cv::Scalar GtBoxOverlay::kBoxColor(0, 255, 0);    // green

TrackOverlay::TrackOverlay(std::string channel) : Renderer("track"), channel_(std::move(channel)) {}

void TrackOverlay::subscribe(bus::Bus& bus) {
  bus.subscribe<aerie::track_t>(channel_, [this](const aerie::track_t& m, const bus::ReceiveInfo&) { track_.set(m); });
}

bool TrackOverlay::update() {
  aerie::track_t t;
  if (!track_.take_if_newer(seen_, t)) return false;
  current_ = std::move(t);
  return true;
}

int64_t TrackOverlay::latest_utime() const {
  const auto t = track_.get();
  return t ? t->utime : 0;
}

void TrackOverlay::draw_image(cv::Mat& canvas) {
  if (!current_ || current_->status == aerie::track_t::IDLE) return;
  const auto& t = *current_;
  // Samples per level: coarse levels in cool colours, the finest in yellow.
  static const cv::Scalar level_colors[] = {{0, 255, 255}, {255, 200, 0}, {255, 0, 255}, {255, 128, 128}};
  for (const auto& level : t.levels) {
    const cv::Scalar c = level_colors[std::min<int>(std::max(level.level, 0), 3)];
    for (int i = 0; i < level.npoints; ++i) cv::circle(canvas, cv::Point(cvRound(level.u[i]), cvRound(level.v[i])), 1, c, cv::FILLED);
  }
  const cv::Scalar color = t.status == aerie::track_t::LOST ? cv::Scalar(0, 128, 255) : kBoxColor;
  std::vector<cv::Point> poly;
  for (const auto& c : t.corners) poly.emplace_back(cvRound(c[0]), cvRound(c[1]));
  cv::polylines(canvas, poly, true, color, 2, cv::LINE_8);
  char label[96];
  std::snprintf(label, sizeof(label), "%s %.2f%s", t.tracker.c_str(), t.confidence,
                t.status == aerie::track_t::LOST ? " LOST" : "");
  const cv::Point anchor(poly[0].x, std::max(12, poly[0].y - 6));
  cv::putText(canvas, label, anchor, cv::FONT_HERSHEY_SIMPLEX, 0.45, color, 1, cv::LINE_AA);
}

PilotOverlay::PilotOverlay(std::string channel) : Renderer("pilot"), channel_(std::move(channel)) {}

void PilotOverlay::subscribe(bus::Bus& bus) {
  bus.subscribe<aerie::pilot_state_t>(channel_, [this](const aerie::pilot_state_t& m, const bus::ReceiveInfo&) { state_.set(m); });
}

bool PilotOverlay::update() {
  aerie::pilot_state_t s;
  if (!state_.take_if_newer(seen_, s)) return false;
  current_ = std::move(s);
  return true;
}

std::string PilotOverlay::banner(const aerie::pilot_state_t& s) {
  char text[160];
  const bool landing = s.state == aerie::pilot_state_t::TOUCHDOWN || s.state == aerie::pilot_state_t::LANDED;
  if (s.target_valid && !landing)
    std::snprintf(text, sizeof text, "%s  h %.2f m  off %.2f m  yaw %+.1f deg  losses %d", s.state_name.c_str(),
                  s.height_m, std::hypot(s.target_body[0], s.target_body[1]), s.target_yaw_error_deg, s.losses);
  else
    std::snprintf(text, sizeof text, "%s  (%s)  losses %d", s.state_name.c_str(), s.reason.c_str(), s.losses);
  return text;
}

void PilotOverlay::draw_image(cv::Mat& canvas) {
  if (!current_) return;
  const auto& s = *current_;
  const bool alarm = s.state == aerie::pilot_state_t::HOLD || s.state == aerie::pilot_state_t::ABORT ||
                     s.state == aerie::pilot_state_t::ABORTED;
  const cv::Scalar color = alarm ? cv::Scalar(0, 128, 255) : cv::Scalar(255, 255, 255);
  cv::rectangle(canvas, cv::Rect(0, canvas.rows - 18, canvas.cols, 18), cv::Scalar(0, 0, 0), cv::FILLED);
  cv::putText(canvas, banner(s), cv::Point(4, canvas.rows - 5), cv::FONT_HERSHEY_SIMPLEX, 0.4, color, 1, cv::LINE_AA);
}

GtBoxOverlay::GtBoxOverlay(std::string channel) : Renderer("gt-box"), channel_(std::move(channel)) {}

void GtBoxOverlay::subscribe(bus::Bus& bus) {
  bus.subscribe<aerie::gt_box_t>(channel_, [this](const aerie::gt_box_t& m, const bus::ReceiveInfo&) { box_.set(m); });
}

bool GtBoxOverlay::update() {
  aerie::gt_box_t b;
  if (!box_.take_if_newer(seen_, b)) return false;
  current_ = b;
  return true;
}

void GtBoxOverlay::draw_image(cv::Mat& canvas) {
  if (!current_ || !current_->visible) return;
  const auto& b = *current_;
  cv::rectangle(canvas, cv::Rect(cvRound(b.x), cvRound(b.y), cvRound(b.width), cvRound(b.height)), kBoxColor, 1);
}

}  // namespace aerie::viewer
