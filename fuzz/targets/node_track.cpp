// aerie-track's handlers (air/track/node/track_node.hpp) fed CAM_DOWN frames, TRACK_CMD and
// GT_TRACK messages over memq:// (fuzz_support.hpp: kTrackChannels; record format there), with
// config/track_landing.yaml as aerie-track loads it in the demo (node.tracker amcmr-ct, the
// node's default; init_from_gt 0; the 1 m square helipad refined into TARGET_POSE): the bounded
// decoder, the camera's message-time policy and image metadata (intrinsics), then on the
// node's worker thread the image decoding, every command (INIT, STOP, RESET, SET_TRACKER with
// parameter overrides, any tracker by name), initialisation on the GT_TRACK box of the same
// frame, tracking, the pad's corners and pose, TRACK / TARGET_POSE; the status report after
// each message. The node runs as with --replay (every_frame: the LCM thread hands every frame
// to the worker), and the target waits for the worker after each message, so an input always
// runs the same way.
// Changes: target.fit_h_when_cut on, so that the H-only pose runs as well. For cost:
// camera.width x camera.height is 160 x 120 (track_landing.yaml sets no
// camera, so frames up to 4096 x 4096 are decoded, which a PNG of some tens of kB can declare,
// and the pad search falls back to the whole frame). The seeds are 64 x 48; larger frames are
// refused before decoding (decode_errors), the code path of a frame larger than the configured
// camera in flight. The configured intrinsics (fx 32 px, centred) serve only frames without
// intrinsics in their metadata.
#include "air/track/node/track_node.hpp"
#include "common/util/config.hpp"
#include "fuzz/fuzz_support.hpp"

namespace {

using namespace aerie;

const track::NodeOptions& options() {
  static const track::NodeOptions o = [] {
    track::NodeOptions o = track::node_options(util::Config::load(fuzz::source_path("config/track_landing.yaml")));
    const auto& ch = fuzz::kTrackChannels;
    o.camera_channel = ch[0];
    o.command_channel = ch[1];
    o.gt_channel = ch[2];
    o.every_frame = true;
    o.fit_h_when_cut = true;  // the H-only pose of a pad cut by the border too (off in the config)
    camera::CameraModel c;
    c.width = 160;
    c.height = 120;
    c.fx = c.fy = 32;
    c.cx = 80;
    c.cy = 60;
    o.camera = c;
    return o;
  }();
  return o;
}

}  // namespace

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
  fuzz::quiet();
  int64_t now = 1'000'000;
  bus::Bus bus("memq://");
  bus::StatusReporter status(bus, "track");
  track::TrackNode node(bus, options(), [&now] { return now; });
  fuzz::publish_records(bus, fuzz::kTrackChannels, data, size, [&] {
    node.wait_idle(30'000);
    while (bus.handle(0) > 0) {  // TRACK / TARGET_POSE of the worker
    }
    now += 10'000;
    node.report(status);
  });
  return 0;
}
