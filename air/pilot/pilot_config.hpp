#pragma once
// config/pilot.yaml -> PilotConfig (every key documented there; unknown keys rejected
// naming the file and the key). The fuzzy rule base defaults to config/flc/landing.yaml,
// compiled in; `fuzzy_rules: PATH` reads another controller file (.yaml or .fll).
#include "air/pilot/pilot.hpp"
#include "common/util/config.hpp"

namespace aerie::pilot {

PilotConfig load_pilot_config(const util::Config& cfg);
// config/flc/landing.yaml as compiled in.
flc::FlcSpec landing_flc();

}  // namespace aerie::pilot
