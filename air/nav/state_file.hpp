#pragma once
// The filter's snapshot on disk (NavConfig::resume.state_file), so that aerie-nav restarted in
// flight (procman's respawn) resumes in the same world frame instead of a new static alignment
// (a new frame that aerie-control refuses). Text, written atomically:
//   aerie-nav state 1
//   utime 1234567                 (of the state)
//   last_update_utime 1234000     (the last applied VO update)
//   p x y z / v x y z / q w x y z / bg x y z / ba x y z
//   P 225 numbers                 (15x15, row-major)
//   T_world_vo qw qx qy qz x y z  (or "T_world_vo none": not anchored yet)
#include <optional>
#include <string>

#include "air/nav/eskf.hpp"

namespace aerie::nav {

void write_snapshot(const std::string& path, const Snapshot& s);  // throws

// The snapshot in `path`; nullopt with the reason in `why` if the file is missing
// (util::read_regular_file's message) or is not a well-formed snapshot (a value not finite, a
// quaternion not of unit norm, a covariance with a negative diagonal or not symmetric).
std::optional<Snapshot> read_snapshot(const std::string& path, std::string& why);

}  // namespace aerie::nav
