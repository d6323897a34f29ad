#include "common/util/config.hpp"

#include <filesystem>
#include <sstream>

namespace aerie::util {

Config Config::load(const std::string& path) {
  if (!std::filesystem::exists(path)) throw std::runtime_error(path + ": config file not found");
  Config c;
  c.origin_ = path;
  try {
    c.root_ = YAML::LoadFile(path);
  } catch (const YAML::Exception& e) {
    throw std::runtime_error(path + ": YAML error at line " + std::to_string(e.mark.line + 1) + ", column " +
                             std::to_string(e.mark.column + 1) + ": " + e.msg);
  }
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
  return c;
}

std::optional<YAML::Node> Config::find(const std::string& key) const {
  if (!root_ || !root_.IsMap()) return std::nullopt;
  YAML::Node n = YAML::Clone(root_);
  std::stringstream ss(key);
  std::string part;
  while (std::getline(ss, part, '.')) {
    if (!n.IsMap()) return std::nullopt;
    n = n[part];
    if (!n) return std::nullopt;
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
