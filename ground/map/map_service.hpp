#pragma once
// The LCM side of aerie-map: VO_POSE + VO_DEPTH in, the occupancy map updated, MAP_OCTOMAP
// out (rate-limited in message time, full or changed region), MAP_QUERY answered,
// MAP_CMD obeyed. Bad messages are counted in the status and dropped, never fatal.
#include <aerie/map_cmd_t.hpp>
#include <aerie/map_query_t.hpp>
#include <aerie/map_response_t.hpp>
#include <aerie/octomap_t.hpp>
#include <aerie/pose_t.hpp>
#include <aerie/spherical_depth_t.hpp>

#include <cstdint>
#include <deque>
#include <filesystem>
#include <map>
#include <memory>
#include <stdexcept>
#include <string>

#include "common/bus/bus.hpp"
#include "common/bus/input_clock.hpp"
#include "common/bus/status.hpp"
#include "common/util/config.hpp"
#include "common/util/time.hpp"
#include "ground/map/distance_map.hpp"
#include "ground/map/occupancy.hpp"

namespace aerie::map {

struct MapServiceConfig {
  OccupancyParams occupancy;
  double distance_max = 2.0;                 // distance_map.max_distance (m)
  size_t distance_max_cells = size_t{64} << 20;  // distance_map.max_cells
  double publish_period_s = 1.0;             // publish.period_s, in message time; <= 0: never
  int full_every = 10;                       // publish.full_every: every Nth publication is the full map
  bool publish_binary = true;                // publish.binary: .bt stream (else .ot with probabilities)
  int64_t pose_tolerance_us = 1000;          // matching.pose_tolerance_us: |utime difference| to match
  int64_t pose_wait_us = 500000;             // matching.pose_wait_us: a depth without pose waits this long
  size_t pose_buffer = 400;                  // matching.pose_buffer: VO_POSE messages kept for matching
  // message_time.*: VO_POSE and VO_DEPTH are one source (the camera frames behind aerie-vo):
  // jumps beyond max_jump_s are held until resync_messages consistent ones re-synchronise;
  // no message for stale_timeout_s (wall clock) reports the source stale.
  util::MessageClockConfig message_time;
  std::string pose_channel = "VO_POSE";      // channels.*
  std::string depth_channel = "VO_DEPTH";
  std::string octomap_channel = "MAP_OCTOMAP";
  std::string query_channel = "MAP_QUERY";
  std::string response_channel = "MAP_RESPONSE";
  std::string cmd_channel = "MAP_CMD";
  // files.directory: the only directory MAP_CMD SAVE and LOAD touch; their path must be a
  // plain file name in it (no '/', no "..", not hidden, .bt or .ot, at most 64 characters)
  // and LOAD refuses a symlink. "" = SAVE and LOAD over LCM are refused.
  std::string files_directory;
  // files.max_files / files.max_bytes: what MAP_CMD SAVE may write in one run of the node (files,
  // and bytes of map files); a SAVE beyond is refused (save_refused.max_files / .max_bytes).
  int max_files = 100;
  int64_t max_bytes = int64_t{1} << 30;

  // Reads config/map.yaml keys (see the file); missing keys keep their defaults.
  static MapServiceConfig from_config(const util::Config& cfg);
};

// A MAP_CMD SAVE or LOAD refused by the file rules; reason() is the counter's suffix
// (save_refused.<reason>, load_refused.<reason>): off, bad_name, symlink, max_files, max_bytes.
class FileRefused : public std::invalid_argument {
 public:
  FileRefused(std::string reason, const std::string& what) : std::invalid_argument(what), reason_(std::move(reason)) {}
  const std::string& reason() const { return reason_; }

