#pragma once
// VoParams from YAML (config/vo.yaml documents every key). Keys not known here, outside
// the sections named in `other_sections`, are refused with the file and key, so that a
// typo does not silently fall back to a default.
#include <string>
#include <vector>

#include "air/stereo/vo/vo.hpp"
#include "common/util/config.hpp"

namespace aerie::stereo {

// The odometry's keys of a VO config; other_sections are read by someone else (e.g. kNodeSections).
VoParams vo_params_from_config(const util::Config& cfg, const std::vector<std::string>& other_sections = {});

// The sections of config/vo.yaml that aerie-vo's node reads, not the odometry.
inline const std::vector<std::string> kNodeSections{"node", "message_time"};

}  // namespace aerie::stereo
