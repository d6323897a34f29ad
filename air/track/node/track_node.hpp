#pragma once
// The air-side tracking node (aerie-track) as a class: subscribes to a camera channel
// (aerie.image_t, or aerie.stereo_image_t whose left image is tracked), TRACK_CMD (operator
// commands) and optionally GT_TRACK (simulator ground truth, to initialise without an
// operator); publishes TRACK for every processed frame with the source frame's utime and
// TARGET_POSE when the target's size and the camera intrinsics are known: from the box size
// (target shape "box"), or for a square pad from its corners found in the tracker's box
// (shape "square", landing/pad_pose.hpp), which also re-seeds a tracker that drifted.
//
// The LCM thread only stores the newest frame and queues commands; a worker thread decodes
// and tracks. When the worker falls behind, older frames are replaced by newer ones and
// counted as skipped: the camera is never blocked.
//
// An INIT that arrives before the first frame waits for it. While one waits, the node listens
// to every channel (pattern ".*", undecoded: only the 8-byte fingerprint is read) to learn which
// channels carry aerie.image_t or aerie.stereo_image_t; after init_wait_warn_s without a frame
// it warns once (log) and in status until a frame comes, naming them. The probe exists only
// during such a wait: LCM reassembles a channel's messages only when someone subscribes to it,
// so the node pays for the other cameras' images only while it is waiting in vain.
#include <aerie/gt_box_t.hpp>
#include <aerie/image_t.hpp>
#include <aerie/stereo_image_t.hpp>
#include <aerie/track_cmd_t.hpp>
#include <aerie/track_t.hpp>

#include <atomic>
#include <condition_variable>
#include <deque>
#include <map>
#include <memory>
#include <mutex>
#include <optional>
#include <string>
#include <thread>

#include "air/track/fiducial/fiducial.hpp"
#include "air/track/landing/pad_pose.hpp"
#include "air/track/node/default_tracker.hpp"
#include "air/track/landing/target_pose.hpp"
#include "air/track/tracker.hpp"
#include "common/bus/bus.hpp"
#include "common/bus/status.hpp"
#include "common/util/config.hpp"
#include "common/util/message_clock.hpp"
#include "common/util/time.hpp"

namespace aerie::track {

// What TARGET_POSE is computed from: the tracker's box and a known size (target_pose.hpp), or
// the corners of a square pad of side target.width_m refined in the box (pad_pose.hpp).
enum class TargetShape { Box, Square };

struct NodeOptions {
  std::string camera_channel = "CAM_LEFT";
  bool stereo = false;  // the camera channel carries stereo_image_t (CAM_STEREO); track its left image
  std::string command_channel = "TRACK_CMD";
  std::string track_channel = "TRACK";
  std::string pose_channel = "TARGET_POSE";
  std::string gt_channel = "GT_TRACK";
  std::string tracker = kDefaultTracker;  // used by INIT commands that name none
  uint64_t seed = 1;
  util::Config trackers;  // per-tracker parameter sections (track.yaml "trackers:")
  int max_points = 200;   // sample positions per level published for display
  int init_from_gt = -1;  // >= 0: after this many frames, initialise on the GT_TRACK box
  // Replaying a log: every frame is tracked, in order (the LCM thread waits for the worker,
  // the camera queue holds 1000 frames) instead of the newest one.
  bool every_frame = false;
  std::string target_name = "target";
  TargetGeometry target;  // width/height 0: no TARGET_POSE
  TargetShape target_shape = TargetShape::Box;
  double pad_border = PadGeometry{}.border;  // square: white border of the pad, fraction of its side
  double search_margin = 0.5;  // square: the pad is searched in the box grown by this x its size per side
  double reseed_iou = 0.5;     // square: re-initialise the tracker on the pad when their IoU is below (0 = never)
  bool fit_h_when_cut = false; // square: a pad cut by the image border gets the pose of its H alone (observe_marking)
  std::optional<camera::CameraModel> camera;  // intrinsics (stereo messages bring their own)
  // target.pose_source apriltag | aruco: TRACK and TARGET_POSE come from the fiducial board of the
  // "fiducial" section, detected in every whole frame (the online tracker is not run);
  // tracker (default): from the tracker, as target.shape says.
  std::optional<FiducialBoard> fiducial;
  FiducialOptions fiducial_options;
  // message_time.*: the camera's time (docs/architecture.md "Message time"): a frame whose utime
  // jumps is held (never tracked, so a bogus time never reaches TRACK / TARGET_POSE), a restart or
  // outage re-synchronises, no frame for stale_timeout_s is reported as "<camera> stale".
  util::MessageClockConfig message_time;
  // TRACK_CMD bounds (docs/track.md, TRACK_CMD "Bounds"): at most this many commands and encoded bytes
  // wait for the worker (node.max_queued_commands [1, 1000], node.max_queued_bytes
  // [65536, 67108864]); beyond, the oldest are dropped (commands_dropped.queue_full).
  int max_queued_commands = 32;
  int64_t max_queued_bytes = int64_t{1} << 20;
  // An INIT waiting this long with no frame on camera_channel is warned about (class comment).
  double init_wait_warn_s = 3.0;
};

// Limits of one TRACK_CMD, checked when it arrives (before it is queued): a command beyond
// them is refused (commands_refused.<reason>) and never held. An INIT's box is in pixels of
// an image (at most image::kMaxPixels, 4096 x 4096): no coordinate needs more than 65536.
inline constexpr int kMaxCommandParams = 64;          // nparams
inline constexpr size_t kMaxCommandName = 64;         // tracker and each parameter name, characters
inline constexpr size_t kMaxCommandValue = 1024;      // each parameter value (YAML text), characters
inline constexpr size_t kMaxCommandCamera = 256;      // camera channel name, characters
inline constexpr int64_t kMaxCommandBytes = 65536;    // the whole encoded command
inline constexpr double kMaxBoxCoordinate = 65536;    // |x|, |y|, width, height of an INIT box, pixels

// Why a TRACK_CMD is refused on arrival ("" = acceptable): the counter's reason (too_large,
// bad_box) in `reason` and a message naming the field and its limit.
std::string refuse_command(const aerie::track_cmd_t& cmd, std::string* reason);

// Reads the "node", "target", "camera" and "trackers" sections of track.yaml; throws naming
// the file and key on a bad value.
NodeOptions node_options(const util::Config& cfg);

class TrackNode {
 public:
  // `now` is the node's clock for staleness (wall clock live; tests pass theirs).
  TrackNode(bus::Bus& bus, NodeOptions options, util::NodeClock now = util::wall_utime);
  ~TrackNode();
  TrackNode(const TrackNode&) = delete;
  TrackNode& operator=(const TrackNode&) = delete;

