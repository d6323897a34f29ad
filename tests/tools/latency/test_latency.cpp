// aerie-latency: order statistics, per-channel latency from a log (receive time -
// utime), unstamped / other-clock / negative cases, per-hop figures from STATUS_*
// heartbeats, and the executable on a written log.
#include <aerie/image_t.hpp>
#include <aerie/pose_t.hpp>
#include <aerie/process_status_t.hpp>
#include <gtest/gtest.h>

#include <fstream>
#include <sstream>

#include "common/logio/event_log.hpp"
#include "procman/testbed.hpp"
#include "tests/support/test_support.hpp"
#include "tools/latency/latency.hpp"

using namespace aerie;
using namespace aerie::latency;

namespace {

template <typename Msg>
std::vector<uint8_t> bytes(const Msg& m) {
  std::vector<uint8_t> b(static_cast<size_t>(m.getEncodedSize()));
  m.encode(b.data(), 0, static_cast<int>(b.size()));
  return b;
}

aerie::pose_t pose(int64_t utime) {
  aerie::pose_t p{};
  p.utime = utime;
  p.seq = 0;
  return p;
}

aerie::process_status_t status(const std::string& node, int64_t source, int64_t receive, int64_t publish) {
  aerie::process_status_t s{};
  s.utime = publish + 1000;
  s.node = node;
  s.ncounters = s.ntimings = 0;
  s.last_source_utime = source;
  s.last_receive_utime = receive;
  s.last_publish_utime = publish;
  return s;
}

const int64_t kT0 = 1'700'000'000'000'000;  // a wall-clock time (2023)

}  // namespace

TEST(LatencyStats, PercentilesInterpolate) {
  std::vector<double> v;
  for (int i = 100; i >= 1; --i) v.push_back(i);
  const Summary s = summarize(v);
  EXPECT_EQ(s.count, 100);
  EXPECT_DOUBLE_EQ(s.min, 1);
  EXPECT_DOUBLE_EQ(s.max, 100);
  EXPECT_DOUBLE_EQ(s.mean, 50.5);
  EXPECT_DOUBLE_EQ(s.median, 50.5);
  EXPECT_NEAR(s.p90, 90.1, 1e-9);
  EXPECT_NEAR(s.p99, 99.01, 1e-9);
  EXPECT_EQ(summarize({}).count, 0);
  EXPECT_DOUBLE_EQ(summarize({7}).p99, 7);
}

