// aerie-bench-fiducial: time per frame of the fiducial pose source (detection + IPPE + LM) on a
// synthetic view of the nested landing board 2 m below, at 640x480 and 1280x720 (the same lens,
// fx = 0.78 x the width), for AprilTag (quad_decimate 1 and 2) and ArUco.
#include "air/track/fiducial/fiducial.hpp"
#include "bench/benchmark_main.hpp"
#include "tests/air/track/fiducial/fiducial_views.hpp"

namespace {

using namespace aerie::track;

aerie::camera::CameraModel camera(int width, int height) {
  aerie::camera::CameraModel c;
  c.width = width, c.height = height;
  c.fx = c.fy = 0.78 * width;
  c.cx = (width - 1) / 2.0, c.cy = (height - 1) / 2.0;
  return c;
}

// args: width, height, decimate x 10.
void run(benchmark::State& state, FiducialBoard board) {
  const auto cam = camera(static_cast<int>(state.range(0)), static_cast<int>(state.range(1)));
  FiducialOptions options;
  options.quad_decimate = state.range(2) / 10.0;
  FiducialDetector detector(board, options);
  const cv::Mat view =
      test::render_view(render_board(board, 2048), cam, test::looking_down(2.0, 20, 10, 0.1, -0.05), 2);
  int64_t found = 0;
  for (auto _ : state) {
    const auto pose = detector.estimate(view, cam);
    found += pose ? 1 : 0;
    benchmark::DoNotOptimize(pose);
  }
  state.counters["found"] = benchmark::Counter(static_cast<double>(found), benchmark::Counter::kAvgIterations);
}

void apriltag(benchmark::State& state) {
  run(state, {FiducialKind::AprilTag, "tagCustom48h12", {{0, 0.6, 0, 0}, {1, 0.06, 0, 0}}});
}
void aruco(benchmark::State& state) {
  run(state, {FiducialKind::ArUco, "DICT_4X4_50", {{0, 0.5, 0, 0}, {1, 0.08, 0.4, 0}, {2, 0.08, -0.4, 0}}});
}

BENCHMARK(apriltag)->ArgNames({"w", "h", "decimate10"})->Args({640, 480, 10})->Args({640, 480, 20})
    ->Args({1280, 720, 10})->Args({1280, 720, 20})->Unit(benchmark::kMillisecond);
BENCHMARK(aruco)->ArgNames({"w", "h", "decimate10"})->Args({640, 480, 10})->Args({1280, 720, 10})
    ->Unit(benchmark::kMillisecond);

}  // namespace

int main(int argc, char** argv) {
  return aerie::bench::benchmark_main(argc, argv, "aerie-bench-fiducial",
                                      "time per frame of the fiducial pose source (AprilTag, ArUco) at 640x480 and 1280x720");
}
