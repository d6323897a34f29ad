#include "ground/map/distance_map.hpp"

#include <dynamicEDT3D/dynamicEDTOctomap.h>

#include <algorithm>
#include <cmath>
#include <stdexcept>
#include <string>

namespace aerie::map {

struct DistanceMap::Impl {
  std::unique_ptr<DynamicEDTOctomap> edt;
  uint64_t epoch = 0;
  uint64_t revision = 0;
  Eigen::Vector3d min = Eigen::Vector3d::Zero(), max = Eigen::Vector3d::Zero();
};

DistanceMap::DistanceMap(double max_distance, size_t max_cells)
    : max_distance_(max_distance), max_cells_(max_cells), impl_(std::make_unique<Impl>()) {
  if (!(max_distance > 0)) throw std::invalid_argument("distance_map: max_distance must be > 0");
}

DistanceMap::~DistanceMap() = default;

void DistanceMap::update(OccupancyMap& map) {
  MapTree& tree = map.tree();
  if (tree.size() == 0) {
    impl_->edt.reset();
    return;
  }
  double x0, y0, z0, x1, y1, z1;
  tree.getMetricMin(x0, y0, z0);
  tree.getMetricMax(x1, y1, z1);
  const Eigen::Vector3d lo(x0, y0, z0), hi(x1, y1, z1);
  const bool covered = impl_->edt && impl_->epoch == map.epoch() && (lo.array() >= impl_->min.array()).all() &&
                       (hi.array() <= impl_->max.array()).all();
  if (!covered) {
    // Rebuild over the known region grown by max_distance (+1 m so that a growing map does
    // not rebuild every frame).
    const double pad = max_distance_ + 1.0;
    const Eigen::Vector3d min = lo.array() - pad, max = hi.array() + pad;
    const Eigen::Vector3d cells = ((max - min) / map.params().resolution).array().ceil();
    const double n = cells.prod();
    // DynamicEDT3D indexes a dense grid of float coordinates: it needs at least one cell per
    // axis and bounds that floats hold (a map of resolution 1e300 crashed it).
    const double extent = std::max(min.cwiseAbs().maxCoeff(), max.cwiseAbs().maxCoeff());
    if (!cells.allFinite() || !(cells.minCoeff() >= 1) || !(extent < 1e7))
      throw std::runtime_error("distance_map: the map's bounds cannot be gridded at resolution " +
                               std::to_string(map.params().resolution) + " m");
    if (n > static_cast<double>(max_cells_))
      throw std::runtime_error("distance_map: the map needs " + std::to_string(static_cast<long long>(n)) +
                               " cells, more than distance_map.max_cells (" + std::to_string(max_cells_) + ")");
    impl_->edt.reset();  // before the new one: it disables nothing, but frees the old grid first
    impl_->edt = std::make_unique<DynamicEDTOctomap>(static_cast<float>(max_distance_), &tree,
                                                     octomap::point3d(static_cast<float>(min.x()), static_cast<float>(min.y()), static_cast<float>(min.z())),
                                                     octomap::point3d(static_cast<float>(max.x()), static_cast<float>(max.y()), static_cast<float>(max.z())),
                                                     false);
    impl_->min = min;
    impl_->max = max;
    impl_->epoch = map.epoch();
    impl_->revision = 0;
    ++rebuilds_;
  }
  if (impl_->revision != map.revision()) {
    impl_->edt->update();
    impl_->revision = map.revision();
  }
}

NearestObstacle DistanceMap::nearest(const Eigen::Vector3d& p) const {
  NearestObstacle out;
  // Outside the grid (the map's bounds grown by more than max_distance) no obstacle is within
  // max_distance; there OctoMap's coordToKey would also overflow an int (docs/fuzz.md, finding 5).
  if (!impl_->edt || !p.allFinite() || (p.array() < impl_->min.array()).any() || (p.array() > impl_->max.array()).any())
    return out;
  float distance = 0.f;
  octomap::point3d obstacle;
  impl_->edt->getDistanceAndClosestObstacle(
      octomap::point3d(static_cast<float>(p.x()), static_cast<float>(p.y()), static_cast<float>(p.z())), distance,
      obstacle);
  if (distance == DynamicEDTOctomap::distanceValue_Error || distance >= impl_->edt->getMaxDist() ||
      distance > max_distance_)
    return out;
  out.distance = distance;
  out.obstacle = {obstacle.x(), obstacle.y(), obstacle.z()};
  return out;
}

}  // namespace aerie::map
