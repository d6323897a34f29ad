// The link's hop from an air log and a ground log (aerie-latency AIR GROUND): messages matched
// by channel and source utime, the direction found from which side logs first, losses counted.
#include <aerie/pose_t.hpp>
#include <gtest/gtest.h>

#include <vector>

#include "tools/latency/link_hops.hpp"

using namespace aerie;
using Log = latency::LinkJoin::Log;

namespace {

std::vector<uint8_t> encoded(int64_t utime) {
  aerie::pose_t m{};
  m.utime = utime;
  std::vector<uint8_t> b(static_cast<size_t>(m.getEncodedSize()));
  m.encode(b.data(), 0, static_cast<int>(b.size()));
  return b;
}

void add(latency::LinkJoin& j, Log log, const std::string& channel, int64_t log_utime, int64_t utime) {
  const auto b = encoded(utime);
  j.add(log, channel, log_utime, b.data(), b.size());
}

}  // namespace

TEST(LinkHops, LatencyDirectionAndLossesPerChannel) {
  latency::LinkJoin j;
  for (int i = 0; i < 100; ++i) {
    const int64_t u = 1'000'000 + i * 50'000;
    add(j, Log::kAir, "CAM_DOWN", u + 2000, u);                           // logged on the air 2 ms after capture
    if (i % 10 != 3) add(j, Log::kGround, "CAM_DOWN", u + 122000, u);     // 120 ms later on the ground; 10 % lost
    add(j, Log::kGround, "CTRL_CMD", u + 130000, u);                      // sent from the ground
    add(j, Log::kAir, "CTRL_CMD", u + 180000, u);                         // 50 ms up
    add(j, Log::kAir, "IMU", u, u);                                       // air only: does not cross
  }
  const auto hops = j.hops();
  ASSERT_EQ(hops.size(), 2u);
  EXPECT_EQ(hops[0].channel, "CAM_DOWN");
  EXPECT_EQ(hops[0].direction, "air->ground");
  EXPECT_EQ(hops[0].sent, 100);
  EXPECT_EQ(hops[0].delivered, 90);
  EXPECT_DOUBLE_EQ(hops[0].latency_ms.median, 120.0);
  EXPECT_EQ(hops[1].channel, "CTRL_CMD");
  EXPECT_EQ(hops[1].direction, "ground->air");
  EXPECT_EQ(hops[1].delivered, 100);
  EXPECT_DOUBLE_EQ(hops[1].latency_ms.max, 50.0);
}

TEST(LinkHops, EqualTimesFallBackOnCountsThenTheHint) {
  latency::LinkJoin j;
  for (int i = 0; i < 10; ++i) {
    add(j, Log::kGround, "UP", i, i + 1);        // zero delay, one lost on the way up
    if (i) add(j, Log::kAir, "UP", i, i + 1);
    add(j, Log::kGround, "TIE", i, i + 1);
    add(j, Log::kAir, "TIE", i, i + 1);
  }
  j.hint("TIE", false);
  const auto hops = j.hops();
  ASSERT_EQ(hops.size(), 2u);
  EXPECT_EQ(hops[0].channel, "TIE");
  EXPECT_EQ(hops[0].direction, "ground->air");
  EXPECT_EQ(hops[1].direction, "ground->air");
  EXPECT_EQ(hops[1].sent, 10);
  EXPECT_EQ(hops[1].delivered, 9);
}
