#pragma once
// The tracker aerie-track starts for an INIT that names none (NodeOptions::tracker, docs/track.md
// "Which to fly"). Header-only, so that the ground side (the viewer's tracker cycle) starts
// with the same one without linking the node.
namespace aerie::track {

inline constexpr const char* kDefaultTracker = "eco";

}  // namespace aerie::track
