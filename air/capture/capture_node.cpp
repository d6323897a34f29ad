#include "air/capture/capture_node.hpp"

#include <spdlog/spdlog.h>

#include <chrono>
#include <thread>

#include "air/capture/pacer.hpp"
#include "common/bus/node.hpp"
#include "common/bus/status.hpp"
#include "common/util/time.hpp"

namespace aerie::capture {

namespace {
// The channel rule a config can break: split_stereo publishes the pair's images alone as well.
void check_channels(const ChannelNames& ch, const std::string& where) {
  if (ch.split_stereo && (ch.stereo.empty() || (ch.left.empty() && ch.right.empty())))
    throw std::invalid_argument(where + ": channels.split_stereo: true needs channels.stereo and channels.left or "
                                "channels.right (it publishes the stereo pair's images alone as well)");
}
}  // namespace

CaptureConfig load_capture_config(const util::Config& c) {
  c.check_keys({"source.type", "source.path", "source.right", "source.calib", "source.timestamps",
                "source.groundtruth", "source.fps", "sim.seed", "sim.trajectory", "sim.speed", "sim.loops",
                "sim.noise_sigma", "sim.start_utime", "output.width", "output.height", "output.downscale",
                "output.color", "output.encoding", "output.jpeg_quality", "playback.rate", "playback.start",
                "playback.stop", "playback.duration", "playback.loop", "playback.stamp",
                "playback.max_consecutive_errors", "channels.left", "channels.right", "channels.stereo",
                "channels.mono", "channels.gt_pose", "channels.gt_track", "channels.split_stereo"});
  constexpr int64_t kMaxFrames = int64_t{1} << 40;
  CaptureConfig k;
  auto& s = k.source;
  s.type = c.get("source.type", s.type);
  s.path = c.get("source.path", s.path);
  s.right = c.get("source.right", s.right);
  s.calib = c.get("source.calib", s.calib);
  s.timestamps = c.get("source.timestamps", s.timestamps);
  s.groundtruth = c.get("source.groundtruth", s.groundtruth);
  s.fps = c.get_in("source.fps", s.fps, 0.01, 1000.0);
  s.sim.seed = c.get<uint64_t>("sim.seed", s.sim.seed);
  s.sim.trajectory = c.get("sim.trajectory", s.sim.trajectory);
  s.sim.speed = c.get_in("sim.speed", s.sim.speed, 0.01, 20.0);
  s.sim.loops = c.get_in("sim.loops", s.sim.loops, 1, 1000);
  s.sim.noise_sigma = c.get_in("sim.noise_sigma", s.sim.noise_sigma, 0.0, 255.0);
  s.sim.start_utime = c.get_in<int64_t>("sim.start_utime", s.sim.start_utime, -1, int64_t{1} << 62);
  auto& o = k.output;
  o.width = c.get_in("output.width", o.width, 0, 16384);
  o.height = c.get_in("output.height", o.height, 0, 16384);
  o.downscale = c.get_in("output.downscale", o.downscale, 1.0, 64.0);
  o.color = c.get("output.color", o.color);
  k.encoding = c.get("output.encoding", k.encoding);
  k.jpeg_quality = c.get_in("output.jpeg_quality", k.jpeg_quality, 1, 100);
  k.rate = c.get_in("playback.rate", k.rate, 0.0, 1000.0);
  k.start = c.get_in<int64_t>("playback.start", k.start, 0, kMaxFrames);
  k.stop = c.get_in<int64_t>("playback.stop", k.stop, -1, kMaxFrames);
  k.duration_s = c.get_in("playback.duration", k.duration_s, 0.0, 1e7);
  k.loop = c.get("playback.loop", k.loop);
  k.stamp = c.get("playback.stamp", k.stamp);
  k.max_consecutive_errors = c.get_in("playback.max_consecutive_errors", k.max_consecutive_errors, 1, 1000000);
  auto& ch = k.channels;
  ch.left = c.get("channels.left", ch.left);
  ch.right = c.get("channels.right", ch.right);
  ch.stereo = c.get("channels.stereo", ch.stereo);
  ch.mono = c.get("channels.mono", ch.mono);
  ch.gt_pose = c.get("channels.gt_pose", ch.gt_pose);
  ch.gt_track = c.get("channels.gt_track", ch.gt_track);
  ch.split_stereo = c.get("channels.split_stereo", ch.split_stereo);
  check_channels(ch, c.origin());
  return k;
}

MessageBuilder::MessageBuilder(const CaptureConfig& cfg, bool stereo, std::optional<camera::RectifiedStereo> rectified)
    : cfg_(cfg), stereo_(stereo), rectified_(rectified), encoding_(image::encoding_from_string(cfg.encoding)) {
  if (cfg.jpeg_quality < 1 || cfg.jpeg_quality > 100) throw std::invalid_argument("jpeg_quality must be in 1..100");
}

FrameMessages MessageBuilder::build(const Frame& f, int64_t utime, int64_t seq) const {
  FrameMessages m;
  const auto& ch = cfg_.channels;
  auto image = [&](const cv::Mat& img, const std::string& camera) {
    auto msg = image::to_message(img, utime, seq, encoding_, cfg_.jpeg_quality);
    image::set_metadata(msg, "camera", camera);
    return msg;
  };
  std::string image_channel;  // the channel GT_TRACK refers to
  if (stereo_) {
    // Each image once: with CAM_STEREO, left and right alone only when asked (split_stereo).
    const bool with_stereo = !ch.stereo.empty() && rectified_;
    const bool alone = !with_stereo || ch.split_stereo;
    image_channel = alone && !ch.left.empty() ? ch.left : with_stereo ? ch.stereo : ch.left;
    const bool need_pair = (alone && (!ch.left.empty() || !ch.right.empty())) || with_stereo;
    if (need_pair) {
      m.left = image(f.left, "left");
      m.right = image(f.right, "right");
    }
    if (!ch.stereo.empty() && rectified_) {
      aerie::stereo_image_t s;
      s.utime = utime;
      s.seq = seq;
      s.left = *m.left;
      s.right = *m.right;
      s.fx = rectified_->fx;
      s.fy = rectified_->fy;
      s.cx = rectified_->cx;
      s.cy = rectified_->cy;
      s.baseline_m = rectified_->baseline;
      m.stereo = std::move(s);
    }
    if (ch.left.empty() || !alone) m.left.reset();
    if (ch.right.empty() || !alone) m.right.reset();
  } else {
    image_channel = ch.mono;
    if (!ch.mono.empty()) m.mono = image(f.left, "mono");
  }
  if (f.gt_pose && !ch.gt_pose.empty()) {
    aerie::gt_pose_t p;
    p.utime = utime;
    p.seq = seq;
    p.frame_id = f.gt_pose->frame_id;
    const auto& t = f.gt_pose->T_world_camera.translation();
    for (int i = 0; i < 3; ++i) p.position[i] = t[i];
    f.gt_pose->T_world_camera.to_wxyz(p.orientation);
    m.gt_pose = std::move(p);
  }
  if (f.gt_box && !ch.gt_track.empty()) {
    const auto& b = *f.gt_box;
    m.gt_box = image::gt_box_message(utime, seq, b.target, image_channel, b.visible, b.box, b.corners);
  }
  return m;
}

namespace {

std::optional<camera::RectifiedStereo> scaled_intrinsics(const FrameSource& src, const OutputFormat& fmt) {
  const auto r = src.rectified();
  return r ? std::optional(fmt.apply(*r)) : std::nullopt;
}

// Sleeps until the wall-clock time `until` (µs), waking for a stop request.
void sleep_until(int64_t until) {
  for (int64_t now = util::wall_utime(); now < until && !bus::stop_requested(); now = util::wall_utime())
    std::this_thread::sleep_for(std::chrono::microseconds(std::min<int64_t>(until - now, 50'000)));
}

}  // namespace

CaptureNode::CaptureNode(bus::Bus& bus, const CaptureConfig& cfg, std::unique_ptr<FrameSource> source)
    : bus_(bus),
      cfg_(cfg),
      source_(std::move(source)),
      format_(cfg_.output, source_->size()),
      builder_(cfg_, source_->stereo(), scaled_intrinsics(*source_, format_)) {
  if (cfg_.stamp != "source" && cfg_.stamp != "wall")
    throw std::invalid_argument("stamp must be 'source' or 'wall', got '" + cfg_.stamp + "'");
  if (cfg_.start < 0) throw std::invalid_argument("start frame must be >= 0");
  if (cfg_.stop >= 0 && cfg_.stop <= cfg_.start) throw std::invalid_argument("stop frame must be after the start frame");
  const auto& ch = cfg_.channels;
  if (source_->stereo() && !source_->rectified() && !ch.stereo.empty())
    spdlog::warn("{}: no stereo calibration, so no {} (only the raw pair)", source_->describe(), ch.stereo);
  check_channels(ch, "aerie-capture");
}

void CaptureNode::publish(const FrameMessages& m) {
  const auto& ch = cfg_.channels;
  if (m.left) bus_.publish(ch.left, *m.left);
  if (m.right) bus_.publish(ch.right, *m.right);
  if (m.stereo) bus_.publish(ch.stereo, *m.stereo);
  if (m.mono) bus_.publish(ch.mono, *m.mono);
  if (m.gt_pose) bus_.publish(ch.gt_pose, *m.gt_pose);
  if (m.gt_box) bus_.publish(ch.gt_track, *m.gt_box);
}

RunStats CaptureNode::run() {
  bus::install_stop_handlers();
  bus::StatusReporter status(bus_, "capture");
  status.ok(source_->describe());
  Pacer pacer(source_->live() ? 0.0 : cfg_.rate);
  RunStats st;
  const int64_t t_start = util::wall_utime();
  if (cfg_.start > 0) source_->seek(cfg_.start);
  std::optional<int64_t> first_utime;
  int64_t period_us = 0, last_utime = 0;
  // Looping: each pass is shifted in time to follow the previous one by one frame interval.
  int64_t loop_offset = 0, pass_first = 0, pass_last = 0, pass_published = 0;
  int consecutive_errors = 0;
  Frame frame;
  while (!bus::stop_requested()) {
    util::Stopwatch sw;
    bool more = false;
    try {
      more = source_->next(frame) && !(cfg_.stop >= 0 && frame.index >= cfg_.stop);
      if (more) format_.apply(frame);
      consecutive_errors = 0;
    } catch (const FrameError& e) {
      ++st.unreadable;
      status.count("frames_unreadable");
      status.warn(e.what());
      spdlog::warn("skipped an unreadable frame: {}", e.what());
      if (++consecutive_errors > cfg_.max_consecutive_errors)
        throw std::runtime_error(std::to_string(consecutive_errors) + " unreadable frames in a row; last: " + e.what());
      status.tick();
      continue;
    }
    if (!more) {  // end of the source (or of the start..stop range)
      if (!cfg_.loop || source_->live() || pass_published == 0) break;
      loop_offset += pass_last - pass_first + std::max<int64_t>(period_us, 1);
      pass_published = 0;
      source_->seek(cfg_.start);
      status.count("loops");
      continue;
    }
    status.time_ms("read_ms", sw.ms());
    if (pass_published++ == 0) pass_first = frame.utime;
    pass_last = frame.utime;
    frame.utime += loop_offset;
    if (!first_utime) first_utime = frame.utime;
    if (cfg_.duration_s > 0 && frame.utime - *first_utime >= static_cast<int64_t>(cfg_.duration_s * 1e6)) break;
    if (st.published > 0) period_us = frame.utime - last_utime;
    last_utime = frame.utime;

    const int64_t due = pacer.due(frame.utime, util::wall_utime());
    sleep_until(due);
    if (bus::stop_requested()) break;
    const int64_t now = util::wall_utime();
    if (pacer.rate() > 0 && st.published > 0 && now - due > period_us) {
      ++st.late;
      status.count("frames_late");
    }
    sw.reset();
    const int64_t utime = cfg_.stamp == "wall" ? util::wall_utime() : frame.utime;
    const auto msgs = builder_.build(frame, utime, st.published);
    status.time_ms("encode_ms", sw.ms());
    sw.reset();
    publish(msgs);
    status.time_ms("publish_ms", sw.ms());
    status.mark_hop(utime, now, util::wall_utime());
    ++st.published;
    status.set("frames_published", st.published);
    status.tick();
  }
  st.wall_s = (util::wall_utime() - t_start) * 1e-6;
  status.publish_now();
  return st;
}

}  // namespace aerie::capture
