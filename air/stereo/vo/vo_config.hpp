#pragma once
// VoParams from YAML (config/vo.yaml documents every key). Keys not known here, outside
// the sections named in `other_sections`, are refused with the file and key, so that a
// typo does not silently fall back to a default.
#include <string>
#include <vector>

#include "air/stereo/vo/vo.hpp"
#include "common/util/config.hpp"

namespace aerie::stereo {

VoParams vo_params_from_config(const util::Config& cfg, const std::vector<std::string>& other_sections = {});

}  // namespace aerie::stereo
