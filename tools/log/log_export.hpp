#pragma once
// `aerie-log export`: one channel of a log to files other tools read.
//   aerie.image_t        -> DIR/000000.png ... + DIR/times.txt (s, message utime)
//   aerie.stereo_image_t -> DIR/image_l/, DIR/image_r/ PNGs + times.txt + calib.txt:
//                           a KITTI-odometry-style folder (aerie-capture --source kitti reads it)
//   aerie.gt_pose_t, aerie.pose_t -> DIR/<CHANNEL>.tum: "t x y z qx qy qz qw" per line
//   aerie.gt_box_t       -> DIR/<CHANNEL>.csv: "t,visible,x,y,width,height"
//   aerie.track_t        -> DIR/<CHANNEL>.csv: "t,seq,x,y,w,h,status,confidence", one row per frame, and
//                           DIR/<CHANNEL>.txt: "x,y,w,h" per frame (OTB groundtruth_rect layout): the box's
//                           top-left corner and size in pixels, 0-based; NaN when the tracker is IDLE.
//                           One row per source frame of the camera channel (the tracks' `camera` field
//                           or `camera`), paired by utime: a frame the tracker skipped is a NaN row
//                           (status SKIPPED); one row per message when the log has no such frames.
#include <cstdint>
#include <string>
#include <vector>

#include "common/logio/event_log.hpp"

namespace aerie::logtools {

struct ExportResult {
  std::string type;             // message type of the channel
  int64_t exported = 0;         // messages written out
  int64_t undecodable = 0;      // skipped: corrupt payload
  int64_t other_type = 0;       // skipped: another type on the same channel
  std::vector<std::string> outputs;  // files/folders written (top level)
  // Tracks: the source channel, its frames in the log (0: none, one row per message) and the
  // frames with no track message (NaN rows).
  std::string camera;
  int64_t frames = 0, skipped_frames = 0;
  std::vector<std::string> notes;    // what the user should know about the output
  std::vector<logio::Damage> damage;
};

// Throws std::runtime_error naming the log/channel when the channel is absent or its
// type cannot be exported, or naming the file when an output cannot be written. out_dir
// must not exist or be empty, unless `force` (then files of the same names are overwritten).
ExportResult export_channel(const std::string& log_path, const std::string& channel, const std::string& out_dir,
                            bool resync = false, bool force = false, const std::string& camera = "");

// "1403715273.262143" for utime 1403715273262143: exact, no floating point.
std::string utime_to_seconds(int64_t utime);

}  // namespace aerie::logtools