TEST(LatencyAnalysis, PerChannelLatencyIsReceiveMinusUtime) {
  LatencyAnalysis a;
  for (int i = 0; i < 100; ++i) {
    const auto b = bytes(pose(kT0 + i * 50'000));
    a.add("VO_POSE", kT0 + i * 50'000 + 1000 * (i + 1), b.data(), b.size());  // 1..100 ms
  }
  const auto ch = a.channels();
  ASSERT_EQ(ch.size(), 1u);
  EXPECT_EQ(ch[0].channel, "VO_POSE");
  EXPECT_EQ(ch[0].type, "aerie.pose_t");
  EXPECT_EQ(ch[0].messages, 100);
  EXPECT_DOUBLE_EQ(ch[0].latency_ms.median, 50.5);
  EXPECT_DOUBLE_EQ(ch[0].latency_ms.max, 100.0);
  EXPECT_EQ(ch[0].negative, 0);
}

TEST(LatencyAnalysis, FlagsWhatCannotBeMeasured) {
  LatencyAnalysis a;
  const auto old = bytes(pose(1'300'000'000'000'000));  // a dataset stamped in 2011
  a.add("CAM_LEFT", kT0, old.data(), old.size());
  const auto early = bytes(pose(kT0 + 3000));           // stamped after it was received
  a.add("CAM_LEFT", kT0, early.data(), early.size());
  const std::vector<uint8_t> junk(40, 0x42);            // not an Aerie type
  a.add("OTHER", kT0, junk.data(), junk.size());
  const auto ch = a.channels();
  ASSERT_EQ(ch.size(), 2u);
  EXPECT_EQ(ch[0].channel, "CAM_LEFT");
  EXPECT_EQ(ch[0].other_clock, 1);
  EXPECT_EQ(ch[0].negative, 1);
  EXPECT_EQ(ch[0].latency_ms.count, 1);
  EXPECT_DOUBLE_EQ(ch[0].latency_ms.median, -3.0);
  EXPECT_EQ(ch[1].channel, "OTHER");
  EXPECT_EQ(ch[1].unstamped, 1);
  EXPECT_EQ(ch[1].latency_ms.count, 0);
  // With --unknown-types the first 8 bytes after the fingerprint are taken as utime.
  LatencyAnalysis u({".*", true});
  u.add("OTHER", kT0, junk.data(), junk.size());
  EXPECT_EQ(u.channels()[0].unstamped, 0);
  const std::string table = format_table(a.channels(), a.hops());
  EXPECT_NE(table.find("another clock"), std::string::npos) << table;
  EXPECT_NE(table.find("clocks differ"), std::string::npos) << table;
}

TEST(LatencyAnalysis, ChannelFilter) {
  LatencyAnalysis a({"CAM_.*", false});
  const auto b = bytes(pose(kT0));
  a.add("CAM_LEFT", kT0 + 1000, b.data(), b.size());
  a.add("VO_POSE", kT0 + 1000, b.data(), b.size());
  ASSERT_EQ(a.channels().size(), 1u);
  EXPECT_EQ(a.channels()[0].channel, "CAM_LEFT");
  EXPECT_EQ(a.events(), 2);
}

TEST(LatencyAnalysis, PerHopFromStatusHeartbeats) {
  LatencyAnalysis a;
  // Each heartbeat: input 10+i ms, processing 5 ms; the repeated one counts once.
  for (int i = 0; i < 5; ++i) {
    const int64_t src = kT0 + i * 1'000'000;
    const auto b = bytes(status("vo", src, src + (10 + i) * 1000, src + (15 + i) * 1000));
    a.add("STATUS_VO", src + 20'000, b.data(), b.size());
    if (i == 4) a.add("STATUS_VO", src + 1'020'000, b.data(), b.size());
  }
  const auto idle = bytes(status("map", 0, 0, 0));  // no hop recorded yet
  a.add("STATUS_MAP", kT0, idle.data(), idle.size());
  const auto hops = a.hops();
  ASSERT_EQ(hops.size(), 1u);
  EXPECT_EQ(hops[0].node, "vo");
  EXPECT_EQ(hops[0].input_ms.count, 5);
  EXPECT_DOUBLE_EQ(hops[0].input_ms.median, 12.0);
  EXPECT_DOUBLE_EQ(hops[0].processing_ms.median, 5.0);
  EXPECT_DOUBLE_EQ(hops[0].processing_ms.max, 5.0);
  EXPECT_DOUBLE_EQ(hops[0].age_ms.max, 19.0);
  const std::string json = to_json(a.channels(), hops);
  EXPECT_NE(json.find("\"node\": \"vo\""), std::string::npos) << json;
}

TEST(LatencyTool, ReadsALogAndWritesCsvAndJson) {
  const auto dir = test::scratch_dir("latency");
  const std::string log = (dir / "flight.lcm").string();
  {
    logio::Writer w(log);
    for (int i = 0; i < 50; ++i) {
      aerie::image_t img{};
      img.utime = kT0 + i * 33'333;
      img.width = img.height = img.row_stride = 1;
      img.pixelformat = aerie::image_t::PIXEL_FORMAT_GRAY;
      img.size = 1;
      img.data = {7};
      img.nmetadata = 0;
      const auto b = bytes(img);
      w.write(img.utime + 2000, "CAM_LEFT", b.data(), b.size());  // 2 ms
    }
    const auto s = bytes(status("track", kT0, kT0 + 3000, kT0 + 8000));
    w.write(kT0 + 9000, "STATUS_TRACK", s.data(), s.size());
  }
  const std::string csv = (dir / "lat.csv").string(), json = (dir / "lat.json").string();
  const std::string out = procman::testbed::run(
      {(test::binary_dir() / "bin" / "aerie-latency").string(), log, "--csv", csv, "--json", json});
  EXPECT_NE(out.find("51 events"), std::string::npos) << out;
  EXPECT_NE(out.find("CAM_LEFT"), std::string::npos) << out;
  std::stringstream ss;
  ss << std::ifstream(csv).rdbuf();
  const std::string text = ss.str();
  EXPECT_NE(text.find("channel,CAM_LEFT,aerie.image_t,50,2.000,2.000,2.000,2.000,2.000,2.000,0,0,0"), std::string::npos)
      << text;
  EXPECT_NE(text.find("hop_processing,track,,1,5.000"), std::string::npos) << text;
  std::stringstream js;
  js << std::ifstream(json).rdbuf();
  EXPECT_NE(js.str().find("\"channel\": \"CAM_LEFT\""), std::string::npos);
  EXPECT_THROW(procman::testbed::run({(test::binary_dir() / "bin" / "aerie-latency").string(), "/nonexistent.lcm"}),
               std::runtime_error);
}

// Recorded data (source_clock.hpp): EuRoC stamps its frames with its own 2014 clock. The
// camera's arrival is the reference; downstream channels and hops are measured from it.
TEST(LatencyAnalysis, DatasetStampedMessagesAreMeasuredFromTheFramesFirstArrival) {
  const int64_t kDataset = 1'403'715'273'262'142;  // EuRoC V1_01 (2014), µs
  LatencyAnalysis a;
  for (int i = 0; i < 20; ++i) {
    const int64_t frame = kDataset + i * 50'000, arrival = kT0 + i * 50'000;
    const auto cam = bytes(pose(frame)), vo = bytes(pose(frame)), ctl = bytes(pose(frame));
    a.add("CAM_STEREO", arrival, cam.data(), cam.size());
    a.add("VO_POSE", arrival + 1000 * (10 + i % 5), vo.data(), vo.size());  // 10..14 ms after the frame
    a.add("CTRL_CMD", arrival + 30'000, ctl.data(), ctl.size());
    // aerie-vo's heartbeat: received 2 ms after the camera's arrival, published 11 ms later.
    const auto st = bytes(status("vo", frame, arrival + 2000, arrival + 13'000));
    a.add("STATUS_VO", arrival + 40'000, st.data(), st.size());
  }
  const auto ch = a.channels();
  ASSERT_EQ(ch.size(), 4u);  // CAM_STEREO, CTRL_CMD, STATUS_VO, VO_POSE
  EXPECT_EQ(ch[0].channel, "CAM_STEREO");
  EXPECT_EQ(ch[0].other_clock, 20);
  EXPECT_EQ(ch[0].references, 20);         // the reference: no latency of its own
  EXPECT_EQ(ch[0].latency_ms.count, 0);
  EXPECT_EQ(ch[1].channel, "CTRL_CMD");
  EXPECT_EQ(ch[1].latency_ms.count, 20);
  EXPECT_DOUBLE_EQ(ch[1].latency_ms.max, 30.0);
  EXPECT_EQ(ch[1].reference, "CAM_STEREO");
  EXPECT_EQ(ch[3].channel, "VO_POSE");
  EXPECT_EQ(ch[3].other_clock, 20);
  EXPECT_EQ(ch[3].latency_ms.count, 20);
  EXPECT_DOUBLE_EQ(ch[3].latency_ms.min, 10.0);
  EXPECT_DOUBLE_EQ(ch[3].latency_ms.median, 12.0);
  EXPECT_DOUBLE_EQ(ch[3].latency_ms.max, 14.0);
  EXPECT_EQ(ch[3].negative, 0);
  const auto hops = a.hops();
  ASSERT_EQ(hops.size(), 1u);
  EXPECT_TRUE(hops[0].source_clock);
  EXPECT_EQ(hops[0].input_ms.count, 20);
  EXPECT_DOUBLE_EQ(hops[0].input_ms.median, 2.0);
  EXPECT_DOUBLE_EQ(hops[0].processing_ms.median, 11.0);
  EXPECT_DOUBLE_EQ(hops[0].age_ms.max, 13.0);
  const std::string table = format_table(ch, hops);
  EXPECT_NE(table.find("latency from the frame's first arrival on CAM_STEREO"), std::string::npos) << table;
  EXPECT_EQ(table.find("e+"), std::string::npos) << table;  // never a latency of years
}

TEST(LatencyAnalysis, WallStampedMessagesAreReceiveMinusUtimeAsBefore) {
  // The same chain live: stamps on the wall clock, so the camera has a latency of its own.
  LatencyAnalysis a;
  for (int i = 0; i < 10; ++i) {
    const int64_t frame = kT0 + i * 50'000;
    const auto cam = bytes(pose(frame)), vo = bytes(pose(frame));
    a.add("CAM_STEREO", frame + 4000, cam.data(), cam.size());
    a.add("VO_POSE", frame + 16'000, vo.data(), vo.size());
  }
  const auto ch = a.channels();
  ASSERT_EQ(ch.size(), 2u);
  EXPECT_EQ(ch[0].other_clock + ch[0].references + ch[1].other_clock, 0);
  EXPECT_DOUBLE_EQ(ch[0].latency_ms.median, 4.0);
  EXPECT_DOUBLE_EQ(ch[1].latency_ms.median, 16.0);
  EXPECT_EQ(ch[1].reference, "");
}

TEST(SourceClock, TheRuleAtItsBoundary) {
  FrameArrivals arrivals;
  EXPECT_TRUE(on_receive_clock(kT0, kT0 + kOtherClockUs));
  EXPECT_FALSE(on_receive_clock(kT0, kT0 + kOtherClockUs + 1));
  EXPECT_FALSE(on_receive_clock(kT0 + kOtherClockUs + 1, kT0));
  // Another clock: the first arrival is the reference, later ones are measured from it.
  EXPECT_FALSE(measure(arrivals, "CAM_STEREO", 42, kT0));
  const auto m = measure(arrivals, "VO_POSE", 42, kT0 + 7500);
  ASSERT_TRUE(m);
  EXPECT_TRUE(m->source_clock);
  EXPECT_DOUBLE_EQ(m->ms, 7.5);
  EXPECT_EQ(m->reference, "CAM_STEREO");
  // Old frames are forgotten beyond the capacity.
  FrameArrivals small(2);
  small.note(1, kT0, "A");
  small.note(2, kT0, "A");
  small.note(3, kT0, "A");
  EXPECT_EQ(small.find(1), nullptr);
  ASSERT_NE(small.find(3), nullptr);
}
