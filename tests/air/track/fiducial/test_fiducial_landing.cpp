// A short lock-step landing on a fiducial pad: the simulator paints config/pads/apriltag_board.pgm
// (made by aerie-fiducial-board from config/track_landing.yaml's fiducial section) over the
// helipad's square (world.helipad_image), aerie-track's pose source is the AprilTag board.
#include <gtest/gtest.h>

#include "air/track/fiducial/fiducial.hpp"
#include "loop/landing.hpp"
#include "tests/loop/landing/short_landing.hpp"

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
  loop::landing::test::start_close(rc);
  const loop::landing::RunResult r = loop::landing::fly(rc);
  loop::landing::test::expect_landed_on_the_pad(r);  // on the board's TARGET_POSE
  EXPECT_GT(r.target_poses, 20);  // every one from the board: the node runs no tracker
  RecordProperty("touchdown_error_m", std::to_string(r.score.touchdown_error_m));
}
