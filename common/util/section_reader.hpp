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
  const std::vector<std::string>& keys() const { return known_; }  // the keys named so far
  void finish() const {
    std::vector<std::string> open;  // each known key with whatever it holds (read by its own reader)
    for (const auto& k : known_) open.push_back(k + ".*");
    c_.check_keys(open);
  }

 private:
  const Config& c_;
  S& out_;
  std::vector<std::string> known_;
};

}  // namespace aerie::util
