#include "ground/map/occupancy.hpp"

#include <octomap/AbstractOcTree.h>

#include <unistd.h>

#include <algorithm>
#include <bit>
#include <cerrno>
#include <cmath>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <iostream>
#include <iterator>
#include <sstream>
#include <stdexcept>

#include "ground/map/key_ray.hpp"

namespace aerie::map {

namespace {

void require(bool ok, const std::string& what) {
  if (!ok) throw std::invalid_argument("map: " + what);
}

float logit(double p) { return static_cast<float>(std::log(p / (1.0 - p))); }
double probability(float log_odds) { return 1.0 / (1.0 + std::exp(-static_cast<double>(log_odds))); }

std::string extension_of(const std::string& path) { return std::filesystem::path(path).extension().string(); }

// Open-addressing hash set of packed OcTreeKeys (linear probing; cleared per frame in
// time proportional to what was inserted). The fallback of VoxelMarks for far voxels.
class KeySet {
 public:
  static constexpr uint64_t kEmpty = ~uint64_t{0};

  // True when key was not in the set (and is now).
  bool insert(uint64_t key) {
    if ((used_.size() + 1) * 2 > keys_.size()) grow();
    size_t i = slot_of(key);
    while (keys_[i] != kEmpty) {
      if (keys_[i] == key) return false;
      i = (i + 1) & mask_;
    }
    keys_[i] = key;
    used_.push_back(i);
    return true;
  }
  void clear() {
    for (size_t i : used_) keys_[i] = kEmpty;
    used_.clear();
  }

 private:
  size_t slot_of(uint64_t key) const { return static_cast<size_t>((key * 0x9E3779B97F4A7C15ull) >> 20) & mask_; }
  void grow() {
    std::vector<uint64_t> old(std::max<size_t>(1 << 12, keys_.size() * 2), kEmpty);
    old.swap(keys_);
    mask_ = keys_.size() - 1;
    used_.clear();
    for (uint64_t k : old)
      if (k != kEmpty) insert(k);
  }

  std::vector<uint64_t> keys_;
  std::vector<size_t> used_;
  size_t mask_ = 0;
};

// The per-frame marks of voxels: a dense bit grid around the sensor in 4x4x4 bricks (one
// 64-bit word per brick, so consecutive voxels of a ray mostly share a word), cleared
// word by word after the frame; voxels outside it go to a hash set.
class VoxelMarks {
 public:
  // Grid of about +-half_extent voxels around `centre` (none when it would exceed max_words).
  void reset(const octomap::OcTreeKey& centre, int half_extent, size_t max_words) {
    clear();
    const long bricks = (2L * half_extent + 4) / 4 + 1;
    const size_t words = static_cast<size_t>(bricks * bricks * bricks);
    if (words > max_words) {
      bricks_ = 0;
      return;
    }
    bricks_ = bricks;
    for (int i = 0; i < 3; ++i) origin_[i] = static_cast<long>(centre[i]) - bricks * 2;
    if (words_.size() != words) words_.assign(words, 0);
  }
  // True when the voxel was not marked yet (and is now).
  bool mark(const octomap::OcTreeKey& k) {
    const long x = k[0] - origin_[0], y = k[1] - origin_[1], z = k[2] - origin_[2];
    const long n = bricks_ * 4;
    if (x < 0 || y < 0 || z < 0 || x >= n || y >= n || z >= n) return overflow_.insert(pack_key(k));
    const size_t w = static_cast<size_t>(((z >> 2) * bricks_ + (y >> 2)) * bricks_ + (x >> 2));
    const uint64_t bit = uint64_t{1} << ((x & 3) | ((y & 3) << 2) | ((z & 3) << 4));
    uint64_t& word = words_[w];
    if (word & bit) return false;
    if (word == 0) dirty_.push_back(w);
    word |= bit;
    return true;
  }
  void clear() {
    for (size_t w : dirty_) words_[w] = 0;
    dirty_.clear();
    overflow_.clear();
  }

