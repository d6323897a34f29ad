#include "ground/map/octomap_message.hpp"

#include <sstream>
#include <stdexcept>
#include <string>

#include "ground/map/occupancy.hpp"

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
  try {
    return read_octree(in, msg.binary);
  } catch (const std::invalid_argument& e) {
    throw std::invalid_argument(std::string("octomap_t: payload is ") + e.what());
  }
}

}  // namespace aerie::map
