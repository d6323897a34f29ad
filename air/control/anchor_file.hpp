#pragma once
// The manoeuvre's anchor on disk (NodeOptions::anchor_file), so that aerie-control
// restarted in flight (procman's respawn) resumes the manoeuvre in the estimator's frame
// instead of refusing it. Five lines of text, written atomically:
//   aerie-control anchor 1
//   channel NAV_STATE          (the pose channel whose frame it is in)
//   utime 1234567              (of the pose that anchored it)
//   start 0.01 -0.02 0.00      (m, that pose's position)
//   reference_deg 90.5
#include <optional>
#include <string>

#include "air/control/control_loop.hpp"

namespace aerie::control {

void write_anchor(const std::string& path, const std::string& channel, const Anchor& anchor);  // throws

// The anchor in `path` if it is one of `channel`'s; nullopt with the reason in `why` if the
// file is missing (util::read_regular_file's message), malformed, or of another channel.
std::optional<Anchor> read_anchor(const std::string& path, const std::string& channel, std::string& why);

}  // namespace aerie::control
