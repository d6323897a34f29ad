// aerie-control's handlers (air/control/control_node.hpp) fed messages over memq://: three
// nodes on one bus, one per input (VO_POSE, NAV_STATE, GT_POSE), each taking controllers on its
// own FLC_PARAMS channel (fuzz_support.hpp: kControlChannels; record format there). Every
// message goes through the bounded decoder of the subscription, then the handler: heading
// from the pose, the message-time policy, the control loop, the FLL import and validation of
// a new controller. The VO node answers every pose (rate 0), the others run at config/control.yaml's
// rate on a node clock that advances 10 ms per message.
#include <memory>

#include "air/control/control_config.hpp"
#include "air/control/control_node.hpp"
#include "common/util/config.hpp"
#include "fuzz/fuzz_support.hpp"

namespace {

using namespace aerie;
using control::NodeOptions;

const control::NodeSetup& setup() {
  static const control::NodeSetup s = control::node_setup(util::Config::load(fuzz::source_path("config/control.yaml")));
  return s;
}

NodeOptions options(NodeOptions::Input input, const std::string& params_channel, double rate_hz) {
  NodeOptions o = setup().options;
  o.input = input;
  o.pose_channel = control::default_pose_channel(input);
  o.frame = control::default_heading_frame(input);
  o.params_channel = params_channel;
  o.rate_hz = rate_hz;
  return o;
}

}  // namespace

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
  fuzz::quiet();
  int64_t now = 1'000'000;
  const util::NodeClock clock = [&now] { return now; };
  bus::Bus bus("memq://");
  bus::StatusReporter status(bus, "control");
  const auto& ch = fuzz::kControlChannels;
  control::ControlNode vo(bus, status, setup().controller, options(NodeOptions::Input::kVoPose, ch[3], 0), clock);
  control::ControlNode nav(bus, status, setup().controller, options(NodeOptions::Input::kNavState, ch[4], 30), clock);
  control::ControlNode gt(bus, status, setup().controller, options(NodeOptions::Input::kGtPose, ch[5], 30), clock);
  fuzz::publish_records(bus, ch, data, size, [&] {
    now += 10'000;
    nav.tick(now);
    gt.tick(now);
  });
  return 0;
}
