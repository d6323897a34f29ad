// OctoMap input (ground/map): the .bt and .ot readers aerie-map --load, MAP_CMD LOAD and the
// viewer use (read_octree: resolution, node count and log-odds checked), and the MAP_OCTOMAP
// decoder (decode_octree on an aerie.octomap_t payload decoded through the bounded decoder),
// every reader on every input. An accepted tree is walked and queried.
#include <sstream>

#include "common/bus/wire.hpp"
#include "fuzz/fuzz_support.hpp"
#include "ground/map/occupancy.hpp"
#include "ground/map/octomap_message.hpp"

namespace {

using namespace aerie;

void use(const octomap::OcTree& tree) {
  double x = 0, y = 0, z = 0;
  tree.getMetricMin(x, y, z);
  tree.getMetricMax(x, y, z);
  tree.search(0.0, 0.0, 0.0);
  size_t leaves = 0;
  for (auto it = tree.begin_leafs(), end = tree.end_leafs(); it != end; ++it) leaves += tree.isNodeOccupied(*it);
  (void)leaves;
}

}  // namespace

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
  fuzz::quiet();
  const std::string bytes = fuzz::as_text(data, size);
  for (const bool binary : {true, false}) {
    fuzz::refusal_ok([&] {
      std::istringstream in(bytes);
      use(*map::read_octree(in, binary));
    });
  }
  aerie::octomap_t msg;
  if (bus::decode_bounded(data, size, msg)) fuzz::refusal_ok([&] { use(*map::decode_octree(msg)); });
  return 0;
}
