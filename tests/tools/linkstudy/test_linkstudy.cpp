// aerie-linkstudy (tools/linkstudy): a bad study YAML is refused naming the field; the channels
// that cross the link follow from the placement; a link that adds nothing leaves the flight as
// it was; a two-condition study in lock-step writes the same CSV twice, whatever the number
// of threads.
#include <gtest/gtest.h>

#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <sstream>
#include <string>

#include "common/logio/event_log.hpp"
#include "tools/linkstudy/study.hpp"

using namespace aerie;

namespace {

const std::string kSource = AERIE_SOURCE_DIR;

const char* kStudy = R"(
seeds: {first: 4, count: 1}
baseline: {delay_ms: 0}
sweeps:
  delay_ms: {values: [0, 300]}
placements: [ground-tracking]
workloads: [landing]
trackers: [amcmr-ct]
landing: {wind_m_s: 1, max_time_s: 14}
)";

std::string refusal(const std::string& yaml) {
  try {
    linkstudy::load_study(util::Config::parse(yaml, "study.yaml"), kSource);
  } catch (const std::exception& e) {
    return e.what();
  }
  return "";
}

std::string with(const std::string& key_line, const std::string& replaces) {
  std::string s = kStudy;
  const auto at = s.find(replaces);
  return s.replace(at, replaces.size(), key_line);
}

std::string slurp(const std::string& path) {
  std::ifstream f(path);
  std::stringstream s;
  s << f.rdbuf();
  return s.str();
}

}  // namespace

TEST(LinkStudy, BadStudyIsRefusedNamingTheField) {
  EXPECT_EQ(refusal(kStudy), "");
  const std::string node = refusal(with("placements: [{mine: {tracker: ground}}]", "placements: [ground-tracking]"));
  EXPECT_NE(node.find("placements[0].mine"), std::string::npos) << node;
  EXPECT_NE(node.find("unknown node 'tracker'"), std::string::npos) << node;
  const std::string side = refusal(with("placements: [{mine: {track: sky}}]", "placements: [ground-tracking]"));
  EXPECT_NE(side.find("placements[0].mine.track"), std::string::npos) << side;
  const std::string negative = refusal(with("baseline: {delay_ms: -10}", "baseline: {delay_ms: 0}"));
  EXPECT_NE(negative.find("baseline: key 'delay_ms' = -10"), std::string::npos) << negative;
  const std::string sweep = refusal(with("  delay_ms: {values: [0, -300]}", "  delay_ms: {values: [0, 300]}"));
  EXPECT_NE(sweep.find("sweeps.delay_ms.values"), std::string::npos) << sweep;
  const std::string placement = refusal(with("placements: [on-the-moon]", "placements: [ground-tracking]"));
  EXPECT_NE(placement.find("placements[0]"), std::string::npos) << placement;
  EXPECT_NE(placement.find("unknown placement 'on-the-moon'"), std::string::npos) << placement;
  const std::string workload = refusal(with("workloads: [mapping]", "workloads: [landing]"));
  EXPECT_NE(workload.find("workloads"), std::string::npos) << workload;
  const std::string tracker = refusal(with("trackers: [kcf2]", "trackers: [amcmr-ct]"));
  EXPECT_NE(tracker.find("unknown tracker 'kcf2'"), std::string::npos) << tracker;
  const std::string key = refusal(std::string(kStudy) + "delay: 5\n");
  EXPECT_NE(key.find("delay"), std::string::npos) << key;
  const std::string loss = refusal(with("baseline: {loss: 1.5}", "baseline: {delay_ms: 0}"));
  EXPECT_NE(loss.find("baseline: key 'loss' = 1.5"), std::string::npos) << loss;
}

