// aerie-cmd's messages (tools/cmd/command.hpp): what the operator types -> the message the
// viewer would send, each bad value refused naming it, and the rules of "took effect".
#include <gtest/gtest.h>

#include <unistd.h>

#include <algorithm>
#include <string>
#include <vector>

#include "air/track/factory.hpp"
#include "tests/support/test_support.hpp"
#include "tools/cmd/command.hpp"

using namespace aerie::cmd;

TEST(CmdBox, ParsesFourNumbers) {
  const Box b = parse_box("10,20.5,30,40.25");
  EXPECT_EQ(b.x, 10);
  EXPECT_EQ(b.y, 20.5);
  EXPECT_EQ(b.width, 30);
  EXPECT_EQ(b.height, 40.25);
  const Box corner = parse_box("0,0,1,1");
  EXPECT_EQ(corner.x, 0);
  EXPECT_EQ(corner.height, 1);
}

TEST(CmdBox, RefusesWhatIsNotFourPositiveNumbers) {
  aerie::test::expect_refusals([](const std::string& t) { parse_box(t); },
                               {{"10,20,30", "--box '10,20,30': expected four numbers X,Y,W,H"},
                                {"10,20,30", "got 3"},
                                {"10,20,30,40,50", "got more than four"},
                                {"", "'' is not a number"},
                                {"10,20,,40", "'' is not a number"},
                                {"10,twenty,30,40", "'twenty' is not a number"},
                                {"10,20,30,40px", "'40px' is not a number"},
                                {" 10,20,30,40", "' 10' is not a number"},
                                {"10,20,30,nan", "'nan' is not a number"},
                                {"10,20,30,inf", "'inf' is not a number"},
                                {"-1,20,30,40", "X = -1"},
                                {"10,-0.5,30,40", "Y = -0.5"},
                                {"10,20,0,40", "W = 0"},
                                {"10,20,30,-4", "H = -4"}});
}

TEST(CmdTracker, KnowsEveryNameOfTheFactoryAndRefusesOthers) {
  for (const auto& n : aerie::track::aerie_tracker_names()) EXPECT_EQ(check_tracker(n), n);
  for (const auto& n : aerie::track::opencv_tracker_names()) EXPECT_EQ(check_tracker(n), n);
  EXPECT_EQ(check_tracker("eco"), "eco");
  const std::string e = aerie::test::refusal([](const std::string& t) { check_tracker(t); }, "kcf2");
  EXPECT_NE(e.find("--tracker 'kcf2': unknown tracker (known: "), std::string::npos) << e;
  for (const auto& n : aerie::track::aerie_tracker_names()) EXPECT_NE(e.find(n), std::string::npos) << n << ": " << e;
  EXPECT_NE(e.find("opencv-kcf"), std::string::npos) << e;
}

TEST(CmdTrack, BuildsTheViewersMessage) {
  const auto c = track_command(aerie::track_cmd_t::INIT, "ct", "CAM_DOWN", Box{1, 2, 3, 4}, 123, 7);
  EXPECT_EQ(c.utime, 123);
  EXPECT_EQ(c.seq, 7);
  EXPECT_EQ(c.command, aerie::track_cmd_t::INIT);
  EXPECT_EQ(c.tracker, "ct");
  EXPECT_EQ(c.camera, "CAM_DOWN");
  EXPECT_EQ(c.x, 1);
  EXPECT_EQ(c.y, 2);
  EXPECT_EQ(c.width, 3);
  EXPECT_EQ(c.height, 4);
  EXPECT_EQ(c.nparams, 0);
  EXPECT_TRUE(c.param_names.empty());
  const auto stop = track_command(aerie::track_cmd_t::STOP, "", "", std::nullopt, 5, 0);
  EXPECT_EQ(stop.command, aerie::track_cmd_t::STOP);
  EXPECT_EQ(stop.x, 0);
  EXPECT_EQ(stop.width, 0);
  EXPECT_EQ(describe(Command{"TRACK_CMD", c}), "TRACK_CMD INIT tracker=ct camera=CAM_DOWN box=(1, 2, 3, 4)");
  EXPECT_EQ(describe(Command{"TRACK_CMD", stop}), "TRACK_CMD STOP tracker=(node's) camera=(node's)");
}

TEST(CmdPilot, WordsAndSource) {
  EXPECT_EQ(pilot_command_code("start"), aerie::pilot_cmd_t::START);
  EXPECT_EQ(pilot_command_code("abort"), aerie::pilot_cmd_t::ABORT);
  EXPECT_EQ(pilot_command_code("land"), aerie::pilot_cmd_t::LAND);
  EXPECT_EQ(pilot_command_code("resume"), aerie::pilot_cmd_t::RESUME);
  EXPECT_EQ(aerie::test::refusal([](const std::string& w) { pilot_command_code(w); }, "ABORT"),
            "pilot: unknown command 'ABORT' (expected abort, land, resume or start)");
  char host[256] = {};
  ASSERT_EQ(::gethostname(host, sizeof(host) - 1), 0);
  EXPECT_EQ(command_source(), std::string("aerie-cmd@") + host);
  const auto p = pilot_command(aerie::pilot_cmd_t::LAND, "aerie-cmd@gcs", 9, 2);
  EXPECT_EQ(p.utime, 9);
  EXPECT_EQ(p.seq, 2);
  EXPECT_EQ(p.command, aerie::pilot_cmd_t::LAND);
  EXPECT_EQ(p.source, "aerie-cmd@gcs");
  EXPECT_EQ(describe(Command{"PILOT_CMD", p}), "PILOT_CMD LAND source=aerie-cmd@gcs");
}

