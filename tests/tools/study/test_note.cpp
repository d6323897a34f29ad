// tools/study/note.hpp and the link study's RunRow note: values come back exactly (NaN, the
// infinities, the smallest subnormal, strings with spaces, colons and newlines), a note that
// holds other values is refused naming it, and a RunRow survives the trip field for field.
#include <gtest/gtest.h>

#include <cmath>
#include <limits>

#include "tools/linkstudy/study.hpp"
#include "tools/study/note.hpp"

using namespace aerie;

TEST(StudyNote, ValuesComeBackExactly) {
  const double values[] = {0.1, -1.0 / 3.0, 6.02214076e23, std::numeric_limits<double>::denorm_min(),
                           std::numeric_limits<double>::max(), std::numeric_limits<double>::infinity(),
                           -std::numeric_limits<double>::infinity(), -0.0};
  study::NoteWriter w;
  for (double v : values) w.real(v);
  w.real(std::nan("")).integer(std::numeric_limits<int64_t>::min()).text("a b:c\nd ").text("");
  study::NoteReader r(w.str(), "the note");
  for (double v : values) {
    const double got = r.real();
    EXPECT_EQ(got, v);
    EXPECT_EQ(std::signbit(got), std::signbit(v));
  }
  EXPECT_TRUE(std::isnan(r.real()));
  EXPECT_EQ(r.integer(), std::numeric_limits<int64_t>::min());
  EXPECT_EQ(r.text(), "a b:c\nd ");
  EXPECT_EQ(r.text(), "");
  EXPECT_NO_THROW(r.end());
}

TEST(StudyNote, ANoteWithOtherValuesIsRefusedNamingIt) {
  auto refusal = [](const std::string& note, auto read) {
    try {
      study::NoteReader r(note, "run 3's note");
      read(r);
    } catch (const std::runtime_error& e) {
      return std::string(e.what());
    }
    return std::string("(accepted)");
  };
  EXPECT_EQ(refusal("1.5 ", [](auto& r) { r.integer(); }), "run 3's note is malformed at byte 4: expected an integer, got '1.5'");
  EXPECT_EQ(refusal("x ", [](auto& r) { r.real(); }), "run 3's note is malformed at byte 2: expected a number, got 'x'");
  EXPECT_EQ(refusal("1 ", [](auto& r) { r.integer(), r.integer(); }),
            "run 3's note is malformed at byte 2: expected another value, the note ends");
  EXPECT_EQ(refusal("9:abc ", [](auto& r) { r.text(); }),
            "run 3's note is malformed at byte 0: expected <length>:<bytes>, got '9:abc '");
  EXPECT_EQ(refusal("1 2 ", [](auto& r) { r.integer(), r.end(); }), "run 3's note is malformed at byte 2: 2 bytes left over");
}

TEST(StudyNote, ALinkStudyRowSurvivesTheTripFieldForField) {
  linkstudy::RunRow row;
  row.success = true;
  row.metric = "touchdown_error_m";
  row.value = 0.123456789012345;
  row.touchdown_error_m = 0.123456789012345;
  row.yaw_error_deg = 1.0 / 3.0;
  row.time_s = 17.25;
  row.losses = 3;
  row.target_rmse_xy_m = std::nan("");
  row.heading_rmse_deg = -1;
  row.frames_visible = 412;
  row.frames_lost = 7;
  row.entered_danger = true;
  row.view_age_p50_ms = 101.5;
  row.view_age_p95_ms = 310.25;
  row.view_messages = 999;
  row.pilot_stale_holds = 2;
  row.control_fallbacks = 1;
  row.down = {10, 9, 123456, 1, 0, 0, 0, 4};
  row.up = {20, 18, 654, 0, 2, 0, 0, 0};
  row.hops.push_back({"CAMERA_LEFT", "air->ground", {9, 1.5, 2.25, 2.0, 3.0, 3.5, 4.0}, 10, 9});
  row.hops.push_back({"CTRL_CMD with space", "ground->air", {}, 5, 0});
  row.down_kbit_s = 812.3;
  row.up_kbit_s = 3.1;
  row.final_state = "LANDED";
  row.faults.counters = {1, 1, 40, 2};
  row.faults.applied = "kill:track@6.5+1";
  row.faults.stalled_frames = 5;
  row.faults.command_timeouts = 1;
  row.faults.malformed = 8;
  row.sim_s = 21.5;
  row.wall_s = 3.75;
  const linkstudy::RunRow back = linkstudy::row_from_note(linkstudy::row_note(row), "the note");
  linkstudy::Condition c;
  linkstudy::Placement p{"onboard", {}};
  const linkstudy::RunSpec spec{&c, &p, linkstudy::Workload::kLanding, "amcmr-ct", 4, "kill:track@6.5+1"};
  EXPECT_EQ(linkstudy::csv_row("delay_ms", spec, back), linkstudy::csv_row("delay_ms", spec, row));
  EXPECT_TRUE(std::isnan(back.target_rmse_xy_m));
  EXPECT_EQ(back.down.bytes_delivered, 123456);  // not in the CSV: the report's kbit/s come from it
  EXPECT_EQ(back.down.reencoded, 4);
  ASSERT_EQ(back.hops.size(), 2u);
  EXPECT_EQ(back.hops[0].channel, "CAMERA_LEFT");
  EXPECT_EQ(back.hops[0].latency_ms.median, 2.0);
  EXPECT_EQ(back.hops[0].latency_ms.max, 4.0);
  EXPECT_EQ(back.hops[1].channel, "CTRL_CMD with space");
  EXPECT_EQ(back.hops[1].direction, "ground->air");
  EXPECT_EQ(back.hops[1].sent, 5);
  EXPECT_EQ(back.wall_s, 3.75);
  EXPECT_THROW(linkstudy::row_from_note(linkstudy::row_note(row) + "1 ", "the note"), std::runtime_error);
}
