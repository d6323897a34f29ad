// The LCM event-log reader/writer: byte-exact round trip, the header layout of the
// standard format, and precise reports on truncated and corrupt logs.
#include <gtest/gtest.h>

#include <filesystem>
#include <fstream>
#include <iterator>
#include <limits>

#include "common/logio/event_log.hpp"
#include "tests/support/test_support.hpp"

namespace aerie::logio {
namespace {

std::vector<uint8_t> payload(int i) {
  std::vector<uint8_t> v(static_cast<size_t>(37 * i + 5));
  for (size_t k = 0; k < v.size(); ++k) v[k] = static_cast<uint8_t>((k * 31 + static_cast<size_t>(i)) & 0xff);
  return v;
}

// Ten events on two channels; returns the byte offset of every event header.
std::vector<uint64_t> write_log(const std::filesystem::path& path, int n = 10) {
  Writer w(path.string());
  std::vector<uint64_t> offsets;
  uint64_t off = 0;
  for (int i = 0; i < n; ++i) {
    const std::string ch = i % 2 ? "CAM_LEFT" : "GT_POSE";
    const auto p = payload(i);
    w.write(1'000'000 + 50'000 * i, ch, p.data(), p.size());
    offsets.push_back(off);
    off += kHeaderSize + ch.size() + p.size();
  }
  w.close();
  return offsets;
}

std::vector<uint8_t> slurp(const std::filesystem::path& p) {
  std::ifstream in(p, std::ios::binary);
  return {std::istreambuf_iterator<char>(in), {}};
}
void dump(const std::filesystem::path& p, const std::vector<uint8_t>& bytes) {
  std::ofstream out(p, std::ios::binary | std::ios::trunc);
  out.write(reinterpret_cast<const char*>(bytes.data()), static_cast<std::streamsize>(bytes.size()));
}

TEST(EventLog, RoundTripIsIdentical) {
  const auto dir = test::scratch_dir("log");
  const auto offsets = write_log(dir / "a.lcm");
  const auto r = read_all((dir / "a.lcm").string());
  EXPECT_TRUE(r.damage.empty());
  ASSERT_EQ(r.events.size(), 10u);
  for (int i = 0; i < 10; ++i) {
    const auto& ev = r.events[static_cast<size_t>(i)];
    EXPECT_EQ(ev.event_number, i);
    EXPECT_EQ(ev.utime, 1'000'000 + 50'000 * i);
    EXPECT_EQ(ev.channel, i % 2 ? "CAM_LEFT" : "GT_POSE");
    EXPECT_EQ(ev.data, payload(i));
    EXPECT_EQ(ev.offset, offsets[static_cast<size_t>(i)]);
  }
  // Writing what was read gives the same bytes again.
  Writer w((dir / "b.lcm").string());
  for (const auto& ev : r.events) w.write(ev, true);
  w.close();
  EXPECT_EQ(slurp(dir / "a.lcm"), slurp(dir / "b.lcm"));
}

// The event counter is a u64 on disk: numbers written as kept go on past INT64_MAX by wrapping
// (found by fuzz_event_log: the reader's expected next number overflowed), and a damage report
// after such an event names the wrapped number.
TEST(EventLog, EventNumbersWrapPastInt64Max) {
  const auto dir = test::scratch_dir("log");
  const int64_t max = std::numeric_limits<int64_t>::max();
  {
    Writer w((dir / "w.lcm").string());
    Event ev;
    ev.event_number = max - 1;
    ev.utime = 1;
    ev.channel = "GT_POSE";
    ev.data = payload(1);
    w.write(ev, true);
    w.write(2, "GT_POSE", ev.data.data(), ev.data.size());  // max
    w.write(3, "GT_POSE", ev.data.data(), ev.data.size());  // wraps
  }
  auto bytes = slurp(dir / "w.lcm");
  const auto r = read_all((dir / "w.lcm").string());
  EXPECT_TRUE(r.damage.empty());
  ASSERT_EQ(r.events.size(), 3u);
  EXPECT_EQ(r.events[1].event_number, max);
  EXPECT_EQ(r.events[2].event_number, std::numeric_limits<int64_t>::min());
  // Cut inside the third event: the damage names the number expected after INT64_MAX.
  bytes.resize(bytes.size() - 2);
  dump(dir / "t.lcm", bytes);
  const auto t = read_all((dir / "t.lcm").string());
  ASSERT_EQ(t.events.size(), 2u);
  ASSERT_EQ(t.damage.size(), 1u);
  EXPECT_EQ(t.damage[0].event_number, std::numeric_limits<int64_t>::min());
}

TEST(EventLog, HeaderIsBigEndianLcmLayout) {
  const auto dir = test::scratch_dir("log");
  {
    Writer w((dir / "h.lcm").string());
    const uint8_t data[3] = {7, 8, 9};
    w.write(0x0102030405060708, "AB", data, 3);
  }
  const auto b = slurp(dir / "h.lcm");
  const std::vector<uint8_t> expect = {0xED, 0xA1, 0xDA, 0x01,  0, 0, 0, 0, 0, 0, 0, 0,  // sync, event 0
                                       1, 2, 3, 4, 5, 6, 7, 8,                          // utime
                                       0, 0, 0, 2,  0, 0, 0, 3,                         // lengths
                                       'A', 'B', 7, 8, 9};
  EXPECT_EQ(b, expect);
}

TEST(EventLog, EmptyLogHasNoEventsAndNoDamage) {
  const auto dir = test::scratch_dir("log");
  dump(dir / "e.lcm", {});
  const auto r = read_all((dir / "e.lcm").string());
  EXPECT_TRUE(r.events.empty());
  EXPECT_TRUE(r.damage.empty());
}

TEST(EventLog, MissingFileNamesIt) {
  try {
    Reader r("/nonexistent/flight.lcm");
    FAIL() << "no exception";
  } catch (const std::runtime_error& e) {
    EXPECT_NE(std::string(e.what()).find("/nonexistent/flight.lcm"), std::string::npos);
  }
}

// Cut in the middle of event 6's payload: events 0..5 come back, the damage names
// event 6 and the byte offset where it starts.
TEST(EventLog, TruncatedMidEventReturnsAllPriorEvents) {
  const auto dir = test::scratch_dir("log");
  const auto offsets = write_log(dir / "a.lcm");
  auto bytes = slurp(dir / "a.lcm");
  bytes.resize(offsets[6] + kHeaderSize + 5);
  dump(dir / "t.lcm", bytes);
  const auto r = read_all((dir / "t.lcm").string());
  ASSERT_EQ(r.events.size(), 6u);
  EXPECT_EQ(r.events.back().data, payload(5));
  ASSERT_EQ(r.damage.size(), 1u);
  EXPECT_EQ(r.damage[0].kind, Damage::Kind::Truncated);
  EXPECT_EQ(r.damage[0].offset, offsets[6]);
  EXPECT_EQ(r.damage[0].event_number, 6);
  EXPECT_NE(r.damage[0].message.find("byte " + std::to_string(offsets[6])), std::string::npos) << r.damage[0].message;
  EXPECT_NE(r.damage[0].message.find("event 6"), std::string::npos);
  EXPECT_NE(r.damage[0].message.find("t.lcm"), std::string::npos);
}

TEST(EventLog, TruncatedInsideHeader) {
  const auto dir = test::scratch_dir("log");
  const auto offsets = write_log(dir / "a.lcm");
  auto bytes = slurp(dir / "a.lcm");
  bytes.resize(offsets[9] + 10);
  dump(dir / "t.lcm", bytes);
  const auto r = read_all((dir / "t.lcm").string());
  EXPECT_EQ(r.events.size(), 9u);
  ASSERT_EQ(r.damage.size(), 1u);
  EXPECT_EQ(r.damage[0].kind, Damage::Kind::Truncated);
  EXPECT_EQ(r.damage[0].offset, offsets[9]);
}

TEST(EventLog, CorruptSyncStopsOrResynchronises) {
  const auto dir = test::scratch_dir("log");
  const auto offsets = write_log(dir / "a.lcm");
  auto bytes = slurp(dir / "a.lcm");
  bytes[offsets[4] + 1] ^= 0x5a;  // event 4's sync word
  dump(dir / "c.lcm", bytes);

  const auto stop = read_all((dir / "c.lcm").string());
  ASSERT_EQ(stop.events.size(), 4u);
  ASSERT_EQ(stop.damage.size(), 1u);
  EXPECT_EQ(stop.damage[0].kind, Damage::Kind::BadSync);
  EXPECT_EQ(stop.damage[0].offset, offsets[4]);
  EXPECT_EQ(stop.damage[0].event_number, 4);

  const auto re = read_all((dir / "c.lcm").string(), {.resync = true});
  ASSERT_EQ(re.events.size(), 9u);  // all but event 4
  EXPECT_EQ(re.events[4].event_number, 5);
  EXPECT_EQ(re.events[4].data, payload(5));
  ASSERT_EQ(re.damage.size(), 1u);
  EXPECT_EQ(re.damage[0].skipped, offsets[5] - offsets[4]);
}

TEST(EventLog, ImplausibleLengthIsReportedAndSkipped) {
  const auto dir = test::scratch_dir("log");
  const auto offsets = write_log(dir / "a.lcm");
  auto bytes = slurp(dir / "a.lcm");
  bytes[offsets[2] + 20] = 0x7f;  // channel length of event 2 becomes huge
  dump(dir / "c.lcm", bytes);
  const auto re = read_all((dir / "c.lcm").string(), {.resync = true});
  EXPECT_EQ(re.events.size(), 9u);
  ASSERT_EQ(re.damage.size(), 1u);
  EXPECT_EQ(re.damage[0].kind, Damage::Kind::BadHeader);
  EXPECT_EQ(re.damage[0].offset, offsets[2]);
  EXPECT_NE(re.damage[0].message.find("channel length"), std::string::npos);
}

// Garbage appended after a good log: a length that runs past the end is corruption
// when a later event exists, truncation when none does.
TEST(EventLog, TrailingGarbageIsReported) {
  const auto dir = test::scratch_dir("log");
  write_log(dir / "a.lcm", 3);
  auto bytes = slurp(dir / "a.lcm");
  const auto end = bytes.size();
  bytes.insert(bytes.end(), {1, 2, 3, 4, 5, 6, 7});
  dump(dir / "g.lcm", bytes);
  const auto r = read_all((dir / "g.lcm").string(), {.resync = true});
  EXPECT_EQ(r.events.size(), 3u);
  ASSERT_EQ(r.damage.size(), 1u);
  EXPECT_EQ(r.damage[0].offset, end);
  EXPECT_NE(r.damage[0].message.find("no further event"), std::string::npos);
}

TEST(EventLog, WriterRejectsBadChannel) {
  const auto dir = test::scratch_dir("log");
  Writer w((dir / "w.lcm").string());
  EXPECT_THROW(w.write(0, "", nullptr, 0), std::invalid_argument);
}

}  // namespace
}  // namespace aerie::logio
