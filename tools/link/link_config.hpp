#pragma once
// aerie-link's configuration (config/link.yaml, documented there and in docs/link.md).
#include <string>

#include "common/util/config.hpp"
#include "tools/link/link_model.hpp"

namespace aerie::link {

struct LinkConfig {
  std::string air_url = "udpm://239.255.76.67:7667?ttl=0";
  std::string ground_url = "udpm://239.255.76.68:7668?ttl=0";
  std::string stats_channel = "LINK_STATS";
  double stats_period_s = 1.0;
  bool stats_on_air = true;
  bool stats_on_ground = true;
  DirectionConfig air_to_ground;
  DirectionConfig ground_to_air;

  LinkConfig();
};

// Reads every key (missing keys keep the defaults above); throws std::runtime_error
// naming the file and key for a wrong type or value.
LinkConfig load_link_config(const util::Config& cfg);

}  // namespace aerie::link
