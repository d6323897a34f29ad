#include "air/track/node/track_node.hpp"

#include <aerie/target_pose_t.hpp>
#include <spdlog/spdlog.h>

#include <charconv>
#include <chrono>
#include <cmath>
#include <sstream>

#include "air/track/factory.hpp"
#include "common/camera/calibration_io.hpp"
#include "common/image/image_message.hpp"
#include "common/util/time.hpp"

namespace aerie::track {

NodeOptions node_options(const util::Config& cfg) {
  cfg.check_keys({"node.camera_channel", "node.stereo", "node.command_channel", "node.track_channel",
                  "node.pose_channel", "node.gt_channel", "node.tracker", "node.seed", "node.max_points",
                  "node.init_from_gt", "target.name", "target.width_m", "target.height_m", "target.yaw_offset_deg",
                  "target.shape", "target.border", "target.search_margin", "target.reseed_iou", "target.fit_h_when_cut",
                  "camera.calibration", "camera.fx", "camera.fy", "camera.cx", "camera.cy", "camera.width", "camera.height", "trackers.*",
                  "message_time.*", "node.max_queued_commands", "node.max_queued_bytes", "target.pose_source", "fiducial.*"});
  NodeOptions o;
  const util::Config node = cfg.section("node");
  o.camera_channel = node.get("camera_channel", o.camera_channel);
  o.stereo = node.get("stereo", o.stereo);
  o.command_channel = node.get("command_channel", o.command_channel);
  o.track_channel = node.get("track_channel", o.track_channel);
  o.pose_channel = node.get("pose_channel", o.pose_channel);
  o.gt_channel = node.get("gt_channel", o.gt_channel);
  o.tracker = node.get("tracker", o.tracker);
  o.seed = node.get<uint64_t>("seed", o.seed);
  o.max_points = node.get_in("max_points", o.max_points, 0, 100000);
  o.init_from_gt = node.get_in("init_from_gt", o.init_from_gt, -1, 1000000);
  o.max_queued_commands = node.get_in("max_queued_commands", o.max_queued_commands, 1, 1000);
  o.max_queued_bytes = node.get_in<int64_t>("max_queued_bytes", o.max_queued_bytes, 65536, int64_t{64} << 20);
  o.message_time = util::MessageClockConfig::from_config(cfg.section("message_time"), o.message_time);
  if (!is_known_tracker(o.tracker))
    throw std::runtime_error(cfg.origin() + ": node.tracker: unknown tracker '" + o.tracker + "'");

  const util::Config target = cfg.section("target");
  o.target_name = target.get("name", o.target_name);
  o.target.width_m = target.get_in("width_m", 0.0, 0.0, 1000.0);
  o.target.height_m = target.get_in("height_m", o.target.width_m, 0.0, 1000.0);
  o.target.yaw_offset = target.get_in("yaw_offset_deg", 0.0, -360.0, 360.0) * M_PI / 180;
  const std::string shape = target.get<std::string>("shape", "box");
  if (shape != "box" && shape != "square")
    throw std::runtime_error(cfg.origin() + ": target.shape must be box or square, got '" + shape + "'");
  o.target_shape = shape == "square" ? TargetShape::Square : TargetShape::Box;
  o.pad_border = target.get("border", o.pad_border);
  o.search_margin = target.get_in("search_margin", o.search_margin, 0.0, 10.0);
  o.reseed_iou = target.get_in("reseed_iou", o.reseed_iou, 0.0, 1.0);
  o.fit_h_when_cut = target.get("fit_h_when_cut", o.fit_h_when_cut);
  if (!(o.pad_border >= 0 && o.pad_border < 0.25)) throw std::runtime_error(cfg.origin() + ": target.border must be in [0, 0.25)");
  // The pose source (docs/track.md, "Fiducials"): the tracker (target.shape), or a fiducial board.
  const std::string source = target.get<std::string>("pose_source", "tracker");
  if (source == "apriltag" || source == "aruco") {
    o.fiducial = fiducial_board(cfg.section("fiducial"), fiducial_kind_from_string(source));
    o.fiducial_options = fiducial_options(cfg.section("fiducial"));
  } else if (source != "tracker") {
    throw std::runtime_error(cfg.origin() + ": target.pose_source must be tracker, apriltag or aruco, got '" + source + "'");
  }

  const util::Config cam = cfg.section("camera");
  if (cam.has("calibration")) {
    o.camera = camera::read_stereo_calibration(cam.require<std::string>("calibration")).left;
  } else if (cam.get("fx", 0.0) > 0) {
    camera::CameraModel m;
    m.fx = cam.get_in("fx", 0.0, 0.0, 1e5);
    m.fy = cam.get_in("fy", m.fx, 0.0, 1e5);
    m.cx = cam.require<double>("cx");
    m.cy = cam.require<double>("cy");
    m.width = cam.get_in("width", 0, 0, 16384);
    m.height = cam.get_in("height", 0, 0, 16384);
    o.camera = m;
  }
  o.trackers = cfg.section("trackers");
  // Every tracker's parameters are checked now, not at the first INIT in flight.
  if (o.trackers.node() && !o.trackers.node().IsNull()) {
    if (!o.trackers.node().IsMap()) throw std::runtime_error(o.trackers.origin() + ": expected a section per tracker");
    for (const auto& kv : o.trackers.node()) {
      const std::string name = kv.first.Scalar();
      if (!is_known_tracker(name))
        throw std::runtime_error(cfg.origin() + ": trackers." + name + ": unknown tracker (line " +
                                 std::to_string(kv.first.Mark().line + 1) + ")");
      try {
        make_tracker(name, o.trackers.section(name), o.seed);
      } catch (const std::invalid_argument& e) {
        throw std::runtime_error(e.what());
      }
    }
  }
  return o;
}

std::string refuse_command(const aerie::track_cmd_t& c, std::string* reason) {
  auto refuse = [&](const char* why, const std::string& message) {
    if (reason) *reason = why;
    return message;
  };
  const auto chars = [](size_t n, size_t limit) {
    return " of " + std::to_string(n) + " characters (at most " + std::to_string(limit) + ")";
  };
  if (c.nparams < 0 || c.nparams > kMaxCommandParams || c.param_names.size() > size_t{kMaxCommandParams} ||
      c.param_values.size() > size_t{kMaxCommandParams})
    return refuse("too_large", "nparams = " + std::to_string(c.nparams) + " (at most " +
                                   std::to_string(kMaxCommandParams) + " parameter overrides)");
  if (c.tracker.size() > kMaxCommandName) return refuse("too_large", "tracker name" + chars(c.tracker.size(), kMaxCommandName));
  if (c.camera.size() > kMaxCommandCamera) return refuse("too_large", "camera" + chars(c.camera.size(), kMaxCommandCamera));
  for (size_t i = 0; i < c.param_names.size(); ++i)
    if (c.param_names[i].size() > kMaxCommandName)
      return refuse("too_large", "param_names[" + std::to_string(i) + "]" + chars(c.param_names[i].size(), kMaxCommandName));
  for (size_t i = 0; i < c.param_values.size(); ++i)
    if (c.param_values[i].size() > kMaxCommandValue)
      return refuse("too_large", "param_values[" + std::to_string(i) + "]" +
                                     (i < c.param_names.size() ? " ('" + c.param_names[i] + "')" : std::string()) +
                                     chars(c.param_values[i].size(), kMaxCommandValue));
  // The fields are bounded above, so the encoded size cannot overflow.
  if (const int64_t bytes = c.getEncodedSize(); bytes > kMaxCommandBytes)
    return refuse("too_large", std::to_string(bytes) + " bytes encoded (at most " + std::to_string(kMaxCommandBytes) + ")");
  if (c.command == aerie::track_cmd_t::INIT) {
    const std::pair<const char*, double> box[] = {{"x", c.x}, {"y", c.y}, {"width", c.width}, {"height", c.height}};
    for (const auto& [name, v] : box)
      if (!std::isfinite(v) || std::abs(v) > kMaxBoxCoordinate) {
        std::ostringstream m;
        m << "INIT box " << name << " = " << v << " is not a number of pixels in [-" << kMaxBoxCoordinate << ", "
          << kMaxBoxCoordinate << "]";
        return refuse("bad_box", m.str());
      }
  }
  return {};
}

namespace {
// Intrinsics an image brings in its metadata ("fx", "fy", "cx", "cy", decimal ASCII): nullopt
// when it brings none; throws std::invalid_argument naming the key when one is missing or bad.
std::optional<camera::CameraModel> metadata_camera(const aerie::image_t& m) {
  const char* keys[] = {"fx", "fy", "cx", "cy"};
  double v[4];
  int found = 0;
  for (int i = 0; i < 4; ++i) {
    const std::optional<std::string> text = image::metadata(m, keys[i]);
    if (!text) continue;
    ++found;
    const char* end = text->data() + text->size();
    const auto [ptr, ec] = std::from_chars(text->data(), end, v[i]);
    if (ec != std::errc() || ptr != end || !std::isfinite(v[i]))
      throw std::invalid_argument(std::string("metadata ") + keys[i] + ": not a number: '" + *text + "'");
  }
  if (found == 0) return std::nullopt;
  if (found < 4) throw std::invalid_argument("metadata intrinsics need all of fx, fy, cx, cy");
  camera::CameraModel c;
  c.width = m.width, c.height = m.height;
  c.fx = v[0], c.fy = v[1], c.cx = v[2], c.cy = v[3];
  c.validate("metadata intrinsics");
  return c;
}

double iou(const cv::Rect2d& a, const cv::Rect2d& b) {
  const double u = (a | b).area();
  return u > 0 ? (a & b).area() / u : 0;
}
}  // namespace

TrackNode::TrackNode(bus::Bus& bus, NodeOptions options, util::NodeClock now)
    : bus_(bus), opt_(std::move(options)), now_(std::move(now)), camera_clock_(opt_.camera_channel, opt_.message_time) {
  if (!is_known_tracker(opt_.tracker)) throw std::invalid_argument("unknown tracker '" + opt_.tracker + "'");
  if (opt_.target_shape == TargetShape::Square) {
    if (!(opt_.target.width_m > 0)) throw std::invalid_argument("target.shape square needs target.width_m > 0 (the pad's side)");
    if (!(opt_.pad_border >= 0 && opt_.pad_border < 0.25)) throw std::invalid_argument("target.border must be in [0, 0.25)");
    if (!(opt_.search_margin >= 0)) throw std::invalid_argument("target.search_margin must be >= 0");
    if (!(opt_.reseed_iou >= 0 && opt_.reseed_iou <= 1)) throw std::invalid_argument("target.reseed_iou must be in [0, 1]");
  }
  if (opt_.fiducial) fiducial_ = std::make_unique<FiducialDetector>(*opt_.fiducial, opt_.fiducial_options);
  tracker_params_ = opt_.trackers.section(opt_.tracker);
  const int camera_queue = opt_.every_frame ? 1000 : 30;
  if (opt_.stereo) {
    bus_.subscribe<aerie::stereo_image_t>(opt_.camera_channel, [this](const aerie::stereo_image_t& m,
                                                                      const bus::ReceiveInfo& info) {
      camera::CameraModel c;
      c.width = m.left.width;
      c.height = m.left.height;
      c.fx = m.fx, c.fy = m.fy, c.cx = m.cx, c.cy = m.cy;
      on_frame({m.left, info.recv_utime, c});
    }, camera_queue);
  } else {
    bus_.subscribe<aerie::image_t>(opt_.camera_channel, [this](const aerie::image_t& m, const bus::ReceiveInfo& info) {
      std::optional<camera::CameraModel> cam;
      try {
        cam = metadata_camera(m);
      } catch (const std::exception& e) {  // keep the configured camera
        count("camera_metadata_errors");
        fail(opt_.camera_channel + ": " + e.what() + " (configured camera kept)");
      }
      on_frame({m, info.recv_utime, cam});
    }, camera_queue);
  }
  bus_.subscribe<aerie::track_cmd_t>(opt_.command_channel,
                                     [this](const aerie::track_cmd_t& m, const bus::ReceiveInfo&) { on_command(m); });
  if (opt_.init_from_gt >= 0)
    bus_.subscribe<aerie::gt_box_t>(opt_.gt_channel, [this](const aerie::gt_box_t& m, const bus::ReceiveInfo&) { on_gt(m); });
  worker_ = std::thread([this] { run(); });
}

TrackNode::~TrackNode() {
  {
    std::lock_guard lk(mutex_);
    stop_ = true;
    if (image_probe_) bus_.unsubscribe(*image_probe_);
    image_probe_ = nullptr;
  }
  wake_.notify_all();
  taken_.notify_all();
  worker_.join();
}

void TrackNode::on_frame(Frame frame) {
  std::unique_lock lk(mutex_);
  if (opt_.every_frame) taken_.wait(lk, [&] { return !pending_ || stop_; });
  ++counters_["frames_received"];
  // The message-time policy, reported under the names bus::InputClock uses.
  const auto time = camera_clock_.observe(frame.image.utime, now_());
  if (!time.accepted()) {
    ++counters_[opt_.camera_channel + ".time_jumps"];
    error_ = time.reason;
    error_fresh_ = true;
    if (camera_clock_.held() <= 10 || camera_clock_.held() % 100 == 0) spdlog::warn("{}", time.reason);
    return;
  }
  if (time.verdict == util::MessageClock::Verdict::kResynced) {
    ++counters_[opt_.camera_channel + ".time_resyncs"];
    spdlog::info("{}", time.reason);
  }
  if (pending_) ++counters_["frames_skipped"];  // latest-frame semantics: the older one is dropped
  pending_ = std::move(frame);
  wake_.notify_one();
}

void TrackNode::on_command(const aerie::track_cmd_t& cmd) {
  count("commands");
  std::string reason;
  if (const std::string why = refuse_command(cmd, &reason); !why.empty()) {
    count("commands_refused." + reason);
    fail(opt_.command_channel + " seq " + std::to_string(cmd.seq) + ": " + why + ": refused");
    return;
  }
  // Bounded: the newest commands win; the oldest beyond max_queued_commands / _bytes are dropped.
  const int64_t bytes = cmd.getEncodedSize();
  int64_t dropped = 0;
  {
    std::lock_guard lk(mutex_);
    while (!commands_.empty() && (commands_.size() >= static_cast<size_t>(opt_.max_queued_commands) ||
                                  command_bytes_ + bytes > opt_.max_queued_bytes)) {
      command_bytes_ -= commands_.front().getEncodedSize();
      commands_.pop_front();
      ++dropped;
    }
    commands_.push_back(cmd);
    command_bytes_ += bytes;
    if (dropped > 0) counters_["commands_dropped.queue_full"] += dropped;
  }
  wake_.notify_one();
  if (dropped > 0)
    fail(opt_.command_channel + ": " + std::to_string(dropped) + " older command(s) dropped: more than " +
         std::to_string(opt_.max_queued_commands) + " commands or " + std::to_string(opt_.max_queued_bytes) +
         " bytes waiting for the tracker");
}

void TrackNode::on_gt(const aerie::gt_box_t& gt) {
  std::lock_guard lk(mutex_);
  gt_.push_back(gt);
  if (gt_.size() > 64) gt_.pop_front();
}

void TrackNode::count(const std::string& name, int64_t n) {
  std::lock_guard lk(mutex_);
  counters_[name] += n;
}

void TrackNode::fail(const std::string& message) {
  spdlog::warn("{}", message);
  std::lock_guard lk(mutex_);
  error_ = message;
  error_fresh_ = true;
}

int64_t TrackNode::counter(const std::string& name) const {
  std::lock_guard lk(mutex_);
  const auto it = counters_.find(name);
  return it == counters_.end() ? 0 : it->second;
}

void TrackNode::report(bus::StatusReporter& status) {
  std::lock_guard lk(mutex_);
  const int64_t now = now_();
  if (const auto change = camera_clock_.stale_change(now)) {
    stale_message_ = *change;
    if (!change->empty()) {
      ++counters_[opt_.camera_channel + ".outages"];
      spdlog::warn("{}", *change);
    }
  }
  watch_waiting_init(now);
  const bool stale = camera_clock_.stale(now);
  counters_[opt_.camera_channel + ".stale"] = stale ? 1 : 0;
  for (const auto& [name, value] : counters_) status.set(name, value);
  if (error_fresh_) {
    status.warn(error_);
    error_fresh_ = false;
  } else if (!error_.empty() && counters_["frames_processed"] == 0) {
    status.warn(error_);
  } else {
    status.ok(tracker_name_.empty() ? "idle" : "tracking with " + tracker_name_);
  }
  if (stale) status.warn(stale_message_);
  if (!init_wait_message_.empty()) status.warn(init_wait_message_ = waiting_init_message(now));
  if (hop_source_ != 0) status.mark_hop(hop_source_, hop_receive_, hop_publish_);
}

void TrackNode::watch_waiting_init(int64_t now) {
  if (!init_waiting_) {
    if (image_probe_) bus_.unsubscribe(*image_probe_);
    image_probe_ = nullptr;
    image_channels_.clear();
    init_waiting_since_ = 0;
    init_wait_message_.clear();
    return;
  }
  if (init_waiting_since_ == 0) init_waiting_since_ = now;
  if (!image_probe_) {
    // Undecoded and bounded: the fingerprint names the type; a full queue drops the newest.
    image_probe_ = &bus_.subscribe_raw(".*", [this](const uint8_t* data, size_t size, const bus::ReceiveInfo& info) {
      if (size < 8) return;
      int64_t hash = 0;
      for (int i = 0; i < 8; ++i) hash = static_cast<int64_t>(static_cast<uint64_t>(hash) << 8 | data[i]);
      const char* type = hash == aerie::image_t::getHash()          ? "image_t"
                         : hash == aerie::stereo_image_t::getHash() ? "stereo_image_t"
                                                                    : nullptr;
      std::lock_guard lk(mutex_);
      if (type && image_channels_.size() < 64) image_channels_.emplace(info.channel, type);
    }, 4);
  }
  if (init_wait_message_.empty() && now - init_waiting_since_ >= static_cast<int64_t>(opt_.init_wait_warn_s * 1e6)) {
    init_wait_message_ = waiting_init_message(now);
    ++counters_["init_waits_without_frames"];
    spdlog::warn("{}", init_wait_message_);
  }
}

std::string TrackNode::waiting_init_message(int64_t now) const {
  std::ostringstream m;
  m << "INIT seq " << waiting_init_seq_ << " waits: no frame on " << opt_.camera_channel << " ("
    << (opt_.stereo ? "stereo_image_t" : "image_t") << ") for " << std::fixed;
  m.precision(1);
  m << (now - init_waiting_since_) / 1e6 << " s; ";
  if (const auto it = counters_.find("frames_received"); it != counters_.end() && it->second > 0)
    m << it->second << " received there but none usable (decode_errors, time_jumps); ";
  if (image_channels_.empty()) {
    m << "no channel carries images (is the camera running?)";
  } else {
    m << "images are on";
    const char* sep = " ";
    for (const auto& [channel, type] : image_channels_) {
      m << sep << channel << " (" << type << ")";
      sep = ", ";
    }
    m << ": start aerie-track with --camera CHANNEL (and --stereo for stereo_image_t)";
  }
  return m.str();
}

bool TrackNode::wait_idle(int timeout_ms) {
  std::unique_lock lk(mutex_);
  return idle_.wait_for(lk, std::chrono::milliseconds(timeout_ms),
                        [&] { return !busy_ && !pending_ && commands_.empty(); });
}

void TrackNode::run() {
  while (true) {
    std::deque<aerie::track_cmd_t> cmds;
    std::optional<Frame> frame;
    {
      std::unique_lock lk(mutex_);
      wake_.wait(lk, [&] { return stop_ || pending_ || !commands_.empty(); });
      if (stop_) return;
      cmds.swap(commands_);
      command_bytes_ = 0;
      frame.swap(pending_);
      busy_ = true;
    }
    taken_.notify_all();
    bool initialised_now = false;
    if (frame) {
      try {
        cv::Mat img = image::from_message(frame->image, max_pixels());
        if (tracker_ && img.size() != last_frame_.size()) {  // the tracker's model is of the old size
          count("frame_size_changes");
          fail(opt_.camera_channel + ": frame size changed from " + std::to_string(last_frame_.cols) + "x" +
               std::to_string(last_frame_.rows) + " to " + std::to_string(img.cols) + "x" + std::to_string(img.rows) +
               "; track of " + tracker_name_ + " ended (send INIT again)");
          tracker_.reset();
          tracker_name_.clear();
        }
        last_frame_ = std::move(img);
        last_camera_ = frame->camera ? frame->camera : opt_.camera;
        ++frames_seen_;
      } catch (const std::exception& e) {
        count("decode_errors");
        fail(opt_.camera_channel + ": " + e.what());
        frame.reset();
      }
    }
    if (!last_frame_.empty() && deferred_) {  // the INIT that came before the first frame
      cmds.push_front(*deferred_);
      deferred_.reset();
    }
    for (const auto& cmd : cmds) {
      try {
        // Before the first frame one INIT is held: a later INIT or a STOP supersedes it.
        if (last_frame_.empty() && deferred_ &&
            (cmd.command == aerie::track_cmd_t::INIT || cmd.command == aerie::track_cmd_t::STOP)) {
          count("commands_dropped.superseded");
          spdlog::info("{}: INIT seq {} held for the first frame is superseded by {} seq {}", opt_.command_channel,
                       deferred_->seq, cmd.command == aerie::track_cmd_t::INIT ? "INIT" : "STOP", cmd.seq);
          deferred_.reset();
        }
        if (cmd.command == aerie::track_cmd_t::INIT && last_frame_.empty()) {
          deferred_ = cmd;
          continue;
        }
        execute(cmd);
        initialised_now |= cmd.command != aerie::track_cmd_t::STOP && tracker_ != nullptr;
      } catch (const std::exception& e) {
        count("command_errors");
        fail(opt_.command_channel + ": " + e.what());
      }
    }
    {
      std::lock_guard lk(mutex_);
      init_waiting_ = deferred_.has_value();
      if (deferred_) waiting_init_seq_ = deferred_->seq;
    }
    if (frame && opt_.init_from_gt >= 0 && !gt_init_done_ && !tracker_ && frames_seen_ > opt_.init_from_gt) {
      std::optional<aerie::gt_box_t> gt;
      {
        std::lock_guard lk(mutex_);
        // The box of this very frame (same utime), never an older one: which box initialises
        // the tracker must not depend on how the channels' messages interleaved (replays).
        for (const auto& g : gt_)
          if (g.visible && g.utime == frame->image.utime) gt = g;
      }
      if (gt) {
        try {
          // A box "visible" up to half a pixel outside the image is cut to it (trackers refuse it otherwise).
          const cv::Rect2d box = cv::Rect2d(gt->x, gt->y, gt->width, gt->height) &
                                 cv::Rect2d(0, 0, last_frame_.cols, last_frame_.rows);
          start_tracker(opt_.tracker, opt_.trackers.section(opt_.tracker), box);
          gt_init_done_ = initialised_now = true;
          spdlog::info("initialised {} on the {} box from {}", opt_.tracker, gt->target, opt_.gt_channel);
        } catch (const std::exception& e) {
          count("command_errors");  // tried again on the next frame's box
          fail(opt_.gt_channel + ": " + e.what());
        }
      }
    }
    if (frame) {
      if (initialised_now && tracker_) {
        TrackState s;  // the frame the tracker was initialised on: the box itself
        s.initial_size = last_box_.size();
        s.pose = {last_box_.x + last_box_.width / 2, last_box_.y + last_box_.height / 2, 1, 0};
        s.confidence = 1;
        publish(*frame, &s, 0);
      } else {
        process(*frame);
      }
    }
    {
      std::lock_guard lk(mutex_);
      busy_ = false;
    }
    idle_.notify_all();
  }
}

int64_t TrackNode::max_pixels() const {
  if (opt_.camera && opt_.camera->width > 0 && opt_.camera->height > 0)
    return static_cast<int64_t>(opt_.camera->width) * opt_.camera->height;
  return image::kMaxPixels;
}

void TrackNode::start_tracker(const std::string& name, const util::Config& params, const cv::Rect2d& box) {
  if (last_frame_.empty()) throw std::invalid_argument("no camera frame yet on " + opt_.camera_channel);
  auto t = make_tracker(name, params, opt_.seed);
  t->init(last_frame_, box);
  tracker_ = std::move(t);
  tracker_name_ = name;
  tracker_params_ = params;
  last_box_ = box;
  last_pad_box_ = {};
  last_pad_yaw_.reset();
}

namespace {
// The tracker's YAML section with the command's name = value overrides (values parsed as YAML).
util::Config with_overrides(const util::Config& trackers, const std::string& name, const aerie::track_cmd_t& cmd) {
  YAML::Node n = trackers.section(name).node().IsMap() ? YAML::Clone(trackers.section(name).node()) : YAML::Node(YAML::NodeType::Map);
  if (cmd.nparams != static_cast<int>(cmd.param_names.size()) || cmd.param_names.size() != cmd.param_values.size())
    throw std::invalid_argument("nparams does not match the parameter arrays");
  for (size_t i = 0; i < cmd.param_names.size(); ++i) n[cmd.param_names[i]] = YAML::Load(cmd.param_values[i]);
  YAML::Emitter out;
  out << n;
  return util::Config::parse(out.c_str(), "TRACK_CMD parameters of " + name);
}
}  // namespace

void TrackNode::execute(const aerie::track_cmd_t& cmd) {
  if (!cmd.camera.empty() && cmd.camera != opt_.camera_channel)
    throw std::invalid_argument("command for camera " + cmd.camera + ", this tracker follows " + opt_.camera_channel);
  const std::string name = !cmd.tracker.empty() ? cmd.tracker : !tracker_name_.empty() ? tracker_name_ : opt_.tracker;
  switch (cmd.command) {
    case aerie::track_cmd_t::INIT:
      start_tracker(name, with_overrides(opt_.trackers, name, cmd), {cmd.x, cmd.y, cmd.width, cmd.height});
      spdlog::info("INIT {} on ({:.0f}, {:.0f}, {:.0f}, {:.0f})", name, cmd.x, cmd.y, cmd.width, cmd.height);
      break;
    case aerie::track_cmd_t::STOP:
      tracker_.reset();
      tracker_name_.clear();
      spdlog::info("STOP");
      break;
    case aerie::track_cmd_t::RESET:
      if (!tracker_) throw std::invalid_argument("RESET while not tracking");
      start_tracker(tracker_name_, tracker_params_, last_box_);  // forget the learned model, keep the box
      spdlog::info("RESET {} at ({:.0f}, {:.0f})", tracker_name_, last_box_.x, last_box_.y);
      break;
    case aerie::track_cmd_t::SET_TRACKER: {
      if (cmd.tracker.empty()) throw std::invalid_argument("SET_TRACKER without a tracker name");
      const util::Config params = with_overrides(opt_.trackers, cmd.tracker, cmd);
      make_tracker(cmd.tracker, params, opt_.seed);  // validates name and parameters
      if (tracker_) {
        start_tracker(cmd.tracker, params, last_box_);
      } else {
        opt_.tracker = cmd.tracker;
        opt_.trackers = [&] {  // the overrides become the defaults of the next INIT
          YAML::Node all = opt_.trackers.node().IsMap() ? YAML::Clone(opt_.trackers.node()) : YAML::Node(YAML::NodeType::Map);
          all[cmd.tracker] = YAML::Clone(params.node());
          YAML::Emitter out;
          out << all;
          return util::Config::parse(out.c_str(), opt_.trackers.origin());
        }();
      }
      spdlog::info("SET_TRACKER {}", cmd.tracker);
      break;
    }
    default:
      throw std::invalid_argument("unknown command " + std::to_string(cmd.command));
  }
}

void TrackNode::process(const Frame& frame) {
  if (fiducial_) return process_fiducial(frame);
  if (!tracker_) {
    publish(frame, nullptr, 0);
    return;
  }
  const util::Stopwatch sw;
  try {
    const TrackState s = tracker_->update(last_frame_);
    const double ms = sw.ms();
    if (!s.lost) last_box_ = s.box();
    count("frames_processed");
    if (s.lost) count("lost_frames");
    if (s.redetected) count("redetections");
    std::optional<PadObservation> pad;
    if (opt_.target_shape == TargetShape::Square && !s.lost && last_camera_) pad = refine(s);
    publish(frame, &s, ms, pad ? &*pad : nullptr);
  } catch (const std::exception& e) {
    count("track_errors");
    fail(tracker_name_ + ": " + e.what() + " (tracking stopped)");
    tracker_.reset();
    tracker_name_.clear();
    publish(frame, nullptr, sw.ms());
  }
}

// The fiducial board in the whole frame: TRACK from the box of its tags (TRACKING when seen;
// LOST once seen, IDLE before), TARGET_POSE from its pose (source APRILTAG / ARUCO).
void TrackNode::process_fiducial(const Frame& frame) {
  const util::Stopwatch sw;
  std::optional<FiducialPose> pose;
  FiducialMiss miss = FiducialMiss::None;
  try {
    if (!last_camera_) throw std::invalid_argument("no camera intrinsics (camera section or image metadata)");
    pose = fiducial_->estimate(last_frame_, *last_camera_, &miss);
  } catch (const std::exception& e) {
    count("fiducial_errors");
    fail(opt_.pose_channel + ": " + e.what());
  }
  const double ms = sw.ms();
  count("frames_processed");
  aerie::track_t m = track_message(frame, to_string(opt_.fiducial->kind), ms);
  m.status = pose ? aerie::track_t::TRACKING : fiducial_seen_ ? aerie::track_t::LOST : aerie::track_t::IDLE;
  if (pose) {
    fiducial_seen_ = true;
    count("fiducial_found");
    const cv::Rect2d& b = pose->box;
    m.x = b.x + b.width / 2, m.y = b.y + b.height / 2, m.scale = 1;
    m.width = b.width, m.height = b.height;
    const cv::Point2d c[4] = {b.tl(), {b.x + b.width, b.y}, b.br(), {b.x, b.y + b.height}};
    for (int i = 0; i < 4; ++i) m.corners[i][0] = c[i].x, m.corners[i][1] = c[i].y;
    m.confidence = static_cast<float>(pose->quality);
    publish_pose(m, {pose->position, pose->yaw},  // goes first: TRACK closes the frame
                 opt_.fiducial->kind == FiducialKind::AprilTag ? aerie::target_pose_t::SOURCE_APRILTAG
                                                               : aerie::target_pose_t::SOURCE_ARUCO);
  } else if (miss != FiducialMiss::None) {
    count("fiducial_miss_" + to_string(miss));
  }
  close_frame(frame, m);
}

// The pad's corners in the tracker's box grown by the margin (and at least as large as the
// last pad seen: the tracker's scale may lag the descent); re-seeds a tracker that disagrees.
std::optional<PadObservation> TrackNode::refine(const TrackState& s) {
  const cv::Rect2d box = s.box();
  const double w = std::max(box.width, last_pad_box_.width) * (1 + 2 * opt_.search_margin);
  const double h = std::max(box.height, last_pad_box_.height) * (1 + 2 * opt_.search_margin);
  // Around the tracker first; then around the pad's last place (the tracker may have drifted
  // off it); then the whole image.
  std::vector<cv::Rect2d> windows{{s.pose.x - w / 2, s.pose.y - h / 2, w, h}};
  if (last_pad_box_.area() > 0) {
    const cv::Point2d c = (last_pad_box_.tl() + last_pad_box_.br()) * 0.5;
    windows.emplace_back(c.x - w / 2, c.y - h / 2, w, h);
  }
  windows.emplace_back(0, 0, last_frame_.cols, last_frame_.rows);
  PadMiss miss = PadMiss::None;
  std::optional<PadObservation> pad;
  const PadGeometry geometry{opt_.target.width_m, opt_.pad_border};
  try {
    for (size_t i = 0; i < windows.size() && !pad; ++i) {
      pad = observe_pad(last_frame_, windows[i], *last_camera_, geometry, {}, &miss);
      if (pad && i > 0) count("pad_found_outside_track");
    }
    // Too close to be seen whole (low in the descent): the pose of its H, in the whole image.
    if (!pad && opt_.fit_h_when_cut && miss != PadMiss::EmptyWindow) {
      pad = observe_marking(last_frame_, windows.back(), *last_camera_, geometry, {}, &miss);
      if (pad) count("pad_marking_only");
    }
  } catch (const std::exception& e) {  // e.g. a configured camera of another size than the frames
    count("pad_errors");
    fail(opt_.pose_channel + ": " + e.what());
    return std::nullopt;
  }
  if (!pad) {
    count("pad_not_found");
    count("pad_miss_" + to_string(miss));
    return pad;
  }
  count("pad_refined");
  last_pad_yaw_ = pad->yaw;
  if (pad->marking_only) return pad;  // its box reaches out of the image: no box to seed a tracker with
  if (opt_.reseed_iou > 0 && iou(pad->box, box) < opt_.reseed_iou) {
    start_tracker(tracker_name_, tracker_params_, pad->box);  // same tracker and parameters, new box
    count("tracker_reseeded");
  }
  last_pad_box_ = pad->box;
  return pad;
}

aerie::track_t TrackNode::track_message(const Frame& frame, const std::string& tracker, double ms) {
  aerie::track_t m{};
  m.utime = frame.image.utime;
  m.seq = seq_++;
  m.tracker = tracker;
  m.camera = opt_.camera_channel;
  m.processing_ms = static_cast<float>(ms);
  m.frames_skipped = counter("frames_skipped");
  return m;
}

void TrackNode::publish_pose(const aerie::track_t& m, const TargetPose& p, int8_t source) {
  aerie::target_pose_t tp{};
  tp.utime = m.utime;
  tp.seq = pose_seq_++;
  tp.target = opt_.target_name;
  for (int i = 0; i < 3; ++i) tp.position[i] = p.position[i];
  tp.yaw = p.yaw;
  tp.confidence = m.confidence;
  tp.source = source;
  bus_.publish(opt_.pose_channel, tp);
  count("poses_published");
}

void TrackNode::close_frame(const Frame& frame, const aerie::track_t& m) {
  bus_.publish(opt_.track_channel, m);
  count("tracks_published");

  std::lock_guard lk(mutex_);
  hop_source_ = m.utime;
  hop_receive_ = frame.receive_utime;
  hop_publish_ = util::wall_utime();
}

void TrackNode::publish(const Frame& frame, const TrackState* s, double ms, const PadObservation* pad) {
  aerie::track_t m = track_message(frame, tracker_name_, ms);
  if (!s) {
    m.status = aerie::track_t::IDLE;
  } else {
    m.status = s->lost ? aerie::track_t::LOST : s->redetected ? aerie::track_t::REDETECTED : aerie::track_t::TRACKING;
    m.x = s->pose.x;
    m.y = s->pose.y;
    m.scale = s->pose.scale;
    m.theta = s->pose.theta;
    m.width = s->size().width;
    m.height = s->size().height;
    const auto c = s->corners();
    for (int i = 0; i < 4; ++i) {
      m.corners[i][0] = c[i].x;
      m.corners[i][1] = c[i].y;
    }
    m.confidence = static_cast<float>(s->confidence);
    for (const auto& l : s->levels) {
      aerie::track_level_t tl{};
      tl.level = l.level;
      tl.evaluated = l.evaluated;
      tl.rejected = l.rejected;
      tl.search_radius = l.search_radius;
      const size_t n = l.samples.size();
      const size_t keep = std::min<size_t>(n, static_cast<size_t>(opt_.max_points));
      for (size_t k = 0; k < keep; ++k) {  // evenly spread subset
        const size_t i = k * n / keep;
        tl.u.push_back(l.samples[i].x);
        tl.v.push_back(l.samples[i].y);
        tl.score.push_back(i < l.scores.size() ? l.scores[i] : 0.0f);
      }
      tl.npoints = static_cast<int32_t>(tl.u.size());
      m.levels.push_back(tl);
    }
    m.nlevels = static_cast<int32_t>(m.levels.size());
  }
  // TARGET_POSE goes first: TRACK closes the frame (aerie-pilot ticks on it, with this frame's pose).
  if (s && !s->lost && opt_.target.width_m > 0 && last_camera_) {
    try {
      // The refined pad when found (yaw modulo pi, absolute), else the box-based estimate.
      TargetPose p = pad ? TargetPose{pad->position, pad->yaw} : target_pose(*s, *last_camera_, opt_.target);
      // A box tells nothing of a square pad's orientation: keep the last refined one.
      if (!pad && opt_.target_shape == TargetShape::Square && last_pad_yaw_) p.yaw = *last_pad_yaw_;
      publish_pose(m, p, pad ? aerie::target_pose_t::SOURCE_FIT : aerie::target_pose_t::SOURCE_BOX);
    } catch (const std::exception& e) {
      count("pose_errors");
      fail(opt_.pose_channel + ": " + e.what());
    }
  }
  close_frame(frame, m);
}

}  // namespace aerie::track
