#pragma once
// Reads keys of a flat options struct from a Config, remembering each key it read, so that
// check_unknown() refuses a key nobody reads (naming file, key and line, as Config does).
#include <set>
#include <string>
#include <vector>

#include "common/util/config.hpp"

namespace aerie::util {

class KeyReader {
 public:
  explicit KeyReader(const Config& cfg) : cfg_(cfg) {}
  template <typename T>
  void operator()(const std::string& key, T& value) {
    known_.insert(key);
    value = cfg_.get<T>(key, value);
  }
  // other_sections: sections read by their own readers (every key below them is known).
  void check_unknown(const std::vector<std::string>& other_sections) const {
    std::vector<std::string> known(known_.begin(), known_.end());
    for (const auto& s : other_sections) known.push_back(s + ".*");
    cfg_.check_keys(known);
  }

 private:
  const Config& cfg_;
  std::set<std::string> known_;
};

}  // namespace aerie::util
