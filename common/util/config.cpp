#include "common/util/config.hpp"

#include "common/util/files.hpp"

#include <algorithm>
#include <filesystem>
#include <functional>
#include <map>
#include <sstream>

namespace aerie::util {

namespace {

std::string line_of(const YAML::Node& n) { return "line " + std::to_string(n.Mark().line + 1); }

std::string key_name(const YAML::Node& key, const std::string& origin, const std::string& prefix) {
  if (!key.IsScalar())
    throw std::runtime_error(origin + ": a key under '" + prefix + "' is not a name (" + line_of(key) + ")");
  return key.Scalar();
}

std::string join(const std::string& prefix, const std::string& key) { return prefix.empty() ? key : prefix + "." + key; }

// yaml-cpp keeps every pair of a map whose key is repeated, and n[key] answers the first:
// the second value would be ignored without a word.
void refuse_duplicates(const YAML::Node& n, const std::string& origin, const std::string& prefix = "") {
  if (n.IsSequence()) {
    for (const auto& item : n) refuse_duplicates(item, origin, prefix);
  } else if (n.IsMap()) {
    std::map<std::string, YAML::Node> seen;
    for (const auto& kv : n) {
      const std::string key = key_name(kv.first, origin, prefix);
      const auto [it, fresh] = seen.emplace(key, kv.first);
      if (!fresh)
        throw std::runtime_error(origin + ": duplicate key '" + join(prefix, key) + "' (" + line_of(it->second) +
                                 " and " + line_of(kv.first) + ")");
      refuse_duplicates(kv.second, origin, join(prefix, key));
    }
  }
}

}  // namespace

Config Config::load(const std::string& path) {
  require_regular_file(path, "config file");
  Config c;
  c.origin_ = path;
  try {
    c.root_ = YAML::LoadFile(path);
  } catch (const YAML::Exception& e) {
    throw std::runtime_error(path + ": YAML error at line " + std::to_string(e.mark.line + 1) + ", column " +
                             std::to_string(e.mark.column + 1) + ": " + e.msg);
  }
  refuse_duplicates(c.root_, path);
  return c;
}

Config Config::parse(const std::string& text, const std::string& origin) {
  Config c;
  c.origin_ = origin;
  try {
    c.root_ = YAML::Load(text);
  } catch (const YAML::Exception& e) {
    throw std::runtime_error(origin + ": YAML error at line " + std::to_string(e.mark.line + 1) + ": " + e.msg);
  }
  refuse_duplicates(c.root_, origin);
  return c;
}

void Config::check_keys(const std::vector<std::string>& known) const {
  const auto is_leaf = [&](const std::string& p) { return std::find(known.begin(), known.end(), p) != known.end(); };
  const auto is_open = [&](const std::string& p) { return is_leaf(p + ".*"); };
  const auto is_section = [&](const std::string& p) {
    return std::any_of(known.begin(), known.end(), [&](const std::string& k) { return k.rfind(p + ".", 0) == 0; });
  };
  std::function<void(const YAML::Node&, const std::string&)> walk = [&](const YAML::Node& n, const std::string& prefix) {
    for (const auto& kv : n) {
      const std::string key = join(prefix, key_name(kv.first, origin_, prefix));
      if (is_leaf(key) || is_open(key)) continue;
      if (!is_section(key)) {
        std::string here;  // the keys known at this level, to spot a typo
        for (const auto& k : known) {
          if (!prefix.empty() && k.rfind(prefix + ".", 0) != 0) continue;
          const std::string name = k.substr(prefix.empty() ? 0 : prefix.size() + 1);
          const std::string first = name.substr(0, name.find('.'));
          if (first != "*" && here.find(" " + first + ",") == std::string::npos) here += " " + first + ",";
        }
        if (!here.empty()) here = "; known here:" + here.substr(0, here.size() - 1);
        throw std::runtime_error(origin_ + ": unknown key '" + key + "' (" + line_of(kv.first) + ")" + here);
      }
      if (kv.second.IsNull()) continue;  // an empty section
      if (!kv.second.IsMap())
        throw std::runtime_error(origin_ + ": '" + key + "' is a section of keys, not a " +
                                 (kv.second.IsSequence() ? "list" : "value") + " (" + line_of(kv.first) + ")");
      walk(kv.second, key);
    }
  };
  if (!root_ || root_.IsNull()) return;  // an empty file: every default
  if (!root_.IsMap())
    throw std::runtime_error(origin_ + ": expected a map of keys, not a " + (root_.IsSequence() ? "list" : "value") +
                             " (" + line_of(root_) + ")");
  walk(root_, "");
}

std::optional<YAML::Node> Config::find(const std::string& key) const {
  if (!root_ || !root_.IsMap()) return std::nullopt;
  // Walks the tree itself (read-only: a const node's operator[] never inserts), so that the
  // node keeps its position in the file for messages (a clone loses it).
  YAML::Node n;
  n.reset(root_);
  std::stringstream ss(key);
  std::string part;
  while (std::getline(ss, part, '.')) {
    if (!n.IsMap()) return std::nullopt;
    const YAML::Node& parent = n;
    const YAML::Node child = parent[part];
    if (!child) return std::nullopt;
    n.reset(child);
  }
  return n;
}

Config Config::section(const std::string& key) const {
  Config c;
  c.origin_ = origin_ + ":" + key;
  if (auto n = find(key)) c.root_ = *n;
  return c;
}

}  // namespace aerie::util
