#include "air/stereo/node/vo_node.hpp"

#include <aerie/pose_t.hpp>
#include <spdlog/spdlog.h>

#include <algorithm>
#include <cmath>
#include <stdexcept>

#include "air/stereo/vo/vo_config.hpp"
#include "common/image/image_message.hpp"
#include "common/spherical/spherical_message.hpp"
#include "common/util/message_clock.hpp"
#include "common/util/time.hpp"

namespace aerie::stereo {

VoNodeConfig load_vo_node_config(const util::Config& cfg) {
  VoNodeConfig c;
  c.vo = vo_params_from_config(cfg, kNodeSections);
  c.message_time = util::MessageClockConfig::from_config(cfg.section("message_time"), c.message_time);
  const util::Config n = cfg.section("node");
  c.input = n.get<std::string>("input", c.input);
  c.pose = n.get<std::string>("pose", c.pose);
  c.depth = n.get<std::string>("depth", c.depth);
  c.max_pair_skew_us = n.get<int64_t>("max_pair_skew_us", c.max_pair_skew_us);
  c.spherical_resolution_deg = n.get<double>("spherical_resolution_deg", c.spherical_resolution_deg);
  c.spherical_max_range_m = n.get<double>("spherical_max_range_m", c.spherical_max_range_m);
  c.queue = n.get<int>("queue", c.queue);
  n.check_keys({"input", "pose", "depth", "max_pair_skew_us", "spherical_resolution_deg", "spherical_max_range_m", "queue"});
  if (c.input.empty() || c.pose.empty()) throw std::runtime_error(cfg.origin() + ": node.input and node.pose are required");
  if (c.max_pair_skew_us < 0 || c.queue < 1 || !(c.spherical_resolution_deg > 0) || !(c.spherical_max_range_m > 0))
    throw std::runtime_error(cfg.origin() + ": node.max_pair_skew_us >= 0, node.queue >= 1 and positive spherical_*");
  return c;
}

VoNode::VoNode(bus::Bus& bus, bus::StatusReporter& status, const VoNodeConfig& cfg, util::NodeClock now)
    : bus_(bus),
      status_(status),
      cfg_(cfg),
      now_(std::move(now)),
      camera_clock_(status, cfg.input, cfg.message_time),
      input_(bus_.subscribe_queued<aerie::stereo_image_t>(
          cfg_.input,
          [this](const aerie::stereo_image_t& m, const bus::ReceiveInfo& info) { on_stereo(m, info.recv_utime); },
          static_cast<size_t>(std::max(cfg_.queue, 1)))) {
  cfg_.vo.validate();
  status_.ok("waiting for " + cfg_.input);
}

void VoNode::tick() {
  camera_clock_.check(now_());
  if (queue_overflows() > reported_overflows_) report(status_.message());
}

void VoNode::report(const std::string& state) {
  const int64_t overflows = queue_overflows(), gaps = upstream_gaps();
  if (overflows == 0 && gaps == 0) return status_.ok(state);
  // The state without a previous report's suffix (tick() re-reports the last message).
  const std::string base = state.substr(0, state.find(" | "));
  const std::string losses = base + " | " + cfg_.input + ": " + std::to_string(overflows) +
                             " pairs dropped here (input queue of " + std::to_string(cfg_.queue) +
                             " full: the odometry is slower than the camera), " + std::to_string(gaps) +
                             " missing upstream (sequence gaps)";
  const int64_t now = now_();
  if (overflows > reported_overflows_) {
    reported_overflows_ = overflows;
    last_overflow_us_ = now;
  }
  // WARN while pairs are being dropped (one within the last 2 s), OK with the totals after.
  if (overflows > 0 && now - last_overflow_us_ < 2'000'000) return status_.warn(losses);
  status_.ok(losses);
}

VoNode::~VoNode() = default;

void VoNode::check(const aerie::stereo_image_t& m) const {
  const std::string what = cfg_.input + " seq " + std::to_string(m.seq) + ": ";
  if (m.left.width != m.right.width || m.left.height != m.right.height)
    throw std::invalid_argument(what + "left is " + std::to_string(m.left.width) + "x" + std::to_string(m.left.height) +
                                " but right is " + std::to_string(m.right.width) + "x" +
                                std::to_string(m.right.height));
  // Overflow-free: a hostile stamp overflowed |a - b| here (docs/fuzz.md, finding 6).
  if (!util::within(m.left.utime, m.right.utime, cfg_.max_pair_skew_us) ||
      !util::within(m.utime, m.left.utime, cfg_.max_pair_skew_us))
    throw std::invalid_argument(what + "left/right/pair utimes " + std::to_string(m.left.utime) + " / " +
                                std::to_string(m.right.utime) + " / " + std::to_string(m.utime) + " differ by more than " +
                                std::to_string(cfg_.max_pair_skew_us) + " us");
  // Rectified intrinsics a camera can have (a corrupt 1e200 baseline is positive, too).
  const double w = m.left.width, h = m.left.height;
  if (!(m.fx > 0 && m.fx <= 1e5) || !(m.fy > 0 && m.fy <= 1e5) || !(m.baseline_m > 0 && m.baseline_m <= 100) ||
      !(m.cx >= -w && m.cx <= 2 * w) || !(m.cy >= -h && m.cy <= 2 * h))
    throw std::invalid_argument(what + "rectified intrinsics out of range: fx, fy must be in (0, 1e5] px, baseline_m in (0, 100] m, "
                                       "cx, cy within one image size of the image");
}

void VoNode::on_stereo(const aerie::stereo_image_t& m, int64_t receive_utime) {
  cv::Mat left, right;
  try {
    check(m);
    left = image::gray_from_message(m.left);
    right = image::gray_from_message(m.right);
  } catch (const std::exception& e) {
    ++refused_;
    status_.count("refused_pairs");
    status_.warn(e.what());
    spdlog::warn("refused stereo pair: {}", e.what());
    return;
  }
  // The message-time policy: a pair whose time jumps is held (counted "<input>.time_jumps");
  // a re-synchronisation (camera restarted or back after an outage) restarts the odometry.
  const auto time = camera_clock_.observe(m.utime, now_());
  if (!time.accepted()) return;
  if (time.verdict == util::MessageClock::Verdict::kResynced && vo_) {
    vo_->reset(time.reason);
    status_.count("time_resets");
  }
  // A new camera (first pair, or size/intrinsics changed) or time going backwards (a log
  // replayed from the start): start over.
  const StereoCamera cam{m.fx, m.fy, m.cx, m.cy, m.baseline_m, left.cols, left.rows};
  const bool new_camera = !vo_ || vo_->camera() != cam;
  if (vo_ && new_camera) {
    // Another camera than the running odometry's: one corrupt pair must not restart it;
    // resync_messages pairs in a row with the same new camera do.
    camera_run_ = pending_camera_ == cam ? camera_run_ + 1 : 1;
    pending_camera_ = cam;
    if (camera_run_ < cfg_.message_time.resync_messages) {
      status_.count("camera_change_pending");
      return;
    }
  }
  pending_camera_.reset();
  camera_run_ = 0;
  try {
    if (new_camera) {
      if (vo_) spdlog::warn("camera changed on {}: restarting the odometry", cfg_.input);
      vo_ = std::make_unique<StereoOdometry>(cam, cfg_.vo);
      const int s = cfg_.vo.depth_scale;
      spherical::EncoderConfig ec;
      ec.angular_resolution_rad = static_cast<float>(cfg_.spherical_resolution_deg * M_PI / 180.0);
      ec.max_range_m = static_cast<float>(cfg_.spherical_max_range_m);
      // The dense map's size: vo.cpp halves the pair with cv::resize(..., 0.5, 0.5), whose
      // output is saturate_cast<int>(size * 0.5), rounded half to even (377 -> 188, 379 -> 190).
      const cv::Size depth_size = s == 1 ? cv::Size(cam.width, cam.height)
                                         : cv::Size(cv::saturate_cast<int>(cam.width * 0.5),
                                                    cv::saturate_cast<int>(cam.height * 0.5));
      // Intrinsics of the dense map: pixel (x, y) of a half-resolution map is (2x + 0.5, 2y + 0.5) - 0.5.
      const spherical::Intrinsics k{cam.fx / s, cam.fy / s, (cam.cx + 0.5) / s - 0.5, (cam.cy + 0.5) / s - 0.5,
                                    cam.baseline};
      encoder_ = cfg_.depth.empty() ? nullptr : std::make_unique<spherical::SphericalEncoder>(k, depth_size, ec);
      spdlog::info("camera {}x{} f {:.1f} px baseline {:.3f} m; dense depth {}x{} every {} pairs", cam.width,
                   cam.height, cam.fx, cam.baseline, depth_size.width, depth_size.height, cfg_.vo.depth_every);
      status_.count("camera_changes");
    } else if (m.utime <= last_utime_ && time.verdict != util::MessageClock::Verdict::kResynced) {
      // Not newer than the last pair. A copy of it (a duplicated or corrupted datagram) is
      // dropped. An older one is dropped too, unless resync_messages older pairs come in a
      // row, each newer than the one before: a new time base (a log replayed from its start),
      // and the odometry starts over. One stray pair must not restart it: a burst of copies
      // of one frame restarted it on every copy, and the avoidance manoeuvre lost its frame.
      if (m.utime == last_utime_) {
        status_.count("duplicate_pairs");
        return;
      }
      older_run_ = older_run_ > 0 && m.utime > older_last_ ? older_run_ + 1 : 1;
      older_last_ = m.utime;
      if (older_run_ < cfg_.message_time.resync_messages) {
        status_.count("out_of_order_pairs");
        return;
      }
      vo_->reset("time went back from " + std::to_string(last_utime_) + " to " + std::to_string(m.utime));
      status_.count("time_resets");
    }
    older_run_ = 0;
    last_utime_ = m.utime;
    const VoResult r = vo_->process(left, right, m.utime);
    ++processed_;
    publish(r, m.seq, receive_utime);
    last_ = r;
  } catch (const std::exception& e) {
    // Not expected (the input was checked): report, keep the node alive, start over.
    status_.count("errors");
    status_.error(std::string("odometry failed: ") + e.what());
    spdlog::error("odometry failed on {} seq {}: {}", cfg_.input, m.seq, e.what());
    vo_.reset();
  }
}

void VoNode::publish(const VoResult& r, int64_t seq, int64_t receive_utime) {
  aerie::pose_t p{};
  p.utime = r.utime;
  p.seq = seq;
  const auto& t = r.T_world_cam.translation();
  for (int i = 0; i < 3; ++i) p.position[i] = t[i];
  r.T_world_cam.to_wxyz(p.orientation);
  for (int i = 0; i < 36; ++i) p.covariance[i] = r.covariance(i / 6, i % 6);
  p.features_2d = r.features_2d;
  p.features_3d = r.features_3d;
  p.inliers = r.inliers;
  p.keyframe = r.keyframe;
  switch (r.status) {
    case VoStatus::Ok: p.status = aerie::pose_t::OK; break;
    case VoStatus::Initialising: p.status = aerie::pose_t::INITIALISING; break;
    case VoStatus::Lost: p.status = aerie::pose_t::LOST; break;
    case VoStatus::Reset: p.status = aerie::pose_t::RESET; break;
  }
  bus_.publish(cfg_.pose, p);
  if (encoder_ && r.depth_computed && !r.disparity.empty()) {
    const spherical::SphericalDepth depth = encoder_->encode_disparity(r.disparity);
    bus_.publish(cfg_.depth, spherical::to_message(depth, r.utime, seq, r.T_world_cam));
    status_.count("depth_frames");
  }
  const int64_t now = util::wall_utime();
  status_.mark_hop(r.utime, receive_utime, now);
  status_.count("frames");
  if (r.keyframe) status_.count("keyframes");
  if (r.ba_applied) status_.count("ba_results");
  if (r.status == VoStatus::Lost) {
    status_.count("lost");
    status_.warn(r.message);
    spdlog::warn("frame {}: {}", r.frame, r.message);
  } else if (r.status == VoStatus::Reset) {
    status_.count("resets");
    spdlog::info("frame {}: {}", r.frame, r.message);
  } else {
    report(to_string(r.status));
  }
  status_.set("features", r.features);
  status_.set("matches", r.matches);
  status_.set("features_3d", r.features_3d);
  status_.set("features_2d", r.features_2d);
  status_.set("inliers", r.inliers);
  status_.set("inlier_ratio_permille", std::lround(1000 * r.inlier_ratio));
  for (size_t b = 0; b < r.per_bucket.size(); ++b)
    status_.set((b < 10 ? "bucket_0" : "bucket_") + std::to_string(b), r.per_bucket[b]);
  status_.time_ms("depth", r.timings.depth);
  status_.time_ms("features", r.timings.features);
  status_.time_ms("matching", r.timings.matching);
  status_.time_ms("motion", r.timings.motion);
  status_.time_ms("other", r.timings.bookkeeping);
  status_.time_ms("total", r.timings.total());
  status_.time_ms("latency", static_cast<double>(now - receive_utime) * 1e-3);
}

}  // namespace aerie::stereo
