#pragma once
// Distance to the nearest obstacle from any point (DynamicEDT3D on the occupancy map),
// so that the controller can ask how far the wall ahead is. The Euclidean distance
// transform covers the map's known bounding box (grown by max_distance) and is updated
// incrementally from OctoMap's change detection; it is rebuilt when the map outgrows it
// or is cleared/loaded.
#include <Eigen/Core>

#include <cstdint>
#include <memory>
#include <optional>

#include "ground/map/occupancy.hpp"

namespace aerie::map {

struct NearestObstacle {
  double distance = -1.0;  // m; < 0: no obstacle within max_distance (or p outside the map)
  Eigen::Vector3d obstacle = Eigen::Vector3d::Zero();  // centre of the nearest occupied voxel
};

class DistanceMap {
 public:
  // max_distance: distances are exact up to here (m); max_cells bounds the dense grid.
  explicit DistanceMap(double max_distance = 2.0, size_t max_cells = size_t{64} << 20);
  ~DistanceMap();
  DistanceMap(const DistanceMap&) = delete;
  DistanceMap& operator=(const DistanceMap&) = delete;

  // Brings the transform up to date with `map` (no-op when nothing changed).
  void update(OccupancyMap& map);
  // Nearest occupied voxel from p (call update first).
  NearestObstacle nearest(const Eigen::Vector3d& p) const;

  double max_distance() const { return max_distance_; }
  size_t rebuilds() const { return rebuilds_; }

 private:
  struct Impl;
  double max_distance_;
  size_t max_cells_;
  std::unique_ptr<Impl> impl_;
  size_t rebuilds_ = 0;
};

}  // namespace aerie::map
