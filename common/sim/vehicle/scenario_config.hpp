#pragma once
// The avoidance scenario from a YAML section (config/ceopt.yaml `scenario:`, see the
// comments there for every key). Errors name the file and the key; unknown keys are
// refused so that a misspelt key is not silently ignored.
#include "common/sim/vehicle/avoidance.hpp"
#include "common/util/config.hpp"

namespace aerie::sim {

// The `scene:` keys (wall_m, normal_area_m, safe_area_m, lateral_limit_m).
Scene scene_from(const util::Config& scene, Scene defaults = {});

AvoidanceConfig avoidance_config_from(const util::Config& section, AvoidanceConfig defaults = {});

// Throws std::runtime_error naming the unknown key of `section` and the allowed ones.
void require_known_keys(const util::Config& section, std::initializer_list<const char*> allowed);

}  // namespace aerie::sim
