#pragma once
// Every tracker by name, configured from YAML (a config/track.yaml section):
//   ours:        ipsl, ipsl-mr (when air/track/ipsl is built), ct, amcmr-ct, mil, am3, dcf, eco
//   references:  opencv-mil, opencv-kcf, opencv-csrt, opencv-tld, opencv-medianflow,
//                opencv-boosting, opencv-mosse (OpenCV 4.6 defaults, for the benchmark)
#include <cstdint>
#include <memory>
#include <string>
#include <vector>

#include "air/track/tracker.hpp"
#include "common/util/config.hpp"

namespace aerie::track {

// Aerie's trackers that are built, in the order of the thesis.
std::vector<std::string> aerie_tracker_names();
// OpenCV's reference trackers.
std::vector<std::string> opencv_tracker_names();
bool is_known_tracker(const std::string& name);

// `params` holds the tracker's own keys (e.g. the `amcmr-ct:` section of track.yaml);
// absent keys keep the defaults documented in config/track.yaml. Throws
// std::invalid_argument for an unknown name, an unknown key or a bad value, naming them.
std::unique_ptr<Tracker> make_tracker(const std::string& name, const util::Config& params = {}, uint64_t seed = 1);

}  // namespace aerie::track
