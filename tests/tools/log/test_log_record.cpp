// aerie-log record: the recorder keeps a burst that liblcm's default queue of 30 messages
// (lcm-logger's) drops, writes lcm-logger's format byte for byte, and refuses to overwrite.
#include <aerie/gt_pose_t.hpp>
#include <gtest/gtest.h>

#include <chrono>
#include <cstdlib>
#include <filesystem>
#include <thread>
#include <vector>

#include "common/bus/bus.hpp"
#include "common/bus/wire.hpp"
#include "common/logio/event_log.hpp"
#include "tests/support/test_support.hpp"
#include "procman/testbed.hpp"
#include "tools/log/log_record.hpp"

namespace aerie::logtools {
namespace {

namespace fs = std::filesystem;

aerie::gt_pose_t pose(int64_t k) {
  aerie::gt_pose_t m{};
  m.utime = 1'000'000 + k * 5000;
  m.seq = k;
  m.position[0] = 0.01 * static_cast<double>(k);
  m.orientation[0] = 1;
  return m;
}

std::vector<logio::Event> read_log(const fs::path& path) {
  const logio::ReadResult r = logio::read_all(path.string());
  EXPECT_TRUE(r.damage.empty());
  return r.events;
}

}  // namespace

TEST(Recorder, KeepsABurstThatTheDefaultQueueOf30Drops) {
  // UDP multicast in a network namespace of the test's own, as the nodes and lcm-logger use
  // it: liblcm's receive thread takes every datagram off the socket, and queues for a
  // subscription at most its queue capacity until the handling thread comes. 500 messages
  // arrive while the handling thread is busy (here: not called); the socket drops nothing.
  if (const auto why = procman::testbed::namespaces_unavailable(); !why.empty()) GTEST_SKIP() << why;
  procman::testbed::NetNamespace ns(procman::testbed::unique_name("record"));
  procman::testbed::EnterNamespace inside(ns);
  const fs::path dir = test::scratch_dir("record");
  bus::Bus bus("udpm://239.255.76.67:7667?ttl=0");
  Recorder deep(bus, {.path = (dir / "deep.lcm").string(), .queue = 2000});
  Recorder shallow(bus, {.path = (dir / "lcm-logger-like.lcm").string(), .queue = 30});
  for (int64_t k = 0; k < 500; ++k) {
    bus.publish("GT_POSE", pose(k));
    std::this_thread::sleep_for(std::chrono::microseconds(200));  // the receive thread keeps up
  }
  std::this_thread::sleep_for(std::chrono::milliseconds(300));
  while (bus.handle(0) > 0) {
  }
  deep.close();
  shallow.close();
  EXPECT_EQ(deep.events(), 500);
  // liblcm admits one past its capacity; the ~469 others it dropped, with no error anywhere.
  EXPECT_GE(shallow.events(), 30);
  EXPECT_LE(shallow.events(), 31);
  const auto events = read_log(dir / "deep.lcm");
  ASSERT_EQ(events.size(), 500u);
  for (int64_t k = 0; k < 500; ++k) {
    const auto& e = events[k];
    EXPECT_EQ(e.event_number, k);
    EXPECT_EQ(e.channel, "GT_POSE");
    EXPECT_EQ(bus::decode_bounded<aerie::gt_pose_t>(e.data.data(), e.data.size()).seq, k);  // in order, none lost
    if (k > 0) {
      EXPECT_GE(e.utime, events[k - 1].utime);
    }
  }
  EXPECT_EQ(deep.bytes(), static_cast<int64_t>(500 * events[0].data.size()));
}

TEST(Recorder, RecordsOnlyTheChannelsAskedFor) {
  const fs::path dir = test::scratch_dir("record-channels");
  bus::Bus bus("memq://");
  Recorder rec(bus, {.path = (dir / "gt.lcm").string(), .channels = "GT_.*"});
  bus.publish("GT_POSE", pose(1));
  bus.publish("VO_POSE_GT", pose(2));
  bus.publish("GT_POSE2", pose(3));
  while (bus.handle(0) > 0) {
  }
  rec.close();
  const auto events = read_log(dir / "gt.lcm");
  ASSERT_EQ(events.size(), 2u);
  EXPECT_EQ(events[0].channel, "GT_POSE");
  EXPECT_EQ(events[1].channel, "GT_POSE2");
}

TEST(Recorder, RefusesToOverwriteALogAndBadOptions) {
  const fs::path dir = test::scratch_dir("record-refuse");
  const std::string path = (dir / "flight.lcm").string();
  bus::Bus bus("memq://");
  { Recorder first(bus, {.path = path}); }
  try {
    Recorder again(bus, {.path = path});
    FAIL() << "an existing log was overwritten";
  } catch (const std::invalid_argument& e) {
    EXPECT_NE(std::string(e.what()).find("exists; pass --force"), std::string::npos) << e.what();
  }
  EXPECT_NO_THROW(Recorder(bus, {.path = path, .force = true}));
  EXPECT_THROW(Recorder(bus, {.path = (dir / "q.lcm").string(), .queue = -1}), std::invalid_argument);
  EXPECT_FALSE(fs::exists(dir / "q.lcm"));  // refused before the file was created
}

TEST(Recorder, TheCommandRecordsForItsDurationAndRefusesToOverwrite) {
  const fs::path dir = test::scratch_dir("record-cli");
  const std::string log = (dir / "empty.lcm").string();
  const std::string cmd = std::string(AERIE_BINARY_DIR) + "/bin/aerie-log record " + log +
                          " --lcm-url memq:// --duration 0.2 2>/dev/null";
  EXPECT_EQ(std::system(cmd.c_str()), 0);
  EXPECT_TRUE(fs::exists(log));
  EXPECT_EQ(fs::file_size(log), 0u);  // nothing on this process's memq://
  EXPECT_NE(std::system(cmd.c_str()), 0);  // exists: refused without --force
}

}  // namespace aerie::logtools
