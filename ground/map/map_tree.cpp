#include "ground/map/map_tree.hpp"

#include <array>
#include <cassert>

namespace aerie::map {

namespace {

// Spreads the 16 bits of v to every third bit (bit i -> bit 3i).
uint64_t spread3(uint64_t v) {
  v &= 0xFFFF;
  v = (v | (v << 16)) & 0x0000FF0000FFull;
  v = (v | (v << 8)) & 0x00F00F00F00Full;
  v = (v | (v << 4)) & 0x0C30C30C30C3ull;
  v = (v | (v << 2)) & 0x249249249249ull;
  return v;
}

// Morton code whose 3-bit groups, from the top, are OctoMap's child indices
// (x | y << 1 | z << 2) from the root down.
uint64_t morton(uint64_t packed) {
  return spread3(packed) | (spread3(packed >> 16) << 1) | (spread3(packed >> 32) << 2);
}

unsigned child_index(uint64_t packed, unsigned bit) {
  return static_cast<unsigned>(((packed >> bit) & 1) | (((packed >> (16 + bit)) & 1) << 1) |
                               (((packed >> (32 + bit)) & 1) << 2));
}

}  // namespace

void sort_tree_order(std::vector<VoxelUpdate>& updates, std::vector<MortonUpdate>& scratch) {
  constexpr int kBits = 12, kPasses = 4;  // 48-bit codes
  constexpr size_t kBuckets = size_t{1} << kBits;
  const size_t n = updates.size();
  if (n < 2) return;
  scratch.resize(2 * n);
  MortonUpdate* a = scratch.data();
  MortonUpdate* b = a + n;
  for (size_t i = 0; i < n; ++i) a[i] = {morton(updates[i].key), updates[i]};
  std::array<size_t, kBuckets> count{};
  for (int pass = 0; pass < kPasses; ++pass) {
    const int shift = pass * kBits;
    count.fill(0);
    for (size_t i = 0; i < n; ++i) ++count[(a[i].first >> shift) & (kBuckets - 1)];
    // A digit that all keys share (the high bits of a local frame) needs no pass.
    if (count[(a[0].first >> shift) & (kBuckets - 1)] == n) continue;
    size_t sum = 0;
    for (auto& c : count) {
      const size_t t = c;
      c = sum;
      sum += t;
    }
    for (size_t i = 0; i < n; ++i) b[count[(a[i].first >> shift) & (kBuckets - 1)]++] = a[i];
    std::swap(a, b);
  }
  for (size_t i = 0; i < n; ++i) updates[i] = a[i].second;
}

MapTree::BatchResult MapTree::apply_batch(const std::vector<VoxelUpdate>& sorted, const LeafUpdate& update,
                                          const std::function<bool(float, const VoxelUpdate&)>& saturated) {
  BatchResult result;
  if (sorted.empty()) return result;
  bool created_root = false;
  if (root == nullptr) {
    root = new octomap::OcTreeNode();
    ++tree_size;
    size_changed = true;
    created_root = true;
  }
  apply_recursive(root, created_root, 0, sorted.data(), sorted.data() + sorted.size(), update, saturated, result);
  return result;
}

void MapTree::apply_recursive(octomap::OcTreeNode* node, bool node_just_created, unsigned depth,
                              const VoxelUpdate* first, const VoxelUpdate* last, const LeafUpdate& update,
                              const std::function<bool(float, const VoxelUpdate&)>& saturated,
                              BatchResult& result) {
  if (depth == tree_depth) {
    // A leaf: normally one update (unique keys); duplicates are applied in turn.
    for (const VoxelUpdate* u = first; u != last; ++u) {
      const octomap::OcTreeKey key = unpack_key(u->key);
      const bool created = node_just_created && u == first;
      const float before = created ? 0.f : node->getLogOdds();
      const float after = update(key, before, *u);
      node->setLogOdds(after);
      ++result.leaves_updated;
      note_change(key, created, !created && before >= occ_prob_thres_log, after >= occ_prob_thres_log, result);
    }
    return;
  }
  // A pruned leaf above the finest level whose value no update can change stays pruned.
  if (!node_just_created && !nodeHasChildren(node)) {
    const float value = node->getLogOdds();
    bool all_saturated = true;
    for (const VoxelUpdate* u = first; u != last && all_saturated; ++u) all_saturated = saturated(value, *u);
    if (all_saturated) {
      result.leaves_skipped += static_cast<size_t>(last - first);
      return;
    }
  }
  const unsigned bit = tree_depth - 1 - depth;
  for (const VoxelUpdate* group = first; group != last;) {
    const unsigned pos = child_index(group->key, bit);
    const VoxelUpdate* group_end = group + 1;
    while (group_end != last && child_index(group_end->key, bit) == pos) ++group_end;
    bool created = false;
    if (!nodeChildExists(node, pos)) {
      if (!nodeHasChildren(node) && !node_just_created) {
        expandNode(node);  // a pruned node: its 8 children inherit its value
      } else {
        createNodeChild(node, pos);
        created = true;
      }
    }
    apply_recursive(getNodeChild(node, pos), created, depth + 1, group, group_end, update, saturated, result);
    group = group_end;
  }
  if (!pruneNode(node)) node->updateOccupancyChildren();
}

void MapTree::note_change(const octomap::OcTreeKey& key, bool created, bool occupied_before, bool occupied_after,
                          BatchResult& result) {
  if (!created && occupied_before == occupied_after) return;
  if (result.state_changes == 0) {
    result.changed_min = result.changed_max = key;
  } else {
    for (unsigned i = 0; i < 3; ++i) {
      result.changed_min[i] = std::min(result.changed_min[i], key[i]);
      result.changed_max[i] = std::max(result.changed_max[i], key[i]);
    }
  }
  ++result.state_changes;
  if (!use_change_detection) return;
  // OctoMap's change-detection bookkeeping (OccupancyOcTreeBase::updateNodeRecurs).
  if (created) {
    changed_keys.insert({key, true});
    return;
  }
  const auto it = changed_keys.find(key);
  if (it == changed_keys.end())
    changed_keys.insert({key, false});
  else if (!it->second)
    changed_keys.erase(it);  // changed back since the last reset
}

void MapTree::set_node(const octomap::OcTreeKey& key, unsigned depth, float log_odds) {
  bool fresh = false;  // created by this call: no value to inherit
  if (root == nullptr) {
    root = new octomap::OcTreeNode();
    ++tree_size;
    size_changed = true;
    fresh = true;
  }
  octomap::OcTreeNode* node = root;
  for (unsigned d = 0; d < depth && d < tree_depth; ++d) {
    const unsigned pos = octomap::computeChildIdx(key, static_cast<int>(tree_depth - 1 - d));
    if (!nodeChildExists(node, pos)) {
      if (!fresh && !nodeHasChildren(node)) {
        expandNode(node);
      } else {
        createNodeChild(node, pos);
        fresh = true;
      }
    }
    node = getNodeChild(node, pos);
  }
  node->setLogOdds(log_odds);
}

}  // namespace aerie::map
