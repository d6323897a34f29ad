#include "ground/map/map_service.hpp"

#include <spdlog/spdlog.h>

#include <algorithm>
#include <cctype>
#include <cmath>
#include <sstream>

#include "common/spherical/spherical_message.hpp"
#include "common/util/heap.hpp"
#include "common/util/time.hpp"
#include "ground/map/octomap_message.hpp"

namespace aerie::map {

namespace {

std::optional<geometry::SE3> pose_of(const aerie::pose_t& m) {
  const Eigen::Vector4d q(m.orientation[0], m.orientation[1], m.orientation[2], m.orientation[3]);
  const Eigen::Vector3d t(m.position[0], m.position[1], m.position[2]);
  if (!q.allFinite() || !t.allFinite() || std::abs(q.norm() - 1.0) > 1e-3) return std::nullopt;
  return geometry::SE3::from_wxyz(m.orientation, m.position);
}

std::string seconds(int64_t us) {
  std::ostringstream s;
  s << static_cast<double>(us) * 1e-6 << " s";
  return s.str();
}

void merge(std::optional<Region>& into, const std::optional<Region>& r) {
  if (!r) return;
  if (!into) {
    into = r;
    return;
  }
  into->min = into->min.cwiseMin(r->min);
  into->max = into->max.cwiseMax(r->max);
}

}  // namespace

MapServiceConfig MapServiceConfig::from_config(const util::Config& cfg) {
  cfg.check_keys({"resolution", "sensor_model.max_range", "sensor_model.hit", "sensor_model.miss", "sensor_model.min",
                  "sensor_model.max", "pointcloud_min_z", "pointcloud_max_z", "stereo.focal_px", "stereo.baseline_m",
                  "stereo.disparity_sigma_px", "stereo.free_margin_sigmas", "stereo.weight_hits",
                  "visibility_if_occluded", "distance_map.max_distance", "distance_map.max_cells", "publish.period_s",
                  "publish.full_every", "publish.binary", "matching.pose_tolerance_us", "matching.pose_wait_us",
                  "matching.pose_buffer", "message_time.*", "channels.pose", "channels.depth",
                  "channels.octomap", "channels.query", "channels.response", "channels.cmd", "files.directory",
                  "files.max_files", "files.max_bytes"});
  MapServiceConfig c;
  auto& o = c.occupancy;
  // Ranges as documented in config/map.yaml; the probabilities are checked by validate().
  o.resolution = cfg.get_in("resolution", o.resolution, kMinResolution, kMaxResolution);
  o.sensor_model.max_range = cfg.get_in("sensor_model.max_range", o.sensor_model.max_range, 0.01, kMaxRange);
  o.sensor_model.hit = cfg.get("sensor_model.hit", o.sensor_model.hit);
  o.sensor_model.miss = cfg.get("sensor_model.miss", o.sensor_model.miss);
  o.sensor_model.min = cfg.get("sensor_model.min", o.sensor_model.min);
  o.sensor_model.max = cfg.get("sensor_model.max", o.sensor_model.max);
  o.pointcloud_min_z = cfg.get_in("pointcloud_min_z", o.pointcloud_min_z, -1e6, 1e6);
  o.pointcloud_max_z = cfg.get_in("pointcloud_max_z", o.pointcloud_max_z, -1e6, 1e6);
  o.stereo.focal_px = cfg.get_in("stereo.focal_px", o.stereo.focal_px, 0.0, 1e5);
  o.stereo.baseline_m = cfg.get_in("stereo.baseline_m", o.stereo.baseline_m, 0.0, 100.0);
  o.stereo.disparity_sigma_px = cfg.get_in("stereo.disparity_sigma_px", o.stereo.disparity_sigma_px, 0.0, 100.0);
  o.stereo.free_margin_sigmas = cfg.get_in("stereo.free_margin_sigmas", o.stereo.free_margin_sigmas, 0.0, 100.0);
  o.stereo.weight_hits = cfg.get("stereo.weight_hits", o.stereo.weight_hits);
  o.visibility_if_occluded = cfg.get_in("visibility_if_occluded", o.visibility_if_occluded, 0.0, 1.0);
  try {
    o.validate();
  } catch (const std::invalid_argument& e) {
    throw std::runtime_error(cfg.origin() + ": " + e.what());
  }
  c.distance_max = cfg.get_in("distance_map.max_distance", c.distance_max, 0.01, 100.0);
  c.distance_max_cells = static_cast<size_t>(
      cfg.get_in<int64_t>("distance_map.max_cells", static_cast<int64_t>(c.distance_max_cells), 1, int64_t{1} << 28));
  c.publish_period_s = cfg.get_in("publish.period_s", c.publish_period_s, 0.0, 3600.0);
  c.full_every = cfg.get_in("publish.full_every", c.full_every, 1, 1000000);
  c.publish_binary = cfg.get("publish.binary", c.publish_binary);
  c.pose_tolerance_us = cfg.get_in<int64_t>("matching.pose_tolerance_us", c.pose_tolerance_us, 0, 10000000);
  c.pose_wait_us = cfg.get_in<int64_t>("matching.pose_wait_us", c.pose_wait_us, 0, 60000000);
  c.message_time = util::MessageClockConfig::from_config(cfg.section("message_time"), c.message_time);
  c.pose_buffer = static_cast<size_t>(
      cfg.get_in<int64_t>("matching.pose_buffer", static_cast<int64_t>(c.pose_buffer), 1, 100000));
  c.pose_channel = cfg.get("channels.pose", c.pose_channel);
  c.depth_channel = cfg.get("channels.depth", c.depth_channel);
  c.octomap_channel = cfg.get("channels.octomap", c.octomap_channel);
  c.query_channel = cfg.get("channels.query", c.query_channel);
  c.response_channel = cfg.get("channels.response", c.response_channel);
  c.cmd_channel = cfg.get("channels.cmd", c.cmd_channel);
  c.files_directory = cfg.get("files.directory", c.files_directory);
  c.max_files = cfg.get_in("files.max_files", c.max_files, 1, 100000);
  c.max_bytes = cfg.get_in<int64_t>("files.max_bytes", c.max_bytes, int64_t{1} << 20, int64_t{1} << 40);
  return c;
}

MapService::MapService(bus::Bus& bus, bus::StatusReporter& status, const MapServiceConfig& config,
                       util::NodeClock now)
    : bus_(bus),
      status_(status),
      config_(config),
      map_(config.occupancy),
      distances_(config.distance_max, config.distance_max_cells),
      now_(std::move(now)),
      vo_clock_(status, "VO", config.message_time) {
  // Depth frames are large and the update can take tens of ms: a deep queue, and a
  // seq gap count on the subscription tells when LCM still dropped some.
  bus_.subscribe<aerie::pose_t>(config_.pose_channel, [this](const auto& m, const auto& i) { on_pose(m, i); }, 200);
  bus_.subscribe<aerie::spherical_depth_t>(config_.depth_channel,
                                           [this](const auto& m, const auto& i) { on_depth(m, i); }, 100);
  bus_.subscribe<aerie::map_query_t>(config_.query_channel, [this](const auto& m, const auto& i) { on_query(m, i); },
                                     100);
  bus_.subscribe<aerie::map_cmd_t>(config_.cmd_channel, [this](const auto& m, const auto& i) { on_cmd(m, i); });
}

void MapService::reject(const std::string& counter, const std::string& message) {
  status_.count(counter);
  status_.warn(message);
  spdlog::warn("{}", message);
}

bool MapService::accept_time(int64_t utime) {
  const auto r = vo_clock_.observe(utime, now_());
  if (!r.accepted()) return false;
  if (r.verdict == util::MessageClock::Verdict::kResynced) {
    // A new time base (VO restarted, or came back after an outage): poses and waiting depth of
    // the old one would match the wrong frames. The map itself is kept.
    poses_.clear();
    pose_arrivals_.clear();
    pending_.clear();
    newest_utime_ = utime;
    last_depth_utime_ = -1;
    last_publish_utime_ = -1;
  }
  newest_utime_ = std::max(newest_utime_, utime);
  return true;
}

std::optional<geometry::SE3> MapService::vo_pose_at(int64_t utime) const {
  auto it = poses_.lower_bound(utime - config_.pose_tolerance_us);
  if (it == poses_.end() || it->first > utime + config_.pose_tolerance_us) return std::nullopt;
  // The closest within the tolerance.
  auto best = it;
  for (; it != poses_.end() && it->first <= utime + config_.pose_tolerance_us; ++it)
    if (std::llabs(it->first - utime) < std::llabs(best->first - utime)) best = it;
  return best->second;
}

void MapService::on_pose(const aerie::pose_t& msg, const bus::ReceiveInfo& info) {
  status_.count("poses");
  if (msg.status != aerie::pose_t::OK) {
    status_.count("poses_not_ok");  // initialising, lost or reset: not used for mapping
    return;
  }
  const auto pose = pose_of(msg);
  if (!pose) {
    reject("poses_invalid", config_.pose_channel + " seq " + std::to_string(msg.seq) +
                                ": position/orientation not finite or not a unit quaternion; dropped");
    return;
  }
  if (!accept_time(msg.utime)) return;
  // Evict by arrival, not by utime: after a backward step in time (within the clock's jump
  // limit) the new poses are the earliest, and evicting the earliest dropped each at once.
  if (poses_.insert_or_assign(msg.utime, *pose).second) pose_arrivals_.push_back(msg.utime);
  while (poses_.size() > config_.pose_buffer) {
    poses_.erase(pose_arrivals_.front());
    pose_arrivals_.pop_front();
  }
  // Depth frames that were waiting for this pose.
  for (auto it = pending_.begin(); it != pending_.end();) {
    if (std::llabs(it->first - msg.utime) <= config_.pose_tolerance_us) {
      status_.count("pose_from_vo");
      const auto [utime, depth] = std::move(*it);
      it = pending_.erase(it);
      insert(depth, utime, *pose, info.recv_utime);
    } else {
      ++it;
    }
  }
  expire_pending();
}

void MapService::on_depth(const aerie::spherical_depth_t& msg, const bus::ReceiveInfo& info) {
  status_.count("depth_frames");
  std::optional<geometry::SE3> own_pose;
  spherical::SphericalDepth depth;
  try {
    depth = spherical::from_message(msg);
    own_pose = spherical::pose_of(msg);
  } catch (const std::invalid_argument& e) {
    reject("depth_malformed", config_.depth_channel + " seq " + std::to_string(msg.seq) + ": " + e.what() +
                                  "; dropped");
    return;
  }
  if (!accept_time(msg.utime)) return;
  if (msg.utime < last_depth_utime_) status_.count("depth_out_of_order");  // still mapped
  if (const auto vo = vo_pose_at(msg.utime)) {
    status_.count("pose_from_vo");
    insert(depth, msg.utime, *vo, info.recv_utime);
  } else if (own_pose) {
    status_.count("pose_from_depth");
    insert(depth, msg.utime, *own_pose, info.recv_utime);
  } else {
    status_.count("depth_waiting_for_pose");
    pending_.push_back({msg.utime, std::move(depth)});
  }
  expire_pending();
}

void MapService::expire_pending() {
  while (!pending_.empty() &&
         (pending_.front().first + config_.pose_wait_us < newest_utime_ || pending_.size() > 100)) {
    reject("depth_without_pose", config_.depth_channel + " utime " + std::to_string(pending_.front().first) +
                                     " has no pose and no " + config_.pose_channel + " within " +
                                     seconds(config_.pose_wait_us) + "; dropped");
    pending_.pop_front();
  }
}

void MapService::insert(const spherical::SphericalDepth& depth, int64_t utime, const geometry::SE3& T_world_camera,
                        int64_t receive_utime) {
  util::Stopwatch watch;
  FrameStats stats;
  try {
    stats = map_.insert_depth(depth, T_world_camera);
  } catch (const std::invalid_argument& e) {
    reject("depth_rejected", config_.depth_channel + " utime " + std::to_string(utime) + ": " + e.what());
    return;
  }
  status_.time_ms("insert", watch.ms());
  status_.count("frames_mapped");
  status_.count("points", static_cast<int64_t>(stats.points));
  status_.count("points_nonfinite", static_cast<int64_t>(stats.nonfinite));
  status_.count("points_outside_z", static_cast<int64_t>(stats.outside_z));
  status_.count("points_beyond_range", static_cast<int64_t>(stats.beyond_range));
  status_.set("map_nodes", static_cast<int64_t>(map_.tree().size()));
  status_.set("map_bytes", static_cast<int64_t>(map_.memory_bytes()));
  merge(unpublished_, map_.take_changed_region());
  last_depth_utime_ = std::max(last_depth_utime_, utime);
  status_.ok();
  maybe_publish(utime);
  status_.mark_hop(utime, receive_utime, util::wall_utime());
}

void MapService::maybe_publish(int64_t utime) {
  if (config_.publish_period_s <= 0) return;
  const auto period = static_cast<int64_t>(config_.publish_period_s * 1e6);
  if (last_publish_utime_ >= 0 && utime - last_publish_utime_ < period && utime >= last_publish_utime_) return;
  last_publish_utime_ = utime;
  const bool full = publications_ % config_.full_every == 0;
  if (!full && !unpublished_) return;  // nothing changed
  util::Stopwatch watch;
  const auto msg = encode(utime, full ? std::nullopt : unpublished_);
  status_.time_ms("encode", watch.ms());
  bus_.publish(config_.octomap_channel, msg);
  ++publications_;
  unpublished_.reset();
  status_.count(full ? "octomap_full" : "octomap_partial");
  status_.count("octomap_bytes", msg.length);
}

void MapService::publish_full(int64_t utime) {
  const auto msg = encode(utime, std::nullopt);
  bus_.publish(config_.octomap_channel, msg);
  unpublished_.reset();
  status_.count("octomap_full");
  status_.count("octomap_bytes", msg.length);
}

aerie::octomap_t MapService::encode(int64_t utime, const std::optional<Region>& region) {
  aerie::octomap_t msg{};
  msg.utime = utime;
  msg.seq = publish_seq_++;
  msg.resolution = map_.params().resolution;
  msg.binary = config_.publish_binary;
  msg.full = !region.has_value();
  MapTree* tree = &map_.tree();
  std::unique_ptr<MapTree> part;
  if (region) {
    // The leaves inside (or overlapping) the region, at their own depth.
    part = std::make_unique<MapTree>(msg.resolution);
    const octomap::point3d lo(static_cast<float>(region->min.x()), static_cast<float>(region->min.y()),
                              static_cast<float>(region->min.z()));
    const octomap::point3d hi(static_cast<float>(region->max.x()), static_cast<float>(region->max.y()),
                              static_cast<float>(region->max.z()));
    for (auto it = tree->begin_leafs_bbx(lo, hi), end = tree->end_leafs_bbx(); it != end; ++it)
      part->set_node(it.getKey(), it.getDepth(), it->getLogOdds());
    part->updateInnerOccupancy();
    tree = part.get();
    for (int i = 0; i < 3; ++i) {
      msg.bbox_min[i] = region->min[i];
      msg.bbox_max[i] = region->max[i];
    }
  } else {
    double x0 = 0, y0 = 0, z0 = 0, x1 = 0, y1 = 0, z1 = 0;
    if (tree->size() > 0) {
      tree->getMetricMin(x0, y0, z0);
      tree->getMetricMax(x1, y1, z1);
    }
    msg.bbox_min[0] = x0, msg.bbox_min[1] = y0, msg.bbox_min[2] = z0;
    msg.bbox_max[0] = x1, msg.bbox_max[1] = y1, msg.bbox_max[2] = z1;
  }
  encode_octree(*tree, msg.binary, msg);
  return msg;
}

aerie::map_response_t MapService::answer(const aerie::map_query_t& q) {
  aerie::map_response_t r{};
  r.utime = q.utime;
  r.seq = q.seq;
  r.kind = q.kind;
  r.distance = -1.0;
  r.probability = 0.5;
  const Eigen::Vector3d p(q.point[0], q.point[1], q.point[2]);
  if (!p.allFinite()) throw std::invalid_argument("point is not finite");
  if (q.depth < 0 || q.depth > 16) throw std::invalid_argument("depth must be 0..16, got " + std::to_string(q.depth));
  const auto depth = static_cast<unsigned>(q.depth);
  switch (q.kind) {
    case aerie::map_query_t::OCCUPANCY: {
      const auto v = map_.occupancy(p, depth);
      r.occupancy = static_cast<int8_t>(v.state);
      r.probability = v.probability;
      r.voxel_size = v.voxel_size;
      for (int i = 0; i < 3; ++i) r.hit[i] = v.center[i];
      break;
    }
    case aerie::map_query_t::NEAREST_OBSTACLE: {
      distances_.update(map_);
      const auto n = distances_.nearest(p);
      r.voxel_size = map_.params().resolution;
      if (n.distance >= 0 && (q.max_range <= 0 || n.distance <= q.max_range)) {
        r.distance = n.distance;
        r.occupancy = aerie::map_response_t::OCCUPIED;
        for (int i = 0; i < 3; ++i) r.hit[i] = n.obstacle[i];
      }
      break;
    }
    case aerie::map_query_t::RAY: {
      const auto ray = map_.cast_ray(p, {q.direction[0], q.direction[1], q.direction[2]}, q.max_range, depth);
      r.voxel_size = map_.occupancy(p, depth).voxel_size;
      if (ray.hit) {
        r.occupancy = aerie::map_response_t::OCCUPIED;
        r.distance = ray.distance;
        for (int i = 0; i < 3; ++i) r.hit[i] = ray.hit_center[i];
      } else {
        r.occupancy = ray.crossed_unknown ? aerie::map_response_t::UNKNOWN : aerie::map_response_t::FREE;
      }
      break;
    }
    default:
      throw std::invalid_argument("unknown query kind " + std::to_string(q.kind));
  }
  return r;
}

bool valid_reply_channel(const std::string& channel, const std::string& response_channel) {
  if (channel == response_channel) return true;
  const std::string prefix = response_channel + "_";
  if (channel.size() <= prefix.size() || channel.size() > prefix.size() + 32 || channel.rfind(prefix, 0) != 0)
    return false;
  return std::all_of(channel.begin() + static_cast<std::ptrdiff_t>(prefix.size()), channel.end(),
                     [](char ch) { return std::isalnum(static_cast<unsigned char>(ch)) || ch == '_'; });
}

void MapService::on_query(const aerie::map_query_t& q, const bus::ReceiveInfo&) {
  status_.count("queries");
  if (!q.reply_channel.empty() && !valid_reply_channel(q.reply_channel, config_.response_channel)) {
    reject("query_reply_refused", config_.query_channel + " seq " + std::to_string(q.seq) + ": reply channel '" +
                                      q.reply_channel.substr(0, 64) + "' is not " + config_.response_channel +
                                      " or " + config_.response_channel + "_<1..32 of A-Z a-z 0-9 _>; not answered");
    return;
  }
  aerie::map_response_t r;
  try {
    r = answer(q);
  } catch (const std::exception& e) {
    r = aerie::map_response_t{};
    r.utime = q.utime;
    r.seq = q.seq;
    r.kind = q.kind;
    r.distance = -1.0;
    r.error = std::string("map query seq ") + std::to_string(q.seq) + ": " + e.what();
    reject("query_errors", r.error);
  }
  bus_.publish(q.reply_channel.empty() ? config_.response_channel : q.reply_channel, r);
}

std::filesystem::path MapService::confined(const std::string& name) const {
  if (config_.files_directory.empty())
    throw FileRefused("off", "SAVE and LOAD over " + config_.cmd_channel + " are off (files.directory is not set)");
  const bool plain = !name.empty() && name.size() <= 64 && name[0] != '.' && name.find("..") == std::string::npos &&
                     std::all_of(name.begin(), name.end(), [](char ch) {
                       return std::isalnum(static_cast<unsigned char>(ch)) || ch == '_' || ch == '-' || ch == '.';
                     });
  const std::string ext = std::filesystem::path(name).extension().string();
  if (!plain || (ext != ".bt" && ext != ".ot")) {
    std::string shown;  // at most 80 characters of it, control characters as '?' (it goes to the log)
    for (const char ch : name.substr(0, 80)) shown += std::isprint(static_cast<unsigned char>(ch)) ? ch : '?';
    throw FileRefused("bad_name", "'" + shown + "' is not a plain map file name in " + config_.files_directory +
                                      " (letters, digits, '_', '-', '.', at most 64, not starting with '.', no " +
                                      "\"..\", ending .bt or .ot)");
  }
  return std::filesystem::path(config_.files_directory) / name;
}

std::string MapService::save_in_directory(const std::string& name) {
  const std::filesystem::path first = confined(name);
  if (files_saved_ >= config_.max_files)
    throw FileRefused("max_files", "SAVE refused: " + std::to_string(files_saved_) + " map files written in this run (files.max_files = " +
                                       std::to_string(config_.max_files) + ")");
  if (bytes_saved_ >= config_.max_bytes)
    throw FileRefused("max_bytes", "SAVE refused: " + std::to_string(bytes_saved_) + " bytes of maps written in this run (files.max_bytes = " +
                                       std::to_string(config_.max_bytes) + ")");
  std::filesystem::create_directories(config_.files_directory);
  const std::string stem = first.stem().string(), ext = first.extension().string();
  for (int version = 0; version <= 1000; ++version) {
    const std::filesystem::path p =
        version == 0 ? first : first.parent_path() / (stem + "-" + std::to_string(version) + ext);
    std::error_code ec;
    if (std::filesystem::exists(std::filesystem::symlink_status(p, ec))) continue;  // never overwritten
    if (!map_.save_new(p.string())) continue;  // taken meanwhile, try the next version
    const auto size = std::filesystem::file_size(p, ec);
    const int64_t bytes = ec ? 0 : static_cast<int64_t>(size);
    if (bytes_saved_ + bytes > config_.max_bytes) {  // its size is known once written: taken back
      std::filesystem::remove(p, ec);
      throw FileRefused("max_bytes", "SAVE refused: the map's " + std::to_string(bytes) + " bytes would pass files.max_bytes = " +
                                         std::to_string(config_.max_bytes) + " (" + std::to_string(bytes_saved_) +
                                         " written in this run)");
    }
    ++files_saved_;
    bytes_saved_ += bytes;
    status_.set("files_saved", files_saved_);
    status_.set("bytes_saved", bytes_saved_);
    return p.string();
  }
  throw std::runtime_error("map: 1000 versions of '" + name + "' exist in " + config_.files_directory);
}

void MapService::load_from_directory(const std::string& name) {
  const std::filesystem::path p = confined(name);
  std::error_code ec;
  if (std::filesystem::is_symlink(std::filesystem::symlink_status(p, ec)))
    throw FileRefused("symlink", "'" + p.string() + "' is a symbolic link; LOAD reads only files in " +
                                     config_.files_directory);
  load(p.string());
}

void MapService::load(const std::string& path) {
  map_.load(path);
  unpublished_.reset();
  publications_ = 0;  // the next publication is the full map
  spdlog::info("loaded map '{}' ({} nodes, resolution {} m)", path, map_.tree().size(), map_.params().resolution);
}

void MapService::on_cmd(const aerie::map_cmd_t& c, const bus::ReceiveInfo&) {
  status_.count("commands");
  try {
    switch (c.command) {
      case aerie::map_cmd_t::SAVE: {
        const std::string written = save_in_directory(c.path);
        status_.ok("saved the map to '" + written + "'");
        spdlog::info("saved map to '{}'", written);
        break;
      }
      case aerie::map_cmd_t::LOAD:
        load_from_directory(c.path);
        break;
      case aerie::map_cmd_t::CLEAR:
        map_.clear();
        unpublished_.reset();
        publications_ = 0;
        // The octree's nodes are freed; hand their pages back (util/heap.hpp), or the RSS
        // keeps the largest map so far.
        status_.count("heap_released_kb", util::trim_heap());
        // The heap with an empty map: the same state after every CLEAR, so its growth over
        // many flights is a leak, not a larger map (docs/results/soak.md).
        status_.set("heap_in_use_after_clear_kb", util::heap_figures().in_use_kb);
        spdlog::info("map cleared");
        break;
      case aerie::map_cmd_t::PUBLISH_FULL:
        publish_full(newest_utime_ >= 0 ? newest_utime_ : c.utime);
        break;
      default:
        throw std::invalid_argument("unknown command " + std::to_string(c.command));
    }
    status_.count("commands_done");
  } catch (const FileRefused& e) {  // counted with its reason, and among the command errors
    status_.count(std::string(c.command == aerie::map_cmd_t::SAVE ? "save_refused." : "load_refused.") + e.reason());
    reject("command_errors", config_.cmd_channel + " seq " + std::to_string(c.seq) + ": " + e.what());
  } catch (const std::exception& e) {
    reject("command_errors", config_.cmd_channel + " seq " + std::to_string(c.seq) + ": " + e.what());
  }
}

}  // namespace aerie::map
