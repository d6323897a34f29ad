// Issue 49, the hot path: aerie-capture's node publishing faster than aerie-vo's node can take
// the pairs. Every pair published is either processed by the odometry or counted as an overflow
// of the node's input queue, exactly; none is a sequence gap; the status says so.
#include <gtest/gtest.h>

#include <aerie/pose_t.hpp>
#include <aerie/process_status_t.hpp>

#include <chrono>
#include <map>
#include <thread>

#include "air/capture/capture_node.hpp"
#include "air/capture/source_factory.hpp"
#include "air/stereo/node/vo_node.hpp"

namespace aerie {
namespace {

stereo::VoNodeConfig vo_config(int queue) {
  stereo::VoNodeConfig c;
  c.vo.ba.enabled = false;  // the front end alone: the test is about the queue
  c.depth = "";
  c.queue = queue;
  return c;
}

capture::CaptureConfig capture_config(int frames) {
  capture::CaptureConfig c;
  c.rate = 0;  // as fast as the simulator renders
  c.stop = frames;
  c.source.sim.trajectory = "survey";
  return c;
}

std::map<std::string, int64_t> counters(const aerie::process_status_t& m) {
  std::map<std::string, int64_t> c;
  for (int i = 0; i < m.ncounters; ++i) c[m.counter_names[i]] = m.counter_values[i];
  return c;
}

TEST(CaptureVoQueue, APublisherFasterThanTheOdometryIsAccountedExactly) {
  // Capture publishes all 30 pairs before the node runs once (a stalled odometry): the queue
  // of 4 keeps the newest 4, the other 26 are overflows, none a gap.
  const int n = 30;
  bus::Bus bus("memq://");
  bus::StatusReporter status(bus, "VO");
  std::vector<aerie::pose_t> poses;
  bus.subscribe<aerie::pose_t>("VO_POSE", [&](const aerie::pose_t& p, const auto&) { poses.push_back(p); }, 1000);
  std::map<std::string, int64_t> reported;
  bus.subscribe<aerie::process_status_t>("STATUS_VO", [&](const aerie::process_status_t& m, const auto&) {
    reported = counters(m);
  });
  stereo::VoNode vo(bus, status, vo_config(4), [] { return int64_t{0}; });
  const auto cc = capture_config(n);
  capture::CaptureNode capture(bus, cc, capture::make_source(cc.source_options()));
  ASSERT_EQ(capture.run().published, n);
  while (bus.handle(0) > 0) {
  }
  vo.tick();
  EXPECT_EQ(vo.processed(), 4);
  EXPECT_EQ(vo.queue_overflows(), n - 4);
  EXPECT_EQ(vo.upstream_gaps(), 0);
  EXPECT_EQ(vo.processed() + vo.queue_overflows(), n);
  ASSERT_EQ(poses.size(), 4u);
  EXPECT_EQ(poses.front().seq, n - 4);  // the newest pairs were kept
  EXPECT_EQ(poses.back().seq, n - 1);
  // Named in the status: counters and message.
  status.publish_now();
  while (bus.handle(0) > 0) {
  }
  EXPECT_EQ(reported.at("CAM_STEREO.received"), n);
  EXPECT_EQ(reported.at("CAM_STEREO.queue_overflows"), n - 4);
  EXPECT_EQ(reported.at("CAM_STEREO.sequence_gaps"), 0);
  EXPECT_EQ(reported.at("frames"), 4);
  EXPECT_NE(status.message().find("CAM_STEREO: 26 pairs dropped here (input queue of 4 full"), std::string::npos)
      << status.message();
  EXPECT_NE(status.message().find("0 missing upstream"), std::string::npos) << status.message();
}

TEST(CaptureVoQueue, ConcurrentCaptureAndOdometryLoseNothingUncounted) {
  // The live shape: capture in its own thread as fast as it renders, the node's loop in this one.
  const int n = 60;
  bus::Bus bus("memq://");
  bus::StatusReporter status(bus, "VO");
  stereo::VoNode vo(bus, status, vo_config(2));
  const auto cc = capture_config(n);
  capture::CaptureNode capture(bus, cc, capture::make_source(cc.source_options()));
  int64_t published = 0;
  std::thread producer([&] { published = capture.run().published; });
  // Until every pair is accounted for, or a minute has passed (a lost pair would wait forever).
  const auto deadline = std::chrono::steady_clock::now() + std::chrono::seconds(60);
  while (vo.processed() + vo.queue_overflows() < n && std::chrono::steady_clock::now() < deadline) {
    bus.handle(20);
    vo.tick();
  }
  producer.join();
  while (bus.handle(0) > 0) {
  }
  EXPECT_EQ(published, n);
  EXPECT_EQ(vo.processed() + vo.queue_overflows(), n);
  EXPECT_EQ(vo.upstream_gaps(), 0);
  if (vo.queue_overflows() > 0) {
    EXPECT_NE(status.message().find("pairs dropped here"), std::string::npos) << status.message();
  }
}

}  // namespace
}  // namespace aerie
