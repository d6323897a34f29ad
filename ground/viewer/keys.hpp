#pragma once
// The viewer's keys: one table for the help overlay and docs/viewer.md's "Keys" table
// (test_viewer checks that the doc lists exactly these, in this order).
#include <array>
#include <string_view>

namespace aerie::viewer {

struct KeyBinding {
  std::string_view key;      // as the doc writes it
  std::string_view overlay;  // the help overlay's short word
  std::string_view action;   // the doc's description
};

inline constexpr std::array<KeyBinding, 14> kKeys{{
    {"drag", "track box", "on the camera pane: TRACK_CMD INIT with that box and the current tracker"},
    {"t", "tracker", "next tracker (SET_TRACKER); the cycle starts with the node's default"},
    {"x", "stop", "stop tracking (TRACK_CMD STOP)"},
    {"r", "reset", "reset tracking (TRACK_CMD RESET)"},
    {"c", "view", "reset the cameras of the image pane and the 3D scene"},
    {"p", "pause", "pause or resume the display"},
    {"1-9", "toggle", "toggle renderer 1-9 (the numbers of the renderer table)"},
    {"h", "help", "hide or show this help text"},
    {"v", "map res", "OctoMap display resolution (finest, 2x, 4x, 8x voxels)"},
    {"n", "CE param", "next CE parameter of the CE PDF chart"},
    {"[ ]", "select", "select the previous or next procman command in the process panel"},
    {"s", "start/stop", "start or stop the selected command"},
    {"g", "realign", "align the ground truth to the estimate now (else every --align-period s)"},
    {"q", "quit", "quit (also Escape)"},
}};

}  // namespace aerie::viewer
