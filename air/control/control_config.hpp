#pragma once
// aerie-control's configuration: config/control.yaml (every key documented there),
// then command-line overrides.
#include <optional>
#include <string>

#include "air/control/control_node.hpp"
#include "common/util/config.hpp"

namespace aerie::control {

struct CliOverrides {
  std::string controller, input, pose_channel;
  std::optional<double> reference_deg, forward_speed, rate_hz, stale_timeout_s;
};

struct NodeSetup {
  flc::FlcSpec controller;
  NodeOptions options;
};

// Throws std::runtime_error naming the file and key.
NodeSetup node_setup(const util::Config& cfg, const CliOverrides& cli = {});

}  // namespace aerie::control
