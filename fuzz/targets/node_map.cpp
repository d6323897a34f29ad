// aerie-map's handlers (ground/map/map_service.hpp) fed VO_POSE, VO_DEPTH, MAP_QUERY and
// MAP_CMD messages over memq:// (fuzz_support.hpp: kMapChannels; record format there), with
// config/map.yaml: the bounded decoder, then pose/depth matching in message time, insertion of
// the spherical depth into the octree, MAP_OCTOMAP publication, every query (occupancy, ray,
// nearest obstacle on the distance map, ...) and every command. files.directory is an empty
// folder of the fuzzer's own, so that SAVE and LOAD run confined there.
// The voxels are 0.4 m and the sensor range 2 m (config/map.yaml: 0.1 m, 5 m): the same code
// runs, but a recorded VO_DEPTH's 30,000 rays cross 5 voxels each instead of 50, so an input
// costs about a tenth (docs/fuzz.md: 14-24 executions/s with the flight's settings).
#include "common/util/config.hpp"
#include "fuzz/fuzz_support.hpp"
#include "ground/map/map_service.hpp"

namespace {

using namespace aerie;

map::MapServiceConfig config() {
  static const map::MapServiceConfig c =
      map::MapServiceConfig::from_config(util::Config::load(fuzz::source_path("config/map.yaml")));
  map::MapServiceConfig mine = c;
  mine.occupancy.resolution = 0.4;
  mine.occupancy.sensor_model.max_range = 2.0;
  const auto& ch = fuzz::kMapChannels;
  mine.pose_channel = ch[0];
  mine.depth_channel = ch[1];
  mine.query_channel = ch[2];
  mine.cmd_channel = ch[3];
  mine.files_directory = fuzz::empty_temp_folder("maps");
  return mine;
}

}  // namespace

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
  fuzz::quiet();
  int64_t now = 1'000'000;
  bus::Bus bus("memq://");
  bus::StatusReporter status(bus, "map");
  map::MapService service(bus, status, config(), [&now] { return now; });
  fuzz::publish_records(bus, fuzz::kMapChannels, data, size, [&] {
    now += 10'000;
    service.tick();
  });
  return 0;
}