TEST(LinkStudy, ShippedStudiesLoad) {
  for (const char* f : {"/config/linkstudy/quick.yaml", "/config/linkstudy/placements.yaml", "/config/linkstudy/delay_edge.yaml",
                        "/config/linkstudy/faults.yaml", "/config/linkstudy/faults_avoidance.yaml",
                        "/config/linkstudy/faults_link.yaml"})
    EXPECT_NO_THROW(linkstudy::load_study(util::Config::load(kSource + f), kSource)) << f;
  // A fault scenario is refused naming what is wrong in it.
  try {
    linkstudy::load_study(util::Config::parse(std::string(kStudy) + "faults: [none, \"kill:track@8\"]\n", "study.yaml"), kSource);
    ADD_FAILURE() << "a kill without a duration was accepted";
  } catch (const std::exception& e) {
    EXPECT_NE(std::string(e.what()).find("faults: fault 'kill:track@8': kill needs a duration"), std::string::npos) << e.what();
  }
  // trackers.yaml replays a landing recorded under logs/ (the file says how): until it is, that is what it says.
  try {
    linkstudy::load_study(util::Config::load(kSource + "/config/linkstudy/trackers.yaml"), kSource);
  } catch (const std::exception& e) {
    EXPECT_NE(std::string(e.what()).find("replay.log"), std::string::npos) << e.what();
  }
}

TEST(LinkStudy, WhatCrossesFollowsThePlacement) {
  const auto study = linkstudy::load_study(util::Config::load(kSource + "/config/linkstudy/quick.yaml"), kSource);
  const auto placements = linkstudy::builtin_placements();
  using linkstudy::Workload;
  // (a) onboard: the ground only watches.
  auto x = linkstudy::crossing(study, Workload::kLanding, placements[0]);
  EXPECT_EQ(x.down, "CAM_DOWN|PILOT_STATE|TRACK");
  EXPECT_EQ(x.up, "");
  EXPECT_EQ(x.operator_channel, "CAM_DOWN");
  // (b) tracking on the ground: the images (and the operator's box) down, the commands up.
  x = linkstudy::crossing(study, Workload::kLanding, placements[1]);
  EXPECT_EQ(x.down, "CAM_DOWN|GT_TRACK|IMU");
  EXPECT_EQ(x.up, "CTRL_CMD");
  // (c) control on the ground: the tracker's results down.
  x = linkstudy::crossing(study, Workload::kLanding, placements[2]);
  EXPECT_EQ(x.down, "CAM_DOWN|IMU|TARGET_POSE|TRACK");
  EXPECT_EQ(x.up, "CTRL_CMD");
  x = linkstudy::crossing(study, Workload::kAvoidance, placements[1]);
  EXPECT_EQ(x.down, "CAM_STEREO|IMU");
  EXPECT_EQ(x.up, "CTRL_CMD");
  x = linkstudy::crossing(study, Workload::kAvoidance, placements[2]);
  EXPECT_EQ(x.down, "NAV_STATE");
  EXPECT_EQ(x.up, "CTRL_CMD");
}

TEST(LinkStudy, AnOnboardPlacementOverAPerfectLinkFliesAsWithoutALink) {
  auto study = linkstudy::load_study(util::Config::parse(with("placements: [onboard]", "placements: [ground-tracking]"),
                                                         "study.yaml"), kSource);
  const loop::landing::RunConfig rc = loop::landing::load_landing_run(study.landing, 4);
  const loop::landing::RunResult plain = loop::landing::fly(rc);
  const linkstudy::RunRow row = linkstudy::run(study, {&study.sweeps[0].conditions[0], &study.placements[0],
                                                       linkstudy::Workload::kLanding, "amcmr-ct", 4});
  EXPECT_EQ(row.sim_s, plain.sim_s);
  EXPECT_EQ(row.final_state, plain.final_state);
  EXPECT_EQ(row.touchdown_error_m, plain.outcome.landed ? plain.score.touchdown_error_m : -1);
  EXPECT_GT(row.down.delivered, 100);  // the operator watched
  EXPECT_EQ(row.down.dropped_loss + row.down.dropped_queue, 0);
  EXPECT_EQ(row.view_age_p95_ms, 0);   // a perfect link: the operator sees each frame as it is taken
}

