#pragma once
// MAP_OCTOMAP (aerie.octomap_t) payloads: an OctoMap OcTree as the content of a .bt file
// (binary: occupied/free) or a .ot file (full probabilities). Apart from aerie_map so that
// the map itself has no LCM dependency.
#include <octomap/OcTree.h>

#include <memory>

#include <aerie/octomap_t.hpp>

namespace aerie::map {

// Fills msg.resolution, msg.binary, msg.data and msg.length; the caller sets utime, seq,
// full and the bounding box.
void encode_octree(const octomap::OcTree& tree, bool binary, aerie::octomap_t& msg);

// The tree of a message; throws std::invalid_argument naming what is wrong.
std::unique_ptr<octomap::OcTree> decode_octree(const aerie::octomap_t& msg);

}  // namespace aerie::map
