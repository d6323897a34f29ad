#pragma once
// YAML configuration (yaml-cpp) with errors that name the file and the key.
// Keys are dotted paths: cfg.get<double>("ipsl.forgetting_factor", 0.95).
#include <yaml-cpp/yaml.h>

#include <optional>
#include <stdexcept>
#include <string>

namespace aerie::util {

class Config {
 public:
  Config() = default;  // empty: every get() returns its default
  static Config load(const std::string& path);
  static Config parse(const std::string& text, const std::string& origin = "<string>");

  bool has(const std::string& key) const { return static_cast<bool>(find(key)); }

  template <typename T>
  T get(const std::string& key, const T& fallback) const {
    const auto n = find(key);
    return n ? convert<T>(*n, key) : fallback;
  }
  template <typename T>
  T require(const std::string& key) const {
    const auto n = find(key);
    if (!n) throw std::runtime_error(origin_ + ": missing required key '" + key + "'");
    return convert<T>(*n, key);
  }
  Config section(const std::string& key) const;  // empty Config when absent
  const std::string& origin() const { return origin_; }
  const YAML::Node& node() const { return root_; }

 private:
  std::optional<YAML::Node> find(const std::string& key) const;
  template <typename T>
  T convert(const YAML::Node& n, const std::string& key) const {
    try {
      return n.as<T>();
    } catch (const YAML::Exception&) {
      throw std::runtime_error(origin_ + ": key '" + key + "' has the wrong type (line " +
                               std::to_string(n.Mark().line + 1) + ")");
    }
  }

  YAML::Node root_;
  std::string origin_ = "<defaults>";
};

}  // namespace aerie::util