TEST(CmdMap, NamesAndDefaultName) {
  EXPECT_EQ(check_map_name("room.bt"), "room.bt");
  EXPECT_EQ(check_map_name("hall-2.ot"), "hall-2.ot");
  aerie::test::expect_refusals([](const std::string& n) { check_map_name(n); },
                               {{"", "map: file name '' is empty"},
                                {"room", "'room' does not end in .bt or .ot"},
                                {"room.png", "does not end in .bt or .ot"},
                                {".bt", "does not end in .bt or .ot"},
                                {"../room.bt", "has a directory"},
                                {"/tmp/room.bt", "has a directory"}});
  // 2026-12-01 19:08:52 UTC
  EXPECT_EQ(default_map_name(int64_t{1796152132} * 1'000'000 + 999'999), "map-20261201-190852.bt");
  const auto m = map_command(aerie::map_cmd_t::SAVE, "room.bt", 11, 3);
  EXPECT_EQ(m.utime, 11);
  EXPECT_EQ(m.seq, 3);
  EXPECT_EQ(m.command, aerie::map_cmd_t::SAVE);
  EXPECT_EQ(m.path, "room.bt");
  EXPECT_EQ(describe(Command{"MAP_CMD", m}), "MAP_CMD SAVE room.bt");
}

TEST(CmdAck, TrackRules) {
  aerie::track_t t{};
  t.tracker = "ct";
  t.camera = "CAM_LEFT";
  const auto init_ct = track_command(aerie::track_cmd_t::INIT, "ct", "", Box{1, 1, 8, 8}, 0, 0);
  const auto init_any = track_command(aerie::track_cmd_t::INIT, "", "", Box{1, 1, 8, 8}, 0, 0);
  const auto init_down = track_command(aerie::track_cmd_t::INIT, "ct", "CAM_DOWN", Box{1, 1, 8, 8}, 0, 0);
  const auto stop = track_command(aerie::track_cmd_t::STOP, "", "", std::nullopt, 0, 0);
  const auto reset = track_command(aerie::track_cmd_t::RESET, "", "", std::nullopt, 0, 0);
  for (int8_t s : {aerie::track_t::IDLE, aerie::track_t::TRACKING, aerie::track_t::LOST, aerie::track_t::REDETECTED}) {
    t.status = s;
    const bool running = s == aerie::track_t::TRACKING || s == aerie::track_t::REDETECTED;
    EXPECT_EQ(track_took_effect(init_ct, t), running) << int(s);
    EXPECT_EQ(track_took_effect(init_any, t), running) << int(s);
    EXPECT_FALSE(track_took_effect(init_down, t)) << "another camera";
    EXPECT_EQ(track_took_effect(stop, t), s == aerie::track_t::IDLE) << int(s);
    EXPECT_FALSE(track_took_effect(reset, t));
  }
  t.status = aerie::track_t::TRACKING;
  t.tracker = "mil";
  EXPECT_FALSE(track_took_effect(init_ct, t)) << "another tracker";
  EXPECT_TRUE(track_took_effect(init_any, t));
  t.seq = 4;
  t.x = 10, t.y = 20, t.width = 8, t.height = 6, t.confidence = 0.5f;
  EXPECT_EQ(describe(t), "TRACK seq 4: TRACKING tracker=mil camera=CAM_LEFT centre=(10, 20) size=8x6 confidence=0.5");
}

TEST(CmdAck, PilotRules) {
  using S = aerie::pilot_state_t;
  using C = aerie::pilot_cmd_t;
  const std::vector<std::pair<int8_t, std::vector<int8_t>>> effect = {
      {C::START, {S::TAKEOFF, S::SURVEY, S::ACQUIRE, S::APPROACH, S::DESCEND, S::TOUCHDOWN, S::LANDED, S::HOLD, S::ABORT,
                  S::ABORTED}},
      {C::ABORT, {S::ABORT, S::ABORTED}},
      {C::LAND, {S::TOUCHDOWN, S::LANDED}},
      {C::RESUME, {S::ACQUIRE, S::APPROACH, S::DESCEND, S::TOUCHDOWN, S::LANDED}}};
  for (const auto& [command, states] : effect) {
    for (int8_t s = S::IDLE; s <= S::ABORTED; ++s) {
      S m{};
      m.state = s;
      const bool expected = std::find(states.begin(), states.end(), s) != states.end();
      EXPECT_EQ(pilot_took_effect(command, m), expected) << pilot_command_name(command) << " state " << int(s);
    }
  }
  S m{};
  m.seq = 3;
  m.state = S::ABORT;
  m.state_name = "ABORT";
  m.reason = "operator ABORT";
  EXPECT_EQ(describe(m), "PILOT_STATE seq 3: ABORT (operator ABORT)");
}