 private:
  long bricks_ = 0;
  long origin_[3] = {0, 0, 0};
  std::vector<uint64_t> words_;
  std::vector<size_t> dirty_;
  KeySet overflow_;
};

// Per frame: the 4x4x4 bricks (OcTree nodes two levels above the leaves) that the map
// holds as one pruned leaf clamped at the minimum. A miss there cannot change the map (it
// is clamped), so the free-space pass skips them: the map ends the same, faster, since
// after a few frames most free space near the sensor is such bricks. Each brick is
// looked up in the tree once per frame.
class SaturatedFreeBricks {
 public:
  void reset(const MapTree& tree, float log_min, const octomap::OcTreeKey& centre, int half_extent, size_t max_bricks) {
    for (size_t i : looked_up_) state_[i] = kUnknown;
    looked_up_.clear();
    tree_ = &tree;
    log_min_ = log_min;
    n_ = 2 * ((half_extent + 3) / 4) + 3;  // bricks per axis, covering +-half_extent voxels
    if (static_cast<size_t>(n_ * n_ * n_) > max_bricks) {
      n_ = 0;  // too large: never skip
      return;
    }
    for (int i = 0; i < 3; ++i) lo_[i] = (static_cast<long>(centre[i]) >> 2) - n_ / 2;
    if (state_.size() != static_cast<size_t>(n_ * n_ * n_)) state_.assign(static_cast<size_t>(n_ * n_ * n_), kUnknown);
  }
  bool contains(const octomap::OcTreeKey& k) {
    const long x = (k[0] >> 2) - lo_[0], y = (k[1] >> 2) - lo_[1], z = (k[2] >> 2) - lo_[2];
    if (x < 0 || y < 0 || z < 0 || x >= n_ || y >= n_ || z >= n_) return false;
    const size_t i = static_cast<size_t>((z * n_ + y) * n_ + x);
    if (state_[i] == kUnknown) {
      const octomap::OcTreeNode* node = tree_->search(k, tree_->getTreeDepth() - 2);
      state_[i] = node && !tree_->nodeHasChildren(node) && node->getLogOdds() <= log_min_ ? kSaturated : kOther;
      looked_up_.push_back(i);
    }
    return state_[i] == kSaturated;
  }

 private:
  static constexpr uint8_t kUnknown = 0, kSaturated = 1, kOther = 2;
  const MapTree* tree_ = nullptr;
  float log_min_ = 0;
  long n_ = 0;
  long lo_[3] = {0, 0, 0};
  std::vector<uint8_t> state_;
  std::vector<size_t> looked_up_;
};

// OctoMap's coordToKeyChecked casts resolution_factor * coordinate to int before its range
// check: undefined for a coordinate far outside the tree (the map fuzzer's MAP_QUERY at
// x = 4.4e159). The tree spans [-resolution 2^15, resolution 2^15) per axis: checked first.
bool to_key(const MapTree& tree, const Eigen::Vector3d& p, octomap::OcTreeKey& key) {
  const double half = tree.getResolution() * kKeyCentre;
  return p.allFinite() && (p.array().abs() < half).all() && tree.coordToKeyChecked(p.x(), p.y(), p.z(), key);
}

}  // namespace

// Per-frame scratch, kept between frames to avoid reallocation.
struct OccupancyMap::FrameBuffer {
  struct Ray {
    uint64_t end;
    bool hit;
    Eigen::Vector3d point;  // the measured point (or the max-range point), not the voxel centre
  };
  std::vector<Ray> candidates;  // one per usable point
  VoxelMarks ends;              // end voxels that already have a ray
  std::vector<Ray> rays;        // hits first
  VoxelMarks voxels;            // voxels that already have an update
  SaturatedFreeBricks saturated_free;
  std::vector<VoxelUpdate> updates;
  std::vector<MortonUpdate> sort_scratch;

