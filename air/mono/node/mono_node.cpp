#include "air/mono/node/mono_node.hpp"

#include <aerie/pose_t.hpp>
#include <spdlog/spdlog.h>

#include <cmath>
#include <stdexcept>

#include "air/mono/mono_config.hpp"
#include "common/image/image_message.hpp"
#include "common/util/time.hpp"

namespace aerie::mono {

MonoNodeConfig load_mono_node_config(const util::Config& cfg) {
  MonoNodeConfig c;
  c.mono = mono_params_from_config(cfg, kMonoNodeSections);
  const util::Config n = cfg.section("node");
  c.input = n.get<std::string>("input", c.input);
  c.pose = n.get<std::string>("pose", c.pose);
  c.queue = n.get<int>("queue", c.queue);
  c.fx = n.get<double>("fx", c.fx);
  c.fy = n.get<double>("fy", c.fy);
  c.cx = n.get<double>("cx", c.cx);
  c.cy = n.get<double>("cy", c.cy);
  n.check_keys({"input", "pose", "queue", "fx", "fy", "cx", "cy"});
  if (c.input.empty() || c.pose.empty()) throw std::runtime_error(cfg.origin() + ": node.input and node.pose are required");
  if (c.queue < 1) throw std::runtime_error(cfg.origin() + ": node.queue: expected >= 1");
  if (!(c.fx >= 0 && c.fx <= 1e5) || !(c.fy >= 0 && c.fy <= 1e5) || !std::isfinite(c.cx) || !std::isfinite(c.cy))
    throw std::runtime_error(cfg.origin() + ": node.fx, node.fy: expected in [0, 1e5] px (0 = from the image), cx, cy finite");
  return c;
}

MonoNode::MonoNode(bus::Bus& bus, const MonoNodeConfig& cfg) : Node(bus, "mono"), cfg_(cfg) {
  cfg_.mono.validate();
  subscribe<aerie::image_t>(
      cfg_.input, [this](const aerie::image_t& m, const bus::ReceiveInfo& info) { on_image(m, info.recv_utime); },
      cfg_.queue);
  status().ok("waiting for " + cfg_.input);
}

PinholeCamera MonoNode::camera_for(const aerie::image_t& m, const cv::Mat& gray) const {
  auto value = [&](const char* key, double configured) {
    if (configured != 0) return configured;
    const auto v = image::metadata(m, key);
    if (!v) throw std::invalid_argument(cfg_.input + ": no intrinsics: set node." + key + " or send image metadata \"" + key + "\"");
    try {
      return std::stod(*v);
    } catch (const std::exception&) {
      throw std::invalid_argument(cfg_.input + ": image metadata \"" + key + "\" is not a number: '" + *v + "'");
    }
  };
  PinholeCamera cam{value("fx", cfg_.fx), value("fy", cfg_.fy), value("cx", cfg_.cx), value("cy", cfg_.cy), gray.cols,
                    gray.rows};
  const double w = gray.cols, h = gray.rows;
  if (!(cam.fx > 0 && cam.fx <= 1e5) || !(cam.fy > 0 && cam.fy <= 1e5) || !(cam.cx >= -w && cam.cx <= 2 * w) ||
      !(cam.cy >= -h && cam.cy <= 2 * h))
    throw std::invalid_argument(cfg_.input + ": intrinsics out of range: fx, fy in (0, 1e5] px, cx, cy within one image size");
  return cam;
}

void MonoNode::on_image(const aerie::image_t& m, int64_t receive_utime) {
  cv::Mat gray;
  PinholeCamera cam;
  try {
    gray = image::gray_from_message(m);
    cam = camera_for(m, gray);
  } catch (const std::exception& e) {
    ++refused_;
    status().count("refused_images");
    status().warn(e.what());
    spdlog::warn("refused image: {}", e.what());
    return;
  }
  try {
    if (!vo_ || !(vo_->camera() == cam)) {
      if (vo_) spdlog::warn("camera changed on {}: a new odometry (and map)", cfg_.input);
      vo_ = std::make_unique<MonoOdometry>(cam, cfg_.mono);
      status().count("camera_changes");
      spdlog::info("camera {}x{} f {:.1f} px", cam.width, cam.height, cam.fx);
    } else if (m.utime <= last_utime_) {
      if (m.utime == last_utime_) {  // a copy of the last image
        status().count("duplicate_images");
        return;
      }
      vo_->reset("time went back from " + std::to_string(last_utime_) + " to " + std::to_string(m.utime));
      status().count("time_resets");
    }
    last_utime_ = m.utime;
    const MonoResult r = vo_->process(gray, m.utime);
    ++processed_;
    publish(r, image::sequence_number(m), receive_utime);
    last_ = r;
  } catch (const std::exception& e) {
    status().count("errors");
    status().error(std::string("odometry failed: ") + e.what());
    spdlog::error("odometry failed on {}: {}", cfg_.input, e.what());
    vo_.reset();
  }
}

void MonoNode::publish(const MonoResult& r, int64_t seq, int64_t receive_utime) {
  aerie::pose_t p{};
  p.utime = r.utime;
  p.seq = seq;
  const auto& t = r.T_world_cam.translation();
  for (int i = 0; i < 3; ++i) p.position[i] = t[i];
  r.T_world_cam.to_wxyz(p.orientation);
  p.features_2d = r.tracks - r.tracked_landmarks;  // tracked points without a landmark
  p.features_3d = r.tracked_landmarks;
  p.inliers = r.inliers;
  p.keyframe = r.keyframe;
  int8_t state = aerie::pose_t::OK;
  switch (r.status) {
    case MonoStatus::Ok: state = aerie::pose_t::OK; break;
    case MonoStatus::Initialising: state = aerie::pose_t::INITIALISING; break;
    case MonoStatus::Lost: state = aerie::pose_t::LOST; break;
    case MonoStatus::Reset: state = aerie::pose_t::RESET; break;
  }
  p.status = static_cast<int8_t>(state | aerie::pose_t::SCALE_ARBITRARY);
  bus().publish(cfg_.pose, p);
  auto& s = status();
  const int64_t now = util::wall_utime();
  s.mark_hop(r.utime, receive_utime, now);
  s.count("frames");
  if (r.skipped) s.count(r.input_problem + "_frames");  // frozen_frames, blank_frames
  if (r.keyframe) s.count("keyframes_made");
  if (r.ba_applied) s.count("ba_results");
  if (r.status == MonoStatus::Lost) {
    s.count("lost");
    s.warn(r.message);
    spdlog::warn("frame {}: {}", r.frame, r.message);
  } else if (r.status == MonoStatus::Reset) {
    s.count("resets");
    s.ok(r.message);
    spdlog::info("frame {}: {}", r.frame, r.message);
  } else if (r.skipped || r.status == MonoStatus::Initialising) {
    s.warn(r.message);
  } else {
    s.ok(to_string(r.status));
  }
  s.set("keyframes", r.keyframes);
  s.set("landmarks", r.landmarks);
  s.set("tracks", r.tracks);
  s.set("tracked_landmarks", r.tracked_landmarks);
  s.set("inliers", r.inliers);
  s.set("scale_generation", r.scale_generation);
  s.time_ms("tracking", r.timings.tracking);
  s.time_ms("init", r.timings.init);
  s.time_ms("pose", r.timings.pose);
  s.time_ms("keyframe", r.timings.keyframe);
  s.time_ms("total", r.timings.total());
  s.time_ms("latency", static_cast<double>(now - receive_utime) * 1e-3);
}

}  // namespace aerie::mono
