// Micro-benchmarks of the IPSL hot loops: one 32x32 observation warp, and scoring a batch of
// observations against a 16-vector subspace (eqs. 3.8-3.10).
#include <benchmark/benchmark.h>

#include "bench/benchmark_main.hpp"

#include <opencv2/imgproc.hpp>

#include <cstdio>

#include "air/track/ipsl/appearance.hpp"

using namespace aerie::track;

namespace {

cv::Mat test_image() {
  cv::Mat img(240, 376, CV_8U);
  cv::randu(img, 0, 255);
  cv::GaussianBlur(img, img, {0, 0}, 1.5);
  return img;
}

void BM_WarpPatch(benchmark::State& state) {
  const cv::Mat img = test_image();
  std::vector<float> out(32 * 32);
  double t = 0;
  for (auto _ : state) {
    warp_patch(img, {180.3 + t, 120.7, 1.1, 0.2}, {48, 40}, 32, out.data());
    benchmark::DoNotOptimize(out.data());
    t = t > 10 ? 0 : t + 0.37;
  }
}
BENCHMARK(BM_WarpPatch);

void BM_Score(benchmark::State& state) {
  const int n = static_cast<int>(state.range(0)), dim = 32 * 32;
  AppearanceModel model(dim, 16, 0.95, 5, {});
  Eigen::MatrixXf obs = Eigen::MatrixXf::Random(dim, n);
  model.init(obs.col(0));
  for (int i = 1; i < 20; ++i) model.add(obs.col(i % n));
  std::vector<ObservationScore> scores;
  for (auto _ : state) {
    model.score(obs, scores);
    benchmark::DoNotOptimize(scores.data());
  }
  state.SetItemsProcessed(state.iterations() * n);
}
BENCHMARK(BM_Score)->Arg(100)->Arg(300);

}  // namespace

int main(int argc, char** argv) {
  return aerie::bench::benchmark_main(
      argc, argv, "aerie-bench-ipsl-micro",
      "micro-benchmarks of the IPSL hot loops (observation warp, subspace scoring)");
}
