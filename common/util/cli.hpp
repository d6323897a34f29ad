#pragma once
// Options every node shares (--lcm-url, --config, --log-level) and logging setup.
#include <CLI/CLI.hpp>
#include <string>

namespace aerie::util {

struct CommonOptions {
  std::string lcm_url;  // "" = LCM_DEFAULT_URL or LCM's default
  std::string config;   // YAML file ("" = built-in defaults)
  std::string log_level = "info";
};

void add_common_options(CLI::App& app, CommonOptions& opts, bool with_config = true);
// spdlog to stderr with the node name; level from "trace".."off".
void init_logging(const std::string& node, const std::string& level);

}  // namespace aerie::util