  void reset(const octomap::OcTreeKey& origin, int half_extent) {
    constexpr size_t kMaxWords = size_t{1} << 22;  // 32 MiB per grid at most
    candidates.clear();
    rays.clear();
    updates.clear();
    ends.reset(origin, half_extent, kMaxWords);
    voxels.reset(origin, half_extent, kMaxWords);
  }
};

void OccupancyParams::validate() const {
  require(resolution >= kMinResolution && resolution <= kMaxResolution,
          "resolution must be in [" + std::to_string(kMinResolution) + ", " + std::to_string(kMaxResolution) +
              "] m, got " + std::to_string(resolution));
  require(sensor_model.max_range > 0 && sensor_model.max_range <= kMaxRange,
          "sensor_model/max_range must be in (0, " + std::to_string(kMaxRange) + "] m");
  require(sensor_model.hit > 0.5 && sensor_model.hit < 1, "sensor_model/hit must be in (0.5, 1)");
  require(sensor_model.miss > 0 && sensor_model.miss < 0.5, "sensor_model/miss must be in (0, 0.5)");
  require(sensor_model.min > 0 && sensor_model.min < 0.5 && sensor_model.max > 0.5 && sensor_model.max < 1,
          "sensor_model/min must be in (0, 0.5) and sensor_model/max in (0.5, 1)");
  require(!(pointcloud_min_z > pointcloud_max_z), "pointcloud_min_z must be <= pointcloud_max_z");
  require(stereo.disparity_sigma_px >= 0 && stereo.free_margin_sigmas >= 0,
          "stereo/disparity_sigma_px and stereo/free_margin_sigmas must be >= 0");
  require(stereo.disparity_sigma_px == 0 || (stereo.focal_px > 0 && stereo.baseline_m > 0),
          "stereo/focal_px and stereo/baseline_m must be > 0 when disparity_sigma_px > 0");
  require(visibility_if_occluded >= 0 && visibility_if_occluded <= 1, "visibility_if_occluded must be in [0, 1]");
}

OccupancyMap::OccupancyMap(const OccupancyParams& params) : params_(params), frame_(std::make_unique<FrameBuffer>()) {
  params_.validate();
  log_hit_ = logit(params_.sensor_model.hit);
  log_miss_ = logit(params_.sensor_model.miss);
  log_min_ = logit(params_.sensor_model.min);
  log_max_ = logit(params_.sensor_model.max);
  clear();
}

OccupancyMap::~OccupancyMap() = default;

void OccupancyMap::clear() {
  tree_ = std::make_unique<MapTree>(params_.resolution);
  tree_->setProbHit(params_.sensor_model.hit);
  tree_->setProbMiss(params_.sensor_model.miss);
  tree_->setClampingThresMin(params_.sensor_model.min);
  tree_->setClampingThresMax(params_.sensor_model.max);
  changed_.reset();
  ++revision_;
  ++epoch_;
}

FrameStats OccupancyMap::insert_depth(const spherical::SphericalDepth& depth, const geometry::SE3& T_world_camera) {
  std::vector<Eigen::Vector3f> points;
  points.reserve(depth.size());
  const Eigen::Matrix3f R = T_world_camera.rotation_matrix().cast<float>();
  const Eigen::Vector3f t = T_world_camera.translation().cast<float>();
  for (size_t i = 0; i < depth.size(); ++i) points.push_back(R * depth.point_camera(i) + t);
  OccupancyParams::Stereo stereo = params_.stereo;
  if (depth.focal_px > 0 && depth.baseline_m > 0) {
    stereo.focal_px = depth.focal_px;
    stereo.baseline_m = depth.baseline_m;
  }
  return insert(points, t, stereo);
}

FrameStats OccupancyMap::insert_frame(const std::vector<Eigen::Vector3f>& points, const Eigen::Vector3f& origin) {
  return insert(points, origin, params_.stereo);
}

FrameStats OccupancyMap::insert(const std::vector<Eigen::Vector3f>& points, const Eigen::Vector3f& origin_f,
                                const OccupancyParams::Stereo& stereo) {
  FrameStats stats;
  stats.points = points.size();
  auto& f = *frame_;
  const MapTree& tree = *tree_;
  const Eigen::Vector3d origin = origin_f.cast<double>();
  octomap::OcTreeKey origin_key;
  require(to_key(tree, origin, origin_key),
          "sensor origin is not finite or outside the map's key range");
  const double max_range = params_.sensor_model.max_range;
  const double res = params_.resolution;
  const int half_extent = static_cast<int>(std::ceil(max_range / res)) + 4;
  f.reset(origin_key, half_extent);
  if (params_.skip_clamped_free) f.saturated_free.reset(tree, log_min_, origin_key, half_extent, size_t{1} << 24);

  // 1. End voxels; a point within max_range makes its end voxel a hit.
  for (const auto& pf : points) {
    if (!pf.allFinite()) {
      ++stats.nonfinite;
      continue;
    }
    if (pf.z() < params_.pointcloud_min_z || pf.z() > params_.pointcloud_max_z) {
      ++stats.outside_z;
      continue;
    }
    Eigen::Vector3d p = pf.cast<double>();
    const double r = (p - origin).norm();
    const bool hit = r <= max_range;
    if (!hit) {
      p = origin + (p - origin) * (max_range / r);
      ++stats.beyond_range;
    }
    octomap::OcTreeKey key;
    if (!to_key(tree, p, key)) {
      ++stats.out_of_bounds;
      continue;
    }
    f.candidates.push_back({pack_key(key), hit, p});
  }
  // One ray per end voxel, hits first: a voxel that ends both a hit and a truncated ray is a hit.
  for (const bool hits : {true, false})
    for (const auto& c : f.candidates)
      if (c.hit == hits && f.ends.mark(unpack_key(c.end))) f.rays.push_back(c);
  stats.rays = f.rays.size();

  // 2. Hits before free space, so that occupied wins over free within the frame; the
  // weight is the probability that the stereo depth lies inside the voxel (Gaussian
  // range error).
  for (const auto& ray : f.rays) {
    if (!ray.hit) break;
    const octomap::OcTreeKey key = unpack_key(ray.end);
    const double r = (Eigen::Vector3d(tree.keyToCoord(key[0]), tree.keyToCoord(key[1]), tree.keyToCoord(key[2])) -
                      origin).norm();
    const double sigma = stereo.range_sigma(r);
    const float weight = sigma > 0 && stereo.weight_hits
                             ? static_cast<float>(std::erf(res / (2.0 * std::sqrt(2.0) * sigma)))
                             : 1.f;
    f.voxels.mark(key);
    f.updates.push_back({ray.end, std::max(weight, 1e-3f)});
  }
  stats.hit_voxels = f.updates.size();

  // 3. Free space along each ray, in key space, up to the margin before a hit; a voxel is
  // free only if the ray leaves it before that point. Rays go to the measured point, not
  // to the voxel centre (which, at grazing incidence, would cut into the surface). Voxels
  // already in the frame keep their first update: each voxel is updated once per frame.
  // Voxels in bricks clamped free are skipped: a miss cannot change them.
  for (const auto& ray : f.rays) {
    const octomap::OcTreeKey end_key = unpack_key(ray.end);
    const Eigen::Vector3d& end = ray.point;
    const double length = (end - origin).norm();
    if (length <= 0) continue;
    const double free_length =
        ray.hit ? length - stereo.free_margin_sigmas * stereo.range_sigma(length) : length;
    if (free_length <= 0) continue;
    const Eigen::Vector3d direction = (end - origin) / length;
    traverse_keys(origin, direction, free_length, res, 0, [&](const octomap::OcTreeKey& k, double, double t_exit) {
      if (t_exit > free_length) return false;
      if ((!params_.skip_clamped_free || !f.saturated_free.contains(k)) && f.voxels.mark(k))
        f.updates.push_back({pack_key(k), 0.f});
      return k != end_key;
    });
  }
  stats.free_voxels = f.updates.size() - stats.hit_voxels;

  // 4. Apply in one batched descent: log-odds update with clamping; a miss on a voxel
  // believed occupied is weighted by its visibility (S&Z eq. 4-6).
  const float log_hit = log_hit_, log_miss = log_miss_, log_min = log_min_, log_max = log_max_;
  const double hit_p = params_.sensor_model.hit, miss_p = params_.sensor_model.miss;
  const double vis_occluded = params_.visibility_if_occluded;
  const float occupied_threshold = tree.getOccupancyThresLog();
  auto leaf_update = [&](const octomap::OcTreeKey& key, float log_odds, const VoxelUpdate& u) -> float {
    float next;
    if (u.occupancy > 0.f) {
      next = u.occupancy >= 1.f ? log_odds + log_hit : log_odds + logit(0.5 + u.occupancy * (hit_p - 0.5));
    } else if (log_odds > occupied_threshold && vis_occluded < 1.0) {
      // Occlusion = least occupied of the (up to three) face neighbours towards the sensor.
      double occlusion = key == origin_key ? 0.0 : 1.0;
      for (int i = 0; i < 3; ++i) {
        if (key[i] == origin_key[i]) continue;
        octomap::OcTreeKey n = key;
        n[i] = static_cast<octomap::key_type>(key[i] > origin_key[i] ? key[i] - 1 : key[i] + 1);
        const auto* node = tree.search(n);
        const double p_n = node == nullptr ? 0.5 : (node->getLogOdds() <= log_min ? 0.0 : node->getOccupancy());
        occlusion = std::min(occlusion, p_n);
      }
      const double visibility = vis_occluded * occlusion + (1.0 - occlusion);
      // P(occ | miss) = (m_o v P + m_nv (1 - v) P) / (m_o v P + m_f v (1 - P) + m_nv (1 - v)), with the
      // miss likelihoods m_o = miss, m_f = 1 - miss (the inverse model's odds) and m_nv = 1/2.
      const double p = probability(log_odds);
      const double num = miss_p * visibility * p + 0.5 * (1.0 - visibility) * p;
      const double den = num + (1.0 - miss_p) * visibility * (1.0 - p) + 0.5 * (1.0 - visibility) * (1.0 - p);
      next = logit(std::clamp(num / den, 1e-6, 1.0 - 1e-6));
    } else {
      next = log_odds + log_miss;
    }
    return std::clamp(next, log_min, log_max);
  };
  auto saturated = [&](float log_odds, const VoxelUpdate& u) {
    return u.occupancy > 0.f ? log_odds >= log_max : log_odds <= log_min;
  };
  sort_tree_order(f.updates, f.sort_scratch);
  const auto batch = tree_->apply_batch(f.updates, leaf_update, saturated);
  stats.skipped = batch.leaves_skipped;
  stats.state_changes = batch.state_changes;
  if (batch.state_changes > 0) {
    if (!changed_) {
      changed_.emplace(batch.changed_min, batch.changed_max);
    } else {
      for (unsigned i = 0; i < 3; ++i) {
        changed_->first[i] = std::min(changed_->first[i], batch.changed_min[i]);
        changed_->second[i] = std::max(changed_->second[i], batch.changed_max[i]);
      }
    }
  }
  ++revision_;
  return stats;
}

VoxelQuery OccupancyMap::occupancy(const Eigen::Vector3d& p, unsigned depth) const {
  VoxelQuery q;
  const unsigned tree_depth = tree_->getTreeDepth();
  require(depth <= tree_depth, "query depth must be 0..16");
  const unsigned d = depth == 0 ? tree_depth : depth;
  q.voxel_size = tree_->getNodeSize(d);
  octomap::OcTreeKey key;
  if (!to_key(*tree_, p, key)) return q;
  const octomap::OcTreeKey cell = tree_->adjustKeyAtDepth(key, d);
  const auto c = tree_->keyToCoord(cell, d);
  q.center = {c.x(), c.y(), c.z()};
  if (const auto* node = tree_->search(key, d)) {
    q.probability = node->getOccupancy();
    q.state = tree_->isNodeOccupied(node) ? Occupancy::Occupied : Occupancy::Free;
  }
  return q;
}

RayQuery OccupancyMap::cast_ray(const Eigen::Vector3d& origin, const Eigen::Vector3d& direction, double max_range,
                                unsigned depth) const {
  require(origin.allFinite() && direction.allFinite() && direction.norm() > 0, "ray needs a finite origin and a non-zero direction");
  require(std::isfinite(max_range) && max_range > 0, "ray max_range must be > 0");
  const unsigned tree_depth = tree_->getTreeDepth();
  require(depth <= tree_depth, "query depth must be 0..16");
  const unsigned d = depth == 0 ? tree_depth : depth;
  RayQuery q;
  const Eigen::Vector3d dir = direction.normalized();
  traverse_keys(origin, dir, max_range, params_.resolution, tree_depth - d,
                [&](const octomap::OcTreeKey& key, double t_enter, double) {
                  const auto* node = tree_->search(key, d);
                  if (node == nullptr) {
                    q.crossed_unknown = true;
                    return true;
                  }
                  if (!tree_->isNodeOccupied(node)) return true;
                  q.hit = true;
                  q.distance = t_enter;
                  const auto c = tree_->keyToCoord(key, d);
                  q.hit_center = {c.x(), c.y(), c.z()};
                  return false;
                });
  return q;
}

namespace {
// Writes the tree next to `path` (path + ".part"); returns that file's name.
std::string write_part(const MapTree& tree, const std::string& path) {
  const std::string ext = extension_of(path);
  if (ext != ".bt" && ext != ".ot")
    throw std::runtime_error("map: cannot save '" + path + "': the extension must be .bt or .ot");
  const std::string tmp = path + ".part";
  const bool ok = ext == ".bt" ? tree.writeBinaryConst(tmp) : tree.write(tmp);
  if (!ok) {
    std::error_code ec;
    std::filesystem::remove(tmp, ec);
    throw std::runtime_error("map: cannot write '" + path + "'");
  }
  return tmp;
}
}  // namespace

void OccupancyMap::save(const std::string& path) const {
  // Write next to the target and rename, so that an interrupted save never leaves a truncated map.
  const std::string tmp = write_part(*tree_, path);
  std::error_code ec;
  std::filesystem::rename(tmp, path, ec);
  if (ec) {
    std::filesystem::remove(tmp, ec);
    throw std::runtime_error("map: cannot write '" + path + "'");
  }
}

bool OccupancyMap::save_new(const std::string& path) const {
  const std::string tmp = write_part(*tree_, path);
  const int rc = ::link(tmp.c_str(), path.c_str());  // fails with EEXIST instead of replacing
  const int err = errno;
  std::error_code ec;
  std::filesystem::remove(tmp, ec);
  if (rc == 0) return true;
  if (err == EEXIST) return false;
  throw std::runtime_error("map: cannot write '" + path + "': " + std::strerror(err));
}

namespace {
// liboctomap's readers print "Reading binary octree type ..." to std::cerr on every call (the
// Debian library is built with its debug output on); a map message a second would flood
// the nodes' logs. Errors still reach the caller as exceptions below.
class QuietCerr {
 public:
  QuietCerr() : saved_(std::cerr.rdbuf(nullptr)) {}
  ~QuietCerr() {
    std::cerr.rdbuf(saved_);
    std::cerr.clear();  // writes to the null buffer set badbit
  }
  QuietCerr(const QuietCerr&) = delete;
  QuietCerr& operator=(const QuietCerr&) = delete;

