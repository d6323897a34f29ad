#pragma once
// Reads the keys of one YAML section into a struct, each key named once; finish() then
// rejects any key of the section that was not read, naming it and the known ones (a typo
// would otherwise be silently ignored).
//   SectionReader<Params>(cfg.section("wind"), wind)("mean_m_s", &Params::mean_m_s).finish();
#include <algorithm>
#include <stdexcept>
#include <string>
#include <vector>

#include "common/util/config.hpp"

namespace aerie::util {

template <typename S>
class SectionReader {
 public:
  SectionReader(const Config& section, S& out) : c_(section), out_(out) {}
  template <typename T>
  SectionReader& operator()(const std::string& key, T S::*member) {
    out_.*member = c_.get<T>(key, out_.*member);
    known_.push_back(key);
    return *this;
  }
  // A key read elsewhere (a nested section, a key with its own parsing).
  SectionReader& known(const std::string& key) {
    known_.push_back(key);
    return *this;
  }
  void finish() const {
    const YAML::Node& n = c_.node();
    if (!n || n.IsNull()) return;
    if (!n.IsMap()) throw std::runtime_error(c_.origin() + ": expected a map of keys");
    for (const auto& kv : n) {
      const std::string key = kv.first.as<std::string>();
      if (std::find(known_.begin(), known_.end(), key) != known_.end()) continue;
      std::string list;
      for (const auto& k : known_) list += (list.empty() ? "" : ", ") + k;
      throw std::runtime_error(c_.origin() + ": unknown key '" + key + "' (known: " + list + ")");
    }
  }

 private:
  const Config& c_;
  S& out_;
  std::vector<std::string> known_;
};

}  // namespace aerie::util
