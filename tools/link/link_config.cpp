#include "tools/link/link_config.hpp"

#include <stdexcept>
#include <vector>

#include "common/util/section_reader.hpp"

namespace aerie::link {

LinkConfig::LinkConfig() {
  air_to_ground.name = "air->ground";
  air_to_ground.channels =
      "CAM_.*|GT_.*|TRACK|TARGET_POSE|VO_.*|CTRL_CMD|MAP_QUERY|STATUS_.*";  // no PMD_* (issue 46)
  air_to_ground.seed = 1;
  ground_to_air.name = "ground->air";
  ground_to_air.channels = "PILOT_CMD|TRACK_CMD|FLC_PARAMS|MAP_CMD|MAP_QUERY|MAP_RESPONSE";
  ground_to_air.seed = 2;
  // As config/link.yaml: the operator's commands at a human's pace, telemetry at the sensors'.
  ground_to_air_rates = {RateRule{"PILOT_CMD|TRACK_CMD|MAP_CMD", 20, 40, 65536, 131072},
                         RateRule{".*", 100, 200, 1 << 20, 2 << 20}};
  air_to_ground_rates = {RateRule{".*", 4000, 8000, 64e6, 128e6}};
}

DoorPolicy LinkConfig::policy(seal::Direction d) const {
  return d == seal::Direction::AirToGround ? DoorPolicy{air_to_ground.channels, air_to_ground_rates, ""}
                                           : DoorPolicy{ground_to_air.channels, ground_to_air_rates, operator_channels};
}

namespace {

std::string line_of(const YAML::Node& n) { return "line " + std::to_string(n.Mark().line + 1); }

// <direction>.rate: a list of {channels, messages_per_s, message_burst, bytes_per_s, byte_burst}.
std::vector<RateRule> read_rates(const util::Config& cfg, const std::string& key, std::vector<RateRule> fallback) {
  const util::Config s = cfg.section(key);
  const YAML::Node& root = s.node();
  if (!root || !root.IsMap() || !root["rate"]) return fallback;
  const YAML::Node list = root["rate"];
  const std::string at = cfg.origin() + ": " + key + ".rate";
  if (list.IsNull()) return {};
  if (!list.IsSequence()) throw std::runtime_error(at + ": expected a list of rules (" + line_of(list) + ")");
  std::vector<RateRule> rules;
  for (size_t i = 0; i < list.size(); ++i) {
    const YAML::Node r = list[i];
    const std::string here = at + "[" + std::to_string(i) + "]";
    if (!r.IsMap()) throw std::runtime_error(here + ": expected a map {channels, messages_per_s, ...} (" + line_of(r) + ")");
    RateRule rule;
    for (const auto& kv : r) {
      const std::string k = kv.first.as<std::string>();
      try {
        if (k == "channels") rule.channels = kv.second.as<std::string>();
        else if (k == "messages_per_s") rule.messages_per_s = kv.second.as<double>();
        else if (k == "message_burst") rule.message_burst = kv.second.as<double>();
        else if (k == "bytes_per_s") rule.bytes_per_s = kv.second.as<double>();
        else if (k == "byte_burst") rule.byte_burst = kv.second.as<double>();
        else
          throw std::runtime_error(here + ": unknown key '" + k + "' (" + line_of(kv.first) +
                                   "); known here: channels, messages_per_s, message_burst, bytes_per_s, byte_burst");
      } catch (const YAML::Exception&) {
        throw std::runtime_error(here + ": key '" + k + "' has the wrong type (" + line_of(kv.second) + ")");
      }
    }
    try {
      rule.validate();
    } catch (const std::invalid_argument& e) {
      throw std::runtime_error(here + " (" + line_of(r) + "): " + e.what());
    }
    rules.push_back(std::move(rule));
  }
  return rules;
}

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


const std::vector<std::string>& known_keys() {
  static const std::vector<std::string> keys = [] {
    std::vector<std::string> k = {"air_url", "ground_url", "seed", "stats.channel", "stats.period_s", "stats.publish_on",
                                  "rekey.seconds", "rekey.messages", "rekey.overlap_s",
                                  "door.max_message_bytes", "door.max_pending_bytes", "door.max_pending_messages",
                                  "door.reassembly_timeout_s", "door.max_datagram_bytes"};
    for (const std::string d : {"air_to_ground", "ground_to_air"})
      for (const char* leaf : {"channels", "delay_ms", "jitter_ms", "jitter_distribution", "reorder", "loss.model",
                               "loss.probability", "loss.p_good_to_bad", "loss.p_bad_to_good", "loss.loss_good",
                               "loss.loss_bad", "bandwidth_kbps", "queue_bytes", "queue_policy", "jpeg.channels",
                               "jpeg.quality", "seed", "rate.*"})
        k.push_back(d + "." + leaf);
    k.push_back("ground_to_air.operator_channels");
    return k;
  }();
  return keys;
}

struct RekeyKeys {
  double seconds = 0, overlap_s = 0;
  uint64_t messages = 0;
};
struct DoorKeys {
  int64_t max_message_bytes = 0, max_pending_bytes = 0, max_pending_messages = 0, max_datagram_bytes = 0;
  double reassembly_timeout_s = 0;
};

}  // namespace

LinkConfig load_link_config(const util::Config& cfg) {
  cfg.check_keys(known_keys());  // issue 48: a typo was silently ignored
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
  c.air_to_ground_rates = read_rates(cfg, "air_to_ground", c.air_to_ground_rates);
  c.ground_to_air_rates = read_rates(cfg, "ground_to_air", c.ground_to_air_rates);
  c.operator_channels = cfg.get<std::string>("ground_to_air.operator_channels", c.operator_channels);
  try {
    ChannelMatcher m(c.operator_channels);
  } catch (const std::regex_error& e) {
    throw std::runtime_error(cfg.origin() + ": ground_to_air.operator_channels '" + c.operator_channels +
                             "' is not a regex: " + e.what());
  }

  RekeyKeys rk{c.rekey.seconds, c.rekey_overlap_s, c.rekey.messages};
  util::SectionReader<RekeyKeys>(cfg.section("rekey"), rk)("seconds", &RekeyKeys::seconds)(
      "messages", &RekeyKeys::messages)("overlap_s", &RekeyKeys::overlap_s).finish();
  c.rekey.seconds = rk.seconds;
  c.rekey.messages = rk.messages;
  c.rekey_overlap_s = rk.overlap_s;
  try {
    c.rekey.validate();
    seal::OpenerConfig{.overlap_s = c.rekey_overlap_s}.validate();
  } catch (const std::invalid_argument& e) {
    throw std::runtime_error(cfg.origin() + ": rekey: " + e.what());
  }
  DoorKeys dk{static_cast<int64_t>(c.reassembly.max_message_bytes), static_cast<int64_t>(c.reassembly.max_pending_bytes),
              static_cast<int64_t>(c.reassembly.max_pending_messages),
              static_cast<int64_t>(c.reassembly.max_datagram_bytes), c.reassembly.timeout_s};
  util::SectionReader<DoorKeys>(cfg.section("door"), dk)("max_message_bytes", &DoorKeys::max_message_bytes)(
      "max_pending_bytes", &DoorKeys::max_pending_bytes)("max_pending_messages", &DoorKeys::max_pending_messages)(
      "max_datagram_bytes", &DoorKeys::max_datagram_bytes)("reassembly_timeout_s", &DoorKeys::reassembly_timeout_s)
      .finish();
  for (const int64_t v : {dk.max_message_bytes, dk.max_pending_bytes, dk.max_pending_messages, dk.max_datagram_bytes})
    if (v < 0) throw std::runtime_error(cfg.origin() + ": door: sizes and counts must be >= 0, got " + std::to_string(v));
  c.reassembly.max_message_bytes = static_cast<size_t>(dk.max_message_bytes);
  c.reassembly.max_pending_bytes = static_cast<size_t>(dk.max_pending_bytes);
  c.reassembly.max_pending_messages = static_cast<size_t>(dk.max_pending_messages);
  c.reassembly.max_datagram_bytes = static_cast<size_t>(dk.max_datagram_bytes);
  c.reassembly.timeout_s = dk.reassembly_timeout_s;
  try {
    c.reassembly.validate();
  } catch (const std::invalid_argument& e) {
    throw std::runtime_error(cfg.origin() + ": door: " + e.what());
  }
  if (c.air_url == c.ground_url)
    throw std::runtime_error(cfg.origin() + ": air_url and ground_url are the same network ('" + c.air_url +
                             "'): the link would relay its own output");
  return c;
}

}  // namespace aerie::link