 private:
  std::streambuf* saved_;
};
}  // namespace

namespace {
// What read_octree promises of a tree (see occupancy.hpp); throws std::invalid_argument.
void check_tree(const octomap::OcTree& tree, std::istream& in, const char* what) {
  const double res = tree.getResolution();
  if (!(res >= kMinResolution && res <= kMaxResolution))
    throw std::invalid_argument(std::string(what) + " of resolution " + std::to_string(res) + " m, outside [" +
                                std::to_string(kMinResolution) + ", " + std::to_string(kMaxResolution) + "] m");
  if (in.peek() != std::char_traits<char>::eof())
    throw std::invalid_argument(std::string(what) + " followed by bytes that are not part of the tree");
  if (tree.size() > kMaxMapNodes)
    throw std::invalid_argument(std::string(what) + " of " + std::to_string(tree.size()) + " nodes, more than " +
                                std::to_string(kMaxMapNodes));
  for (auto it = tree.begin_tree(), end = tree.end_tree(); it != end; ++it) {
    const float l = it->getLogOdds();
    if (!(std::abs(l) <= kMaxLogOdds))
      throw std::invalid_argument(std::string(what) + " with a node of log-odds " + std::to_string(l) +
                                  " (not a saved occupancy map: garbage data?)");
  }
}
}  // namespace

namespace {
// Where OctoMap's reader will start reading the body: its header read as it reads it (the first
// line, then AbstractOcTree::readHeader's whitespace-separated tokens up to the token "data" and
// the end of its line), so that the body checked below is the one OctoMap reads. A header read
// any other way (line by line, "data" alone on a line) checked a later body than OctoMap's
// reader then read: a "data 49" line made an 8 kB .bt grow a tree without end (issue 19,
// fuzz/regressions/octomap/bt_data_token_not_line_oom.bt). OctoMap's pre-2013 binary format
// (no text header) is refused. Throws std::invalid_argument.
size_t octree_body_offset(const std::string& bytes, bool binary) {
  std::istringstream s(bytes);
  std::string line;
  std::getline(s, line);
  const std::string first = binary ? "# Octomap OcTree binary file" : "# Octomap OcTree file";
  if (line.compare(0, first.size(), first) != 0)
    throw std::invalid_argument("a file whose first line is not '" + first + "'" +
                                (binary ? " (an old binary format? OctoMap's convert_octree updates it)" : ""));
  auto skip_line = [&s] {
    char c = 0;
    do c = static_cast<char>(s.get());
    while (s.good() && c != '\n');
  };
  std::string token, id;
  bool data = false;
  while (s.good() && !data) {
    s >> token;
    if (token == "data") {
      data = true;
      skip_line();
    } else if (token.compare(0, 1, "#") == 0) {
      skip_line();
    } else if (token == "id") {
      s >> id;
    } else if (token == "res") {
      double res = 0;
      s >> res;
    } else if (token == "size") {
      unsigned size = 0;
      s >> size;
    } else {
      skip_line();
    }
  }
  if (!data) throw std::invalid_argument("an OctoMap tree without a 'data' line");
  if (id == "1") id = "OcTree";  // OctoMap's deprecated id
  if (id != "OcTree") throw std::invalid_argument("a tree of id '" + id + "', not an OcTree");
  return s.good() ? static_cast<size_t>(s.tellg()) : bytes.size();
}

// OctoMap's readers recurse once per tree level without a depth limit and read on after their
// stream has failed: a crafted tree overflows the stack or, truncated, grows without end (issue
// 19, fuzz/regressions/octomap). So the body is walked here first, iteratively: at most 16
// levels (OctoMap's tree depth), every byte present, at most kMaxMapNodes nodes.
// Throws std::invalid_argument naming what is wrong.
void check_octree_body(const std::string& bytes, bool binary) {
  size_t pos = octree_body_offset(bytes, binary);
  if (pos == bytes.size()) return;  // an empty tree
  // .bt: 2 bytes per node, 2 bits per child (01 free leaf, 10 occupied leaf, 11 inner node).
  // .ot: per node a float and a byte of child flags; every child is a node of its own.
  const size_t node_bytes = binary ? 2 : sizeof(float) + 1;
  std::vector<int> pending;  // per level: children still to read
  size_t nodes = 1;
  auto read_node = [&](size_t depth) {
    if (pos + node_bytes > bytes.size())
      throw std::invalid_argument("an OctoMap tree cut short (" + std::to_string(bytes.size()) + " bytes)");
    int children = 0, inner = 0;
    if (binary) {
      for (int b = 0; b < 2; ++b) {
        const auto flags = static_cast<uint8_t>(bytes[pos + static_cast<size_t>(b)]);
        for (int i = 0; i < 4; ++i) {
          const int code = (flags >> (2 * i)) & 3;
          children += code != 0;
          inner += code == 3;
        }
      }
    } else {
      inner = children = std::popcount(static_cast<uint8_t>(bytes[pos + sizeof(float)]));
    }
    pos += node_bytes;
    if (inner > 0 && depth >= 16)
      throw std::invalid_argument("an OctoMap tree deeper than 16 levels (not a saved map: garbage data?)");
    nodes += static_cast<size_t>(children);
    if (nodes > kMaxMapNodes)
      throw std::invalid_argument("an OctoMap tree of more than " + std::to_string(kMaxMapNodes) + " nodes");
    pending.push_back(inner);
  };
  read_node(0);
  while (!pending.empty()) {
    if (pending.back() == 0) {
      pending.pop_back();
      continue;
    }
    --pending.back();
    read_node(pending.size());
  }
}
}  // namespace

std::unique_ptr<octomap::OcTree> read_octree(std::istream& stream, bool binary) {
  const QuietCerr quiet;
  const std::string bytes((std::istreambuf_iterator<char>(stream)), std::istreambuf_iterator<char>());
  check_octree_body(bytes, binary);
  std::istringstream in(bytes);
  if (binary) {
    auto tree = std::make_unique<octomap::OcTree>(0.1);  // readBinary sets the resolution it reads
    if (!tree->readBinary(in)) throw std::invalid_argument("not an OctoMap binary (.bt) tree");
    check_tree(*tree, in, "an OctoMap binary (.bt) tree");
    return tree;
  }
  std::unique_ptr<octomap::AbstractOcTree> any(octomap::AbstractOcTree::read(in));
  if (!any) throw std::invalid_argument("not an OctoMap (.ot) tree");
  auto* tree = dynamic_cast<octomap::OcTree*>(any.get());
  if (tree == nullptr) throw std::invalid_argument("a " + any->getTreeType() + ", not an OcTree");
  any.release();
  std::unique_ptr<octomap::OcTree> out(tree);
  check_tree(*out, in, "an OctoMap (.ot) tree");
  return out;
}

std::unique_ptr<octomap::OcTree> read_octree_file(const std::string& path) {
  if (!std::filesystem::is_regular_file(path)) throw std::runtime_error("map: no such file '" + path + "'");
  const std::string ext = extension_of(path);
  if (ext != ".bt" && ext != ".ot")
    throw std::runtime_error("map: cannot load '" + path + "': the extension must be .bt or .ot");
  std::ifstream in(path, std::ios::binary);
  try {
    return read_octree(in, ext == ".bt");
  } catch (const std::invalid_argument& e) {
    throw std::runtime_error("map: '" + path + "' is " + e.what());
  }
}

void OccupancyMap::load(const std::string& path) {
  const std::unique_ptr<octomap::OcTree> loaded = read_octree_file(path);
  params_.resolution = loaded->getResolution();
  clear();  // a fresh MapTree at the file's resolution, with our sensor model
  tree_->swapContent(*loaded);
  tree_->updateInnerOccupancy();
}

std::optional<Region> OccupancyMap::take_changed_region() {
  if (!changed_) return std::nullopt;
  const double half = 0.5 * params_.resolution;
  Region r;
  for (unsigned i = 0; i < 3; ++i) {
    r.min[i] = tree_->keyToCoord(changed_->first[i]) - half;
    r.max[i] = tree_->keyToCoord(changed_->second[i]) + half;
  }
  changed_.reset();
  return r;
}

}  // namespace aerie::map