 private:
  std::string reason_;
};

// MAP_QUERY replies go to channels.response, or to channels.response + "_" + a suffix of
// 1..32 letters, digits or '_' (MAP_RESPONSE_PILOT): never to another node's channel.
bool valid_reply_channel(const std::string& channel, const std::string& response_channel);

class MapService {
 public:
  // `now` is the node's clock for staleness (wall clock live; tests pass their own).
  MapService(bus::Bus& bus, bus::StatusReporter& status, const MapServiceConfig& config,
             util::NodeClock now = util::wall_utime);

  OccupancyMap& map() { return map_; }
  const MapServiceConfig& config() const { return config_; }
  // Reports the VO source stale when nothing came for message_time.stale_timeout_s (node clock: wall).
  void tick() { vo_clock_.check(now_()); }
  // Publishes the whole map now (MAP_CMD PUBLISH_FULL does this too).
  void publish_full(int64_t utime);
  // Saves the map (.bt or .ot); throws std::runtime_error.
  void save(const std::string& path) const { map_.save(path); }
  // Replaces the map with a checked one from a file (read_octree_file); the old map stays on failure.
  void load(const std::string& path);
  // MAP_CMD SAVE: a new file in files.directory, never an existing one: `name` when it is
  // free, else `<stem>-1<ext>`, `<stem>-2<ext>`, ... Returns the path written. Throws
  // FileRefused beyond files.max_files / files.max_bytes of this run (a file that would pass
  // max_bytes is removed again).
  std::string save_in_directory(const std::string& name);
  int files_saved() const { return files_saved_; }
  int64_t bytes_saved() const { return bytes_saved_; }
  // MAP_CMD LOAD: `name` in files.directory.
  void load_from_directory(const std::string& name);

  // Encodes the map, or the part inside `region`, as an octomap_t.
  aerie::octomap_t encode(int64_t utime, const std::optional<Region>& region);

 private:
  void on_pose(const aerie::pose_t& msg, const bus::ReceiveInfo& info);
  void on_depth(const aerie::spherical_depth_t& msg, const bus::ReceiveInfo& info);
  void on_query(const aerie::map_query_t& msg, const bus::ReceiveInfo& info);
  void on_cmd(const aerie::map_cmd_t& msg, const bus::ReceiveInfo& info);

  // The message-time policy (bus::InputClock): false when the message is held as a jump; on a
  // re-synchronisation the poses and pending depth of the old time base are dropped.
  bool accept_time(int64_t utime);
  std::optional<geometry::SE3> vo_pose_at(int64_t utime) const;
  void insert(const spherical::SphericalDepth& depth, int64_t utime, const geometry::SE3& T_world_camera,
              int64_t receive_utime);
  void expire_pending();
  void maybe_publish(int64_t utime);
  aerie::map_response_t answer(const aerie::map_query_t& q);
  // files.directory / name, after checking name; throws FileRefused (off, bad_name).
  std::filesystem::path confined(const std::string& name) const;
  void reject(const std::string& counter, const std::string& message);

  bus::Bus& bus_;
  bus::StatusReporter& status_;
  MapServiceConfig config_;
  OccupancyMap map_;
  DistanceMap distances_;
  std::map<int64_t, geometry::SE3> poses_;         // VO_POSE by utime
  std::deque<int64_t> pose_arrivals_;              // their utimes as received: the buffer evicts the oldest received
  std::deque<std::pair<int64_t, spherical::SphericalDepth>> pending_;  // (utime, depth) waiting for VO_POSE
  util::NodeClock now_;
  bus::InputClock vo_clock_;                       // VO_POSE + VO_DEPTH: one time base
  int64_t newest_utime_ = -1;                      // newest accepted message time
  int64_t last_depth_utime_ = -1;
  int64_t last_publish_utime_ = -1;
  std::optional<Region> unpublished_;              // changed since the last publication
  int64_t publish_seq_ = 0;
  int publications_ = 0;
  int files_saved_ = 0;      // by MAP_CMD SAVE in this run
  int64_t bytes_saved_ = 0;
};

}  // namespace aerie::map
