// A short lock-step landing on a fiducial pad: the simulator paints config/pads/apriltag_board.pgm
// (made by aerie-fiducial-board from config/track_landing.yaml's fiducial section) over the
// helipad's square (world.helipad_image), aerie-track's pose source is the AprilTag board.
#include <gtest/gtest.h>

#include "air/track/fiducial/fiducial.hpp"
#include "loop/landing.hpp"

using namespace aerie;

TEST(FiducialLanding, LandsOnTheAprilTagPad) {
  loop::landing::RunConfig rc = loop::landing::load_landing_run(
      util::Config::parse("tracker: amcmr-ct\nmax_time_s: 60\n", "test_fiducial_landing"), 4, AERIE_SOURCE_DIR);
  const util::Config cfg = util::Config::load(AERIE_SOURCE_DIR "/config/track_landing.yaml");
  rc.track.fiducial = track::fiducial_board(cfg.section("fiducial"), track::FiducialKind::AprilTag);
  rc.track.fiducial_options = track::fiducial_options(cfg.section("fiducial"));
  // The image spans the board's printed square (render_board's automatic side: aerie-fiducial-board's output).
  rc.sim.world.helipad_image = AERIE_SOURCE_DIR "/config/pads/apriltag_board.pgm";
  rc.sim.world.helipad_size = track::render_board(*rc.track.fiducial, 512).side_m;
  rc.sim.placement.start_distance_min_m = 0.5;
  rc.sim.placement.start_distance_max_m = 1.0;
  rc.pilot.survey_legs.clear();
  const loop::landing::RunResult r = loop::landing::fly(rc);
  EXPECT_TRUE(r.outcome.landed) << r.final_state << " " << r.outcome.collision;
  EXPECT_TRUE(r.score.success) << "touchdown error " << r.score.touchdown_error_m << " m, yaw " << r.score.yaw_error_deg;
  EXPECT_LT(r.score.touchdown_error_m, 0.15);
  EXPECT_EQ(r.final_state, "LANDED");
  EXPECT_GT(r.descent.size(), 5u);
  EXPECT_LT(r.rmse(0), 0.05);  // TARGET_POSE (the board's) against the truth during the descent
  EXPECT_LT(r.rmse(2), 0.05);
  EXPECT_GT(r.target_poses, 20);  // every one from the board: the node runs no tracker
  EXPECT_EQ(r.lockstep_timeouts, 0);
  RecordProperty("touchdown_error_m", std::to_string(r.score.touchdown_error_m));
}
