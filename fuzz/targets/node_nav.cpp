// aerie-nav's handlers (air/nav/node/nav_node.hpp) fed IMU and VO_POSE messages over memq://
// (fuzz_support.hpp: kNavChannels; record format there), with config/nav.yaml: the bounded
// decoder, then the error-state EKF (static alignment, propagation, delayed and out-of-order VO
// updates, gating, outages) and the NAV_STATE it publishes; the status report after each.
#include "air/nav/node/nav_node.hpp"
#include "common/util/config.hpp"
#include "fuzz/fuzz_support.hpp"

namespace {

using namespace aerie;

const nav::NavConfig& config() {
  static const nav::NavConfig c = nav::load_nav_config(util::Config::load(fuzz::source_path("config/nav.yaml")));
  return c;
}

}  // namespace

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
  fuzz::quiet();
  bus::Bus bus("memq://");
  bus::StatusReporter status(bus, "nav");
  nav::NavNodeOptions options;
  options.imu_channel = fuzz::kNavChannels[0];
  options.vo_channel = fuzz::kNavChannels[1];
  nav::NavNode node(bus, config(), options);
  fuzz::publish_records(bus, fuzz::kNavChannels, data, size, [&] { node.report(status); });
  return 0;
}
