// aerie-map: the ground occupancy map (thesis section 4.2.2). Subscribes VO_POSE + VO_DEPTH,
// publishes MAP_OCTOMAP, answers MAP_QUERY, obeys MAP_CMD; saves the map at exit.
#include <spdlog/spdlog.h>

#include <filesystem>

#include "common/bus/deployment.hpp"
#include "common/bus/node.hpp"
#include "common/util/cli.hpp"
#include "common/util/heap.hpp"
#include "ground/map/map_service.hpp"

int main(int argc, char** argv) {
  CLI::App app{
      "aerie-map: robust OctoMap occupancy map from VO_POSE + VO_DEPTH (spherical depth, thesis eq. 4.17);\n"
      "publishes MAP_OCTOMAP, answers MAP_QUERY (occupancy, nearest obstacle, ray), obeys MAP_CMD\n"
      "(save/load/clear/publish) and saves the map at exit (Ctrl-C)."};
  aerie::util::CommonOptions opts;
  aerie::util::add_common_options(app, opts);
  std::string load_path, save_path = "aerie-map.ot";
  double resolution = 0, max_range = 0;
  app.add_option("--load", load_path, "continue from a saved map (.bt or .ot)")->check(CLI::ExistingFile);
  app.add_option("--save", save_path,
                 "save the map here at exit (.ot keeps probabilities, .bt is smaller; \"\" = do not save)")
      ->capture_default_str();
  app.add_option("--resolution", resolution, "voxel size in metres (overrides the config)");
  app.add_option("--max-range", max_range, "sensor_model/max_range in metres (overrides the config)");
  CLI11_PARSE(app, argc, argv);
  aerie::util::init_logging("aerie-map", opts.log_level);
  aerie::bus::install_stop_handlers();  // early: a Ctrl-C while loading still saves at exit
  aerie::util::map_large_blocks();      // util/heap.hpp

  try {
    const auto ext = std::filesystem::path(save_path).extension();
    if (!save_path.empty() && ext != ".bt" && ext != ".ot")
      throw std::runtime_error("--save '" + save_path + "': the extension must be .bt or .ot");
    const auto config = opts.config.empty() ? aerie::util::Config() : aerie::util::Config::load(opts.config);
    auto cfg = aerie::map::MapServiceConfig::from_config(config);
    if (resolution > 0) cfg.occupancy.resolution = resolution;
    if (max_range > 0) cfg.occupancy.sensor_model.max_range = max_range;

    aerie::bus::require_host_local_commands("aerie-map", "MAP_CMD and MAP_QUERY", opts.lcm_url);
    aerie::bus::Bus bus(opts.lcm_url);
    aerie::bus::StatusReporter status(bus, "aerie-map");
    aerie::map::MapService service(bus, status, cfg);
    if (!load_path.empty()) service.load(load_path);
    spdlog::info("mapping {} + {} at {} m (max range {} m) on {}", cfg.pose_channel, cfg.depth_channel,
                 service.map().params().resolution, cfg.occupancy.sensor_model.max_range, bus.url());
    aerie::bus::run(bus, status, [&] {
      service.tick();  // reports VO_POSE/VO_DEPTH stale during an outage
      return true;
    });

    if (!save_path.empty()) {
      service.save(save_path);
      spdlog::info("saved the map to '{}' ({} nodes, {} frames mapped)", save_path, service.map().tree().size(),
                   status.counter("frames_mapped"));
    }
  } catch (const std::exception& e) {
    spdlog::error("{}", e.what());
    return 1;
  }
  return 0;
}
