// Micro-benchmark of FHOG (air/track/dcf/fhog.cpp), the hot loop of the correlation-filter
// trackers: the library's fhog() against the scalar reference it replaced
// (tests/air/track/fhog_reference.hpp), interleaved in one run on one thread, on a 256x256 BGR
// patch (a DCF search window), a 640x480 grey frame and a 1280x720 grey frame.
//   aerie-bench-fhog-micro [REPETITIONS]     (default 200; median microseconds per call)
#include <opencv2/core.hpp>
#include <opencv2/imgproc.hpp>

#include <algorithm>
#include <chrono>
#include <cstdio>
#include <cstdlib>
#include <fstream>
#include <string>
#include <vector>

#include "air/track/dcf/fhog.hpp"
#include "tests/air/track/fhog_reference.hpp"

using namespace aerie::track;

namespace {

std::string loadavg() {
  std::ifstream f("/proc/loadavg");
  std::string a, b, c;
  f >> a >> b >> c;
  return a + " " + b + " " + c;
}

cv::Mat textured(cv::Size size, int type) {
  cv::Mat img(size, type);
  cv::RNG rng(7);
  rng.fill(img, cv::RNG::UNIFORM, 0, 256);
  cv::GaussianBlur(img, img, {0, 0}, 1.2);
  return img;
}

double median(std::vector<double> v) {
  std::nth_element(v.begin(), v.begin() + v.size() / 2, v.end());
  return v[v.size() / 2];
}

template <typename F>
double time_us(F&& f) {
  const auto t0 = std::chrono::steady_clock::now();
  f();
  return std::chrono::duration<double, std::micro>(std::chrono::steady_clock::now() - t0).count();
}

}  // namespace

int main(int argc, char** argv) {
  int reps = 200;
  for (int i = 1; i < argc; ++i) {
    const std::string arg = argv[i];
    if (arg == "-h" || arg == "--help") {
      std::printf("aerie-bench-fhog-micro: FHOG (air/track/dcf) against its scalar reference, median us per call\n"
                  "Usage: aerie-bench-fhog-micro [REPETITIONS]   (a positive integer, default 200)\n");
      return 0;
    }
    char* end = nullptr;
    const long n = std::strtol(arg.c_str(), &end, 10);
    if (i > 1 || arg.empty() || *end != '\0' || n < 1 || n > 1000000) {
      std::fprintf(stderr, "aerie-bench-fhog-micro: unexpected argument '%s': expected REPETITIONS in [1, 1000000] (see --help)\n",
                   argv[i]);
      return 2;
    }
    reps = static_cast<int>(n);
  }
  cv::setNumThreads(1);
  struct Case {
    const char* name;
    cv::Mat image;
    int cell;
  };
  const std::vector<Case> cases = {{"256x256 BGR, cell 4", textured({256, 256}, CV_8UC3), 4},
                                   {"640x480 grey, cell 4", textured({640, 480}, CV_8UC1), 4},
                                   {"1280x720 grey, cell 4", textured({1280, 720}, CV_8UC1), 4}};
  std::printf("loadavg before: %s\n", loadavg().c_str());
  std::printf("%-24s %12s %12s %8s %12s\n", "case", "reference us", "fhog us", "speed-up", "max |diff|");
  for (const auto& c : cases) {
    std::vector<double> ref, now;
    std::vector<cv::Mat> a, b;
    for (int r = 0; r < reps; ++r) {  // interleaved: both see the same load
      ref.push_back(time_us([&] { a = reference::fhog_reference(c.image, c.cell); }));
      now.push_back(time_us([&] { b = fhog(c.image, c.cell); }));
    }
    double diff = 0;
    for (int ch = 0; ch < kFhogChannels; ++ch) diff = std::max(diff, cv::norm(a[ch], b[ch], cv::NORM_INF));
    const double mr = median(ref), mn = median(now);
    std::printf("%-24s %12.1f %12.1f %7.2fx %12.2e\n", c.name, mr, mn, mr / mn, diff);
  }
  std::printf("loadavg after: %s\n", loadavg().c_str());
  return 0;
}
