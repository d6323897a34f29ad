#include "common/util/cli.hpp"

#include <spdlog/sinks/stdout_color_sinks.h>
#include <spdlog/spdlog.h>

namespace aerie::util {

void add_common_options(CLI::App& app, CommonOptions& opts, bool with_config) {
  app.add_option("--lcm-url", opts.lcm_url, "LCM URL, e.g. udpm://239.255.76.67:7667?ttl=0 (default: $LCM_DEFAULT_URL)");
  if (with_config) app.add_option("-c,--config", opts.config, "YAML configuration file")->check(CLI::ExistingFile);
  app.add_option("--log-level", opts.log_level, "trace, debug, info, warn, error, critical or off")
      ->check(CLI::IsMember({"trace", "debug", "info", "warn", "error", "critical", "off"}));
}

void init_logging(const std::string& node, const std::string& level) {
  auto logger = spdlog::stderr_color_mt(node);
  logger->set_pattern("[%H:%M:%S.%e] [%n] [%^%l%$] %v");
  spdlog::set_default_logger(logger);
  spdlog::set_level(spdlog::level::from_str(level));
}

}  // namespace aerie::util