TEST(LinkStudy, TwoConditionStudyInLockStepWritesTheSameCsvTwice) {
  const auto dir = std::filesystem::temp_directory_path() / ("linkstudy-test-" + std::to_string(::getpid()));
  std::filesystem::create_directories(dir);
  std::ofstream(dir / "study.yaml") << kStudy;
  auto study = [&](const std::string& out, int jobs) {
    const std::string cmd = std::string(AERIE_BINARY_DIR) + "/bin/aerie-linkstudy --config " + (dir / "study.yaml").string() +
                            " --out " + (dir / out).string() + " --base-dir " + kSource + " --no-plots --jobs " +
                            std::to_string(jobs) + " > " + (dir / (out + ".txt")).string() + " 2>&1";
    EXPECT_EQ(std::system(cmd.c_str()), 0) << slurp((dir / (out + ".txt")).string());
    return slurp((dir / out / "study.csv").string());
  };
  const std::string a = study("a", 2), b = study("b", 1);
  EXPECT_EQ(a, b);
  std::istringstream lines(a);
  std::string header, row;
  std::getline(lines, header);
  EXPECT_EQ(header.rfind("condition,delay_ms,loss,bandwidth_mbit,placement,workload,tracker,seed,success,metric,value", 0), 0u);
  int rows = 0;
  while (std::getline(lines, row)) ++rows;
  EXPECT_EQ(rows, 2);
  EXPECT_NE(a.find("delay300_"), std::string::npos);
  EXPECT_TRUE(std::filesystem::exists(dir / "a" / "report.md"));
  std::filesystem::remove_all(dir);
}

// The open-loop workload: a recorded landing replayed through the link. Over a perfect link
// the operator gets a box for every frame the pad is visible in; with 30 % loss on the way
// down to a tracker on the ground, the frames whose image (or box) was lost are counted lost.
TEST(LinkStudy, ReplayScoresTheBoxesThatReachTheOperator) {
  const auto dir = std::filesystem::temp_directory_path() / ("linkstudy-replay-" + std::to_string(::getpid()));
  std::filesystem::create_directories(dir);
  const std::string log = (dir / "flight.lcm").string();
  {
    auto study = linkstudy::load_study(util::Config::parse(kStudy, "study.yaml"), kSource);
    loop::landing::RunConfig rc = loop::landing::load_landing_run(study.landing, 4);
    rc.sim.max_time_s = 12;
    rc.frames_after_end = 0;
    logio::Writer w(log);
    rc.on_message = [&](link::Side, const std::string& channel, const uint8_t* data, size_t size, int64_t now_us) {
      w.write(now_us, channel, data, size);
    };
    loop::landing::fly(rc);
  }
  std::ofstream(dir / "replay.yaml") << "seeds: {first: 1, count: 1}\nsweeps: {loss: {values: [0, 0.3]}}\n"
                                        "placements: [onboard, ground-tracking]\nworkloads: [replay]\n"
                                        "replay: {log: " << log << "}\n";
  const auto study = linkstudy::load_study(util::Config::load((dir / "replay.yaml").string()), kSource);
  const auto& perfect = study.sweeps[0].conditions[0];
  const auto& lossy = study.sweeps[0].conditions[1];
  const auto onboard = linkstudy::run(study, {&perfect, &study.placements[0], linkstudy::Workload::kReplay, "amcmr-ct", 1});
  EXPECT_GT(onboard.frames_visible, 100);
  EXPECT_EQ(onboard.frames_lost, 0);
  EXPECT_GT(onboard.auc, 0.6);
  EXPECT_TRUE(onboard.success);
  EXPECT_EQ(onboard.metric, "auc");
  const auto lost = linkstudy::run(study, {&lossy, &study.placements[1], linkstudy::Workload::kReplay, "amcmr-ct", 1});
  EXPECT_NEAR(static_cast<double>(lost.frames_lost) / static_cast<double>(lost.frames_visible), 0.3, 0.1);
  EXPECT_LT(lost.auc, onboard.auc);
  EXPECT_FALSE(lost.success);
  std::filesystem::remove_all(dir);
}
