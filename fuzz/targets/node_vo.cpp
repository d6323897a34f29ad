// aerie-vo's handler (air/stereo/node/vo_node.hpp) fed CAM_STEREO pairs over memq://
// (fuzz_support.hpp: kVoChannels; record format there), with config/vo.yaml as aerie-vo loads
// it (ba.synchronous off, the bundle adjuster on its own thread, its results applied at the
// next keyframe, so the poses depend on the input alone): the bounded decoder, the pair's
// checks (sizes, skew, intrinsics), both images decoded to grey, the camera's message-time
// policy, camera changes, duplicate and out-of-order pairs, then the odometry (features,
// matching, dense SGBM depth on every second pair, motion, keyframes) and VO_POSE, VO_DEPTH
// (the spherical encoding) and the status; the stale-camera check after each message on a
// node clock that advances 10 ms per message.
// Changes for cost (a pair costs 10-25 ms under ASan; the seeds are 96 x 72, config/vo.yaml is
// tuned for 376 x 240): the bundle adjuster runs at most 2 Levenberg-Marquardt iterations
// (ba.max_iterations 15), and a keyframe is taken when fewer than 30 features are tracked since
// the last one (keyframes.min_tracked 150, more than a 96 x 72 pair has: every depth pair was a
// keyframe, and the adjuster's autodiff took half of the time). The same code runs; the poses
// differ from aerie-vo's on the same pairs.
#include "air/stereo/node/vo_node.hpp"
#include "common/util/config.hpp"
#include "fuzz/fuzz_support.hpp"

namespace {

using namespace aerie;

const stereo::VoNodeConfig& config() {
  static const stereo::VoNodeConfig c = [] {
    stereo::VoNodeConfig c = stereo::load_vo_node_config(util::Config::load(fuzz::source_path("config/vo.yaml")));
    c.vo.ba_synchronous = false;  // as aerie-vo
    c.vo.ba.max_iterations = 2;  // config/vo.yaml: 15
    c.vo.keyframe_min_tracked = 30;  // config/vo.yaml: 150
    c.input = fuzz::kVoChannels[0];
    return c;
  }();
  return c;
}

}  // namespace

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
  fuzz::quiet();
  int64_t now = 1'000'000;
  bus::Bus bus("memq://");
  bus::StatusReporter status(bus, "VO");
  stereo::VoNode node(bus, status, config(), [&now] { return now; });
  fuzz::publish_records(bus, fuzz::kVoChannels, data, size, [&] {
    now += 10'000;
    node.tick();
  });
  return 0;
}
