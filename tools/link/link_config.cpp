#include "tools/link/link_config.hpp"

#include <stdexcept>
#include <vector>

namespace aerie::link {

LinkConfig::LinkConfig() {
  air_to_ground.name = "air->ground";
  air_to_ground.channels =
      "CAM_.*|GT_.*|TRACK|TARGET_POSE|VO_.*|CTRL_CMD|MAP_QUERY|STATUS_.*|PMD_INFO2|PMD_PRINTF|PMD_DISCOVER";
  air_to_ground.seed = 1;
  ground_to_air.name = "ground->air";
  ground_to_air.channels = "TRACK_CMD|FLC_PARAMS|MAP_RESPONSE|PMD_ORDERS2|PMD_DISCOVER";
  ground_to_air.seed = 2;
}

namespace {

void read_direction(const util::Config& cfg, const std::string& key, DirectionConfig& d) {
  const util::Config s = cfg.section(key);
  const std::string at = cfg.origin() + ": " + key + ".";
  d.channels = s.get<std::string>("channels", d.channels);
  d.delay_ms = s.get<double>("delay_ms", d.delay_ms);
  d.jitter_ms = s.get<double>("jitter_ms", d.jitter_ms);
  try {
    d.jitter = jitter_from_string(s.get<std::string>("jitter_distribution", to_string(d.jitter)));
    d.queue_policy = queue_policy_from_string(
        s.get<std::string>("queue_policy", d.queue_policy == QueuePolicy::DropOldest ? "drop_oldest" : "drop_newest"));
    d.loss_model = loss_model_from_string(
        s.get<std::string>("loss.model", d.loss_model == LossModel::Bernoulli ? "bernoulli" : "gilbert_elliott"));
  } catch (const std::invalid_argument& e) {
    throw std::runtime_error(at + e.what());
  }
  d.reorder = s.get<bool>("reorder", d.reorder);
  d.loss = s.get<double>("loss.probability", d.loss);
  d.gilbert_elliott.p_good_to_bad = s.get<double>("loss.p_good_to_bad", d.gilbert_elliott.p_good_to_bad);
  d.gilbert_elliott.p_bad_to_good = s.get<double>("loss.p_bad_to_good", d.gilbert_elliott.p_bad_to_good);
  d.gilbert_elliott.loss_good = s.get<double>("loss.loss_good", d.gilbert_elliott.loss_good);
  d.gilbert_elliott.loss_bad = s.get<double>("loss.loss_bad", d.gilbert_elliott.loss_bad);
  d.bandwidth_bps = 1000.0 * s.get<double>("bandwidth_kbps", d.bandwidth_bps / 1000.0);
  d.queue_bytes = s.get<int64_t>("queue_bytes", d.queue_bytes);
  d.jpeg_channels = s.get<std::string>("jpeg.channels", d.jpeg_channels);
  d.jpeg_quality = s.get<int>("jpeg.quality", d.jpeg_quality);
  d.seed = s.get<uint64_t>("seed", d.seed);
  try {
    d.validate();
  } catch (const std::invalid_argument& e) {
    throw std::runtime_error(cfg.origin() + ": " + key + ": " + e.what());
  }
}

}  // namespace

LinkConfig load_link_config(const util::Config& cfg) {
  LinkConfig c;
  c.air_url = cfg.get<std::string>("air_url", c.air_url);
  c.ground_url = cfg.get<std::string>("ground_url", c.ground_url);
  if (cfg.has("seed")) {
    const auto seed = cfg.get<uint64_t>("seed", 1);
    c.air_to_ground.seed = 2 * seed - 1;
    c.ground_to_air.seed = 2 * seed;
  }
  c.stats_channel = cfg.get<std::string>("stats.channel", c.stats_channel);
  c.stats_period_s = cfg.get<double>("stats.period_s", c.stats_period_s);
  if (!(c.stats_period_s > 0)) throw std::runtime_error(cfg.origin() + ": stats.period_s must be > 0");
  if (cfg.has("stats.publish_on")) {
    const auto on = cfg.get<std::vector<std::string>>("stats.publish_on", {});
    c.stats_on_air = c.stats_on_ground = false;
    for (const auto& n : on) {
      if (n == "air") c.stats_on_air = true;
      else if (n == "ground") c.stats_on_ground = true;
      else throw std::runtime_error(cfg.origin() + ": stats.publish_on: expected air and/or ground, got '" + n + "'");
    }
  }
  read_direction(cfg, "air_to_ground", c.air_to_ground);
  read_direction(cfg, "ground_to_air", c.ground_to_air);
  if (c.air_url == c.ground_url)
    throw std::runtime_error(cfg.origin() + ": air_url and ground_url are the same network ('" + c.air_url +
                             "'): the link would relay its own output");
  return c;
}

}  // namespace aerie::link
