#pragma once
// An octomap::OcTree that applies one frame's voxel updates in a single batched
// descent (keys sorted in the tree's own Morton order, so every inner node on the
// touched paths is visited once, pruned or refreshed once), instead of one root-to-leaf
// descent per voxel as OcTree::updateNode does. The tree type stays "OcTree": files it
// writes are plain OctoMap files (octovis, octomap tools).
#include <octomap/OcTree.h>

#include <cstdint>
#include <functional>
#include <utility>
#include <vector>

namespace aerie::map {

// OcTreeKey packed as x | y << 16 | z << 32.
inline uint64_t pack_key(const octomap::OcTreeKey& k) {
  return uint64_t{k[0]} | (uint64_t{k[1]} << 16) | (uint64_t{k[2]} << 32);
}
inline octomap::OcTreeKey unpack_key(uint64_t p) {
  return {static_cast<octomap::key_type>(p & 0xFFFF), static_cast<octomap::key_type>((p >> 16) & 0xFFFF),
          static_cast<octomap::key_type>((p >> 32) & 0xFFFF)};
}

// One voxel's update of a frame.
struct VoxelUpdate {
  uint64_t key = 0;     // pack_key
  float occupancy = 0;  // 0: observed free; > 0: observed occupied with this weight (<= 1)
};

// Sorts updates into the order of a depth-first traversal of the tree (child index
// x | y << 1 | z << 2 at every level, from the root): an LSD radix sort on the 48-bit
// Morton code, O(n), in `scratch` (kept by the caller between frames: no allocation).
using MortonUpdate = std::pair<uint64_t, VoxelUpdate>;
void sort_tree_order(std::vector<VoxelUpdate>& updates, std::vector<MortonUpdate>& scratch);

class MapTree : public octomap::OcTree {
 public:
  explicit MapTree(double resolution) : octomap::OcTree(resolution) {}

  // New log-odds of a leaf from its current value (nullptr-free: `existed` tells whether the
  // leaf was there before this frame; a new leaf starts at log-odds 0).
  using LeafUpdate = std::function<float(const octomap::OcTreeKey& key, float log_odds, const VoxelUpdate& u)>;

  struct BatchResult {
    size_t leaves_updated = 0;
    size_t leaves_skipped = 0;     // already saturated inside a pruned node: no change
    size_t state_changes = 0;      // leaves that were created or changed occupied <-> free
    octomap::OcTreeKey changed_min, changed_max;  // bounding keys of those (when state_changes > 0)
  };

  // Applies updates (unique keys, sorted with sort_tree_order). `saturated(log_odds, u)`
  // says that an update would not change a leaf of that value (lets pruned regions stay
  // pruned). Records changed keys for OctoMap's change detection when it is enabled
  // (DynamicEDT3D relies on it).
  BatchResult apply_batch(const std::vector<VoxelUpdate>& sorted, const LeafUpdate& update,
                          const std::function<bool(float, const VoxelUpdate&)>& saturated);

  // Sets the log-odds of the node at `key` and `depth` (creating the path), for copying
  // coarse leaves of another tree. Call updateInnerOccupancy() afterwards.
  void set_node(const octomap::OcTreeKey& key, unsigned depth, float log_odds);

 private:
  void apply_recursive(octomap::OcTreeNode* node, bool node_just_created, unsigned depth, const VoxelUpdate* first,
                       const VoxelUpdate* last, const LeafUpdate& update,
                       const std::function<bool(float, const VoxelUpdate&)>& saturated, BatchResult& result);
  void note_change(const octomap::OcTreeKey& key, bool created, bool occupied_before, bool occupied_after,
                   BatchResult& result);
};

}  // namespace aerie::map
