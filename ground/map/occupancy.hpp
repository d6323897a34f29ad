#pragma once
// Robust volumetric occupancy mapping on OctoMap for stereo depth (thesis section 4.2.2,
// after Schauwecker & Zell 2014, "Robust and efficient volumetric occupancy mapping with
// an application to stereo vision"). Per frame:
//   1. points are filtered (finite, pointcloud_min_z <= z <= pointcloud_max_z) and
//      reduced to one ray per end voxel;
//   2. the end voxel of a point within sensor_model/max_range is a hit, weighted by the
//      probability that the stereo depth falls inside that voxel (depth error
//      sigma_r = r^2 sigma_d / (f b)): far, uncertain points move a voxel less than near ones;
//   3. free space is cast in key space (3D DDA) from the sensor to free_margin_sigmas *
//      sigma_r before the hit (never into the band where the stereo depth is uncertain), or
//      to max_range for farther points;
//   4. each voxel is updated at most once per frame, and occupied wins over free;
//   5. a miss on a voxel the map believes occupied is weighted by its visibility (S&Z
//      eq. 4-6): when the neighbours that face the sensor are occupied, the voxel is
//      probably occluded and the miss says little (keeps walls seen at grazing angles);
//   6. the log-odds are clamped to [sensor_model/min, sensor_model/max] and the updates of a
//      frame are applied in one batched tree descent.
// The reference (plain OctoMap) is OcTree::insertPointCloud; bench/map compares both.
#include <Eigen/Core>

#include <cstdint>
#include <istream>
#include <limits>
#include <memory>
#include <optional>
#include <string>
#include <vector>

#include "common/geometry/se3.hpp"
#include "common/spherical/spherical_depth.hpp"
#include "ground/map/map_tree.hpp"

namespace aerie::map {

// Sane bounds of a map (config/map.yaml, --resolution, --max-range and maps loaded from
// files): OctoMap's 16-bit keys span 65536 voxels per axis, so 1 cm still maps +-327 m.
inline constexpr double kMinResolution = 0.01;  // m
inline constexpr double kMaxResolution = 10.0;  // m
inline constexpr double kMaxRange = 1000.0;     // m, sensor_model/max_range
inline constexpr size_t kMaxMapNodes = size_t{1} << 27;  // nodes of a map read from a file or message
inline constexpr float kMaxLogOdds = 40.f;      // |log-odds| of any node (OctoMap clamps to about +-3.5)

// The parameters of thesis section 4.2.2 (OctoMap names) plus the stereo error model.
struct OccupancyParams {
  double resolution = 0.1;  // m, finest voxel
  struct SensorModel {
    double max_range = 5.0;  // m; farther points are not inserted, their rays clear free space to here
    double hit = 0.7;        // P(occupied | hit)
    double miss = 0.4;       // P(occupied | miss)
    double min = 0.12;       // clamping
    double max = 0.97;
  } sensor_model;
  double pointcloud_min_z = -std::numeric_limits<double>::infinity();  // m, world frame
  double pointcloud_max_z = std::numeric_limits<double>::infinity();
  struct Stereo {
    double focal_px = 163.0;          // of the rectified camera that produced the depth (demo rig)
    double baseline_m = 0.12;
    double disparity_sigma_px = 0.12;  // disparity noise of a VO_DEPTH bin (median of its pixels);
                                       // 0 disables the depth error model
    double free_margin_sigmas = 1.25;  // free space stops this many sigma_r before a hit
    bool weight_hits = true;          // hit weight = P(depth inside the voxel); false: full hits
    // Stereo range error (m) at range r: sigma_r = r^2 sigma_d / (f b).
    double range_sigma(double r) const {
      return disparity_sigma_px > 0 ? r * r * disparity_sigma_px / (focal_px * baseline_m) : 0.0;
    }
  } stereo;
  double visibility_if_occluded = 0.2;  // S&Z P(visible | occluded); 1 disables the visibility term
  // Skip free space inside 4x4x4 bricks already clamped free (a miss cannot change them).
  // Exact: the map is the same either way; false only to check that.
  bool skip_clamped_free = true;

