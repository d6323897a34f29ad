#pragma once
// YAML configuration (yaml-cpp) with errors that name the file and the key.
// Keys are dotted paths: cfg.get<double>("ipsl.forgetting_factor", 0.95).
// load() and parse() refuse a path that is not a regular file (a FIFO would block the
// node) and a document with a key given twice in one map (yaml-cpp keeps the first
// silently); check_keys() refuses what a node does not read; get_in() refuses a number
// outside its documented range.
#include <yaml-cpp/yaml.h>

#include <cmath>
#include <optional>
#include <sstream>
#include <stdexcept>
#include <string>
#include <vector>

namespace aerie::util {

class Config {
 public:
  Config() = default;  // empty: every get() returns its default
  // A copy shares the (read-only) document; assignment rebinds to the other's document.
  // yaml-cpp's Node::operator= writes through a shared node instead: it would change every
  // copy of the document, in every thread that holds one.
  Config(const Config&) = default;
  Config& operator=(const Config& other) {
    root_.reset(other.root_);
    origin_ = other.origin_;
    return *this;
  }
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
  // get() for a number that must lie in [lo, hi]: NaN or a value outside is refused, naming
  // the key, the value, the range and the line (a value left out takes `fallback` unchecked).
  template <typename T>
  T get_in(const std::string& key, const T& fallback, const T& lo, const T& hi) const {
    const auto n = find(key);
    if (!n) return fallback;
    const T v = convert<T>(*n, key);
    if (!(v >= lo && v <= hi)) {
      std::ostringstream s;
      s << origin_ << ": key '" << key << "' = " << v << " is outside its valid range [" << lo << ", " << hi
        << "] (line " << n->Mark().line + 1 << ")";
      throw std::runtime_error(s.str());
    }
    return v;
  }
  Config section(const std::string& key) const;  // empty Config when absent
  // Refuses, naming the file, the key and its line: a document (or section) that is not a
  // map of keys (a top-level list or scalar), a key that is not in `known`, and a scalar or
  // list where a section belongs. `known` holds the dotted paths of the keys that take a
  // value ("sensor_model.max_range"); their prefixes are the sections ("sensor_model");
  // "name.*" accepts any content under `name` (checked by its own reader).
  void check_keys(const std::vector<std::string>& known) const;
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
