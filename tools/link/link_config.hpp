#pragma once
// aerie-link's configuration (config/link.yaml, documented there and in docs/link.md).
#include <string>
#include <vector>

#include "common/seal/seal.hpp"
#include "common/util/config.hpp"
#include "tools/link/door.hpp"
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

  // The door (aerie-link --half air|ground; docs/link.md "The two halves"): per direction the
  // rate limits of the channels that may cross (`<direction>.rate`), the rekeying of the
  // sealed datagrams (`rekey`) and the bounds of fragment reassembly (`door`).
  std::vector<RateRule> air_to_ground_rates;
  std::vector<RateRule> ground_to_air_rates;
  // ground_to_air.operator_channels: the commands that must carry the operator's signature.
  std::string operator_channels = kDefaultOperatorChannels;
  seal::RekeyPolicy rekey;
  double rekey_overlap_s = 5.0;
  ReassemblyLimits reassembly;

  LinkConfig();
  // What may cross one direction at the receiving half: its channels and its rate limits.
  DoorPolicy policy(seal::Direction d) const;
};

// Reads every key (missing keys keep the defaults above); throws std::runtime_error naming
// the file and key for a wrong type or value, and for a key it does not know (with its line).
LinkConfig load_link_config(const util::Config& cfg);

}  // namespace aerie::link
