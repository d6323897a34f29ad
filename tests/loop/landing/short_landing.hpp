#pragma once
// A short landing close to the pad, and what every such landing must show (the landing-loop
// and fiducial-landing tests).
#include <gtest/gtest.h>

#include "loop/landing.hpp"

namespace aerie::loop::landing::test {

// Starts 0.5-1 m from the pad, without the survey: the landing itself, short.
inline void start_close(RunConfig& rc) {
  rc.sim.placement.start_distance_min_m = 0.5;
  rc.sim.placement.start_distance_max_m = 1.0;
  rc.pilot.survey_legs.clear();
}

// Landed on the pad within 15 cm, on poses within 5 cm of the truth in the descent, in lock-step.
inline void expect_landed_on_the_pad(const RunResult& r) {
  EXPECT_TRUE(r.outcome.landed) << r.final_state << " " << r.outcome.collision;
  EXPECT_TRUE(r.score.success) << "touchdown error " << r.score.touchdown_error_m << " m, yaw " << r.score.yaw_error_deg;
  EXPECT_LT(r.score.touchdown_error_m, 0.15);
  EXPECT_EQ(r.final_state, "LANDED");
  EXPECT_GT(r.descent.size(), 5u);
  EXPECT_LT(r.rmse(0), 0.05);  // TARGET_POSE against the truth during the descent
  EXPECT_LT(r.rmse(2), 0.05);
  EXPECT_EQ(r.lockstep_timeouts, 0);
}

}  // namespace aerie::loop::landing::test
