#pragma once
// MonoParams from YAML (config/mono.yaml documents every key), read as air/stereo/vo's
// vo_config.cpp reads the stereo VO's: keys not known here, outside `other_sections`, are
// refused with the file, key and line; values out of range with the key.
#include <string>
#include <vector>

#include "air/mono/mono.hpp"
#include "common/util/config.hpp"

namespace aerie::mono {

MonoParams mono_params_from_config(const util::Config& cfg, const std::vector<std::string>& other_sections = {});

// The sections of config/mono.yaml that aerie-mono's node reads, not the odometry.
inline const std::vector<std::string> kMonoNodeSections{"node"};

}  // namespace aerie::mono