  void validate() const;  // throws std::invalid_argument naming the key
};

// An OctoMap OcTree, at its own resolution, from the content of a .bt file (`binary`:
// occupied/free) or a .ot file (full probabilities). Throws std::invalid_argument saying
// what the content is instead ("not an OctoMap binary (.bt) tree", ...). The tree is
// checked before it is returned: resolution in [kMinResolution, kMaxResolution], the
// stream used up exactly (no bytes after the tree), at most kMaxMapNodes nodes, every
// log-odds finite and within +-kMaxLogOdds (a garbage body parses as random floats).
std::unique_ptr<octomap::OcTree> read_octree(std::istream& in, bool binary);
// The same from a file, .bt or .ot by extension. Throws std::runtime_error naming the path.
std::unique_ptr<octomap::OcTree> read_octree_file(const std::string& path);

enum class Occupancy : int8_t { Unknown = 0, Free = 1, Occupied = 2 };

struct FrameStats {
  size_t points = 0;         // given
  size_t nonfinite = 0;      // dropped: NaN / inf coordinates
  size_t outside_z = 0;      // dropped: outside [pointcloud_min_z, pointcloud_max_z]
  size_t out_of_bounds = 0;  // dropped: outside the octree's key range
  size_t beyond_range = 0;   // farther than max_range: free space only
  size_t rays = 0;           // unique end voxels (rays cast)
  size_t hit_voxels = 0;     // voxels updated as occupied
  size_t free_voxels = 0;    // voxels updated as free
  size_t skipped = 0;        // updates that could not change a saturated pruned node
  size_t state_changes = 0;  // voxels created or changed occupied <-> free
};

struct VoxelQuery {
  Occupancy state = Occupancy::Unknown;
  double probability = 0.5;  // occupancy probability of the node (max of its children when coarse)
  double voxel_size = 0.0;   // edge of the node answered (m)
  Eigen::Vector3d center = Eigen::Vector3d::Zero();
};

struct RayQuery {
  bool hit = false;          // an occupied voxel within max_range
  double distance = -1.0;    // to the hit voxel's centre (m)
  Eigen::Vector3d hit_center = Eigen::Vector3d::Zero();
  bool crossed_unknown = false;  // unknown voxels before the hit (or the end): treated as passable
};

// Axis-aligned region in metres.
struct Region {
  Eigen::Vector3d min = Eigen::Vector3d::Zero();
  Eigen::Vector3d max = Eigen::Vector3d::Zero();
};

class OccupancyMap {
 public:
  explicit OccupancyMap(const OccupancyParams& params = {});
  ~OccupancyMap();
  OccupancyMap(const OccupancyMap&) = delete;
  OccupancyMap& operator=(const OccupancyMap&) = delete;

  // One frame: points in the world frame and the sensor origin (the robust update above).
  FrameStats insert_frame(const std::vector<Eigen::Vector3f>& points_world, const Eigen::Vector3f& origin);
  // One frame of spherical depth (VO_DEPTH) seen from T_world_camera; the depth's own
  // focal length and baseline, when given, replace those of params.stereo.
  FrameStats insert_depth(const spherical::SphericalDepth& depth, const geometry::SE3& T_world_camera);

  // Occupancy at p on OctoMap depth `depth` (0 = finest, else 1..16: voxel edge
  // resolution * 2^(16 - depth)).
  VoxelQuery occupancy(const Eigen::Vector3d& p, unsigned depth = 0) const;
  // First occupied voxel along origin + t * direction, t in [0, max_range] (DDA on the
  // voxels of `depth`); unknown voxels are passable.
  RayQuery cast_ray(const Eigen::Vector3d& origin, const Eigen::Vector3d& direction, double max_range,
                    unsigned depth = 0) const;

  // .bt (binary: occupied/free only) or .ot (full probabilities), chosen by extension.
  // Throws std::runtime_error naming the path.
  void save(const std::string& path) const;
  // As save(), but never replaces an existing file (atomic: link(2) of the written file):
  // false when `path` exists.
  bool save_new(const std::string& path) const;
  // Replaces the map with a saved one (its resolution replaces params.resolution).
  void load(const std::string& path);
  void clear();

  // Region whose voxels changed state since the last call (nullopt: none).
  std::optional<Region> take_changed_region();

  const OccupancyParams& params() const { return params_; }
  const MapTree& tree() const { return *tree_; }
  MapTree& tree() { return *tree_; }
  size_t memory_bytes() const { return tree_->memoryUsage(); }
  // Incremented whenever the tree changes (frames, clear, load), for caches such as the distance map.
  uint64_t revision() const { return revision_; }
  // Incremented whenever the tree object is replaced (clear, load).
  uint64_t epoch() const { return epoch_; }

 private:
  struct FrameBuffer;
  FrameStats insert(const std::vector<Eigen::Vector3f>& points_world, const Eigen::Vector3f& origin,
                    const OccupancyParams::Stereo& stereo);
  OccupancyParams params_;
  std::unique_ptr<MapTree> tree_;
  std::unique_ptr<FrameBuffer> frame_;
  float log_hit_, log_miss_, log_min_, log_max_;
  std::optional<std::pair<octomap::OcTreeKey, octomap::OcTreeKey>> changed_;
  uint64_t revision_ = 0;
  uint64_t epoch_ = 0;
};

}  // namespace aerie::map
