#include "ground/map/octomap_message.hpp"

#include <sstream>
#include <stdexcept>
#include <string>

namespace aerie::map {

void encode_octree(const octomap::OcTree& tree, bool binary, aerie::octomap_t& msg) {
  std::ostringstream out;
  if (binary)
    tree.writeBinaryConst(out);
  else
    tree.write(out);
  const std::string bytes = out.str();
  msg.resolution = tree.getResolution();
  msg.binary = binary;
  msg.data.assign(bytes.begin(), bytes.end());
  msg.length = static_cast<int32_t>(msg.data.size());
}

std::unique_ptr<octomap::OcTree> decode_octree(const aerie::octomap_t& msg) {
  if (msg.length != static_cast<int32_t>(msg.data.size()))
    throw std::invalid_argument("octomap_t: length disagrees with the payload size");
  if (!(msg.resolution > 0)) throw std::invalid_argument("octomap_t: resolution must be positive");
  std::istringstream in(std::string(msg.data.begin(), msg.data.end()));
  if (msg.binary) {
    auto tree = std::make_unique<octomap::OcTree>(msg.resolution);
    if (!tree->readBinary(in)) throw std::invalid_argument("octomap_t: payload is not an OctoMap binary tree");
    return tree;
  }
  std::unique_ptr<octomap::AbstractOcTree> any(octomap::AbstractOcTree::read(in));
  auto* tree = dynamic_cast<octomap::OcTree*>(any.get());
  if (!tree) throw std::invalid_argument("octomap_t: payload is not an OctoMap OcTree");
  any.release();
  return std::unique_ptr<octomap::OcTree>(tree);
}

}  // namespace aerie::map