  // Copies the worker's counters, health and last hop into the status reporter (call from
  // the thread that owns the reporter); a stale camera is reported here (WARN "<camera> stale").
  void report(bus::StatusReporter& status);
  // Blocks until every frame and command received so far is processed (tests); false on timeout.
  bool wait_idle(int timeout_ms);
  int64_t counter(const std::string& name) const;

 private:
  struct Frame {
    aerie::image_t image;
    int64_t receive_utime = 0;
    std::optional<camera::CameraModel> camera;  // from a stereo message
  };
  void on_frame(Frame frame);
  void on_command(const aerie::track_cmd_t& cmd);
  void on_gt(const aerie::gt_box_t& gt);
  void run();
  void execute(const aerie::track_cmd_t& cmd);
  void process(const Frame& frame);
  void process_fiducial(const Frame& frame);  // pose_source apriltag | aruco
  std::optional<PadObservation> refine(const TrackState& s);
  void start_tracker(const std::string& name, const util::Config& params, const cv::Rect2d& box);
  void publish(const Frame& frame, const TrackState* state, double ms, const PadObservation* pad = nullptr);
  // TRACK of a frame: its header (utime, seq, tracker, camera, timing), and publishing it (which
  // closes the frame: the last hop is recorded).
  aerie::track_t track_message(const Frame& frame, const std::string& tracker, double ms);
  void close_frame(const Frame& frame, const aerie::track_t& m);
  // TARGET_POSE of the frame of `m` (its utime and confidence) with the given source.
  void publish_pose(const aerie::track_t& m, const TargetPose& p, int8_t source);
  // Largest frame decoded: the configured camera's size (camera.width x camera.height), else image::kMaxPixels.
  int64_t max_pixels() const;
  void count(const std::string& name, int64_t n = 1);
  void fail(const std::string& message);
  // The INIT-without-frames watch (class comment); called by report() with mutex_ held.
  void watch_waiting_init(int64_t now);
  std::string waiting_init_message(int64_t now) const;

  bus::Bus& bus_;
  NodeOptions opt_;

  // Shared between the LCM thread and the worker.
  mutable std::mutex mutex_;
  std::condition_variable wake_, idle_, taken_;  // taken_: the worker took the pending frame
  std::optional<Frame> pending_;
  std::deque<aerie::track_cmd_t> commands_;  // bounded: max_queued_commands, max_queued_bytes
  int64_t command_bytes_ = 0;                // encoded bytes in commands_
  std::map<std::string, int64_t> counters_;
  std::string error_;
  bool error_fresh_ = false;
  bool busy_ = false, stop_ = false;
  int64_t hop_source_ = 0, hop_receive_ = 0, hop_publish_ = 0;
  std::deque<aerie::gt_box_t> gt_;  // recent ground-truth boxes (init_from_gt)
  util::NodeClock now_;
  util::MessageClock camera_clock_;  // the message-time policy of the camera channel
  std::string stale_message_;
  // An INIT waits for the first frame (set by the worker); since when (report()'s clock), the
  // probe of image channels, what it heard (channel -> message type), the warning given.
  bool init_waiting_ = false;
  int64_t waiting_init_seq_ = 0;
  int64_t init_waiting_since_ = 0;
  bus::Subscription* image_probe_ = nullptr;
  std::map<std::string, std::string> image_channels_;
  std::string init_wait_message_;

  // Worker state.
  // The INIT waiting for the first frame: only the newest (a later INIT or a STOP supersedes it).
  std::optional<aerie::track_cmd_t> deferred_;
  std::unique_ptr<Tracker> tracker_;
  std::unique_ptr<FiducialDetector> fiducial_;
  bool fiducial_seen_ = false;  // since the start: an unseen board is LOST after, IDLE before
  std::string tracker_name_;
  util::Config tracker_params_;
  cv::Mat last_frame_;
  std::optional<camera::CameraModel> last_camera_;
  cv::Rect2d last_box_;
  cv::Rect2d last_pad_box_;  // of the last refined pad (empty: none since the last INIT)
  std::optional<double> last_pad_yaw_;  // its yaw: the box alone has no pad orientation
  int64_t frames_seen_ = 0, seq_ = 0, pose_seq_ = 0;
  bool gt_init_done_ = false;
  std::thread worker_;
};

}  // namespace aerie::track
