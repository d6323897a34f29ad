// SGM and SGBM_F on synthetic pairs with exactly known disparity.
#include <gtest/gtest.h>

#include <opencv2/imgproc.hpp>
#include <string>

#include "air/stereo/sgbm_ctf/sgbm_ctf.hpp"

using namespace aerie::stereo;

namespace {

// A textured left image and the right image of a slanted plane with disparity
// d(x, y) = a + b x + c y in left coordinates: right(x - d(x, y), y) = left(x, y).
struct Plane {
  double a, b, c;
  double at(double x, double y) const { return a + b * x + c * y; }
};

void make_pair(const Plane& p, cv::Size size, cv::Mat& left, cv::Mat& right) {
  cv::RNG rng(7);
  cv::Mat noise(size, CV_8UC1);
  rng.fill(noise, cv::RNG::UNIFORM, 0, 256);
  cv::GaussianBlur(noise, left, cv::Size(0, 0), 1.0);
  cv::normalize(left, left, 0, 255, cv::NORM_MINMAX);
  // Right pixel xr sees the left point x with x - d(x) = xr, i.e. x = (xr + a + c y) / (1 - b).
  cv::Mat mx(size, CV_32FC1), my(size, CV_32FC1);
  for (int y = 0; y < size.height; ++y)
    for (int x = 0; x < size.width; ++x) {
      mx.at<float>(y, x) = static_cast<float>((x + p.a + p.c * y) / (1.0 - p.b));
      my.at<float>(y, x) = static_cast<float>(y);
    }
  cv::remap(left, right, mx, my, cv::INTER_CUBIC, cv::BORDER_REFLECT);
}

struct Error {
  double mean_abs = 0, rms = 0, density = 0;
};

Error compare(const cv::Mat& disp, const Plane& p, int margin) {
  Error e;
  long n = 0, valid = 0;
  for (int y = margin; y < disp.rows - margin; ++y)
    for (int x = margin + 40; x < disp.cols - margin; ++x) {  // x >= 40: right view exists
      ++n;
      const float d = disp.at<float>(y, x);
      if (d < 0) continue;
      ++valid;
      const double err = d - p.at(x, y);
      e.mean_abs += std::abs(err);
      e.rms += err * err;
    }
  e.mean_abs /= std::max(1L, valid);
  e.rms = std::sqrt(e.rms / std::max(1L, valid));
  e.density = static_cast<double>(valid) / static_cast<double>(n);
  return e;
}

}  // namespace

// 320x240, and a size that is not a multiple of any vector width (the census' last vector
// overlaps, SGBM_F's half-resolution pair has odd sizes).
TEST(Sgm, SlantedPlaneWithinHalfPixel) {
  const Plane plane{12.0, 0.03, 0.02};  // 12 .. ~30 px across a 320x240 image
  for (const cv::Size size : {cv::Size(320, 240), cv::Size(333, 181)}) {
    cv::Mat left, right;
    make_pair(plane, size, left, right);
    for (int paths : {4, 8}) {
      SCOPED_TRACE(std::to_string(size.width) + "x" + std::to_string(size.height) + ", " + std::to_string(paths) +
                   " paths");
      SgmParams p;
      p.num_disparities = 48;
      p.paths = paths;
      SemiGlobalMatcher full(p);
      const Error ef = compare(full.compute(left, right), plane, 4);
      EXPECT_LT(ef.mean_abs, 0.5);
      EXPECT_LT(ef.rms, 0.5);
      EXPECT_GT(ef.density, 0.95);

      CoarseToFineSgbm ctf({p, 16});
      const Error ec = compare(ctf.compute(left, right), plane, 4);
      EXPECT_LT(ec.mean_abs, 0.5);
      EXPECT_LT(ec.rms, 0.5);
      EXPECT_GT(ec.density, 0.95);
      EXPECT_GT(ctf.coarse_density(), 0.9);
      EXPECT_EQ(ctf.coarse_disparity().cols, cvRound(size.width * 0.5));  // OpenCV's rounding, half to even
    }
  }
}

TEST(Sgm, RestrictedWindowFindsOnlyDisparitiesInside) {
  const Plane plane{20.0, 0.0, 0.0};
  cv::Mat left, right;
  make_pair(plane, {160, 120}, left, right);
  SgmParams p;
  p.num_disparities = 64;
  SemiGlobalMatcher sgm(p);
  // Window [16, 32) holds the true 20: found. Window [32, 48) does not: nothing may come
  // out below 32, and the uniqueness/left-right checks reject most of it.
  cv::Mat inside(left.size(), CV_16SC1, cv::Scalar(16)), outside(left.size(), CV_16SC1, cv::Scalar(32));
  const Error e = compare(sgm.compute(left, right, inside, 16), plane, 4);
  EXPECT_LT(e.mean_abs, 0.3);
  EXPECT_GT(e.density, 0.95);
  const cv::Mat wrong = sgm.compute(left, right, outside, 16);
  double lo = 0;
  cv::minMaxLoc(wrong, &lo, nullptr, nullptr, nullptr, wrong >= 0);
  EXPECT_GE(lo, 31.5);
}

TEST(Sgm, RejectsBadInput) {
  SgmParams p;
  p.num_disparities = 40;  // not a multiple of 16
  EXPECT_THROW(SemiGlobalMatcher{p}, std::invalid_argument);
  p.num_disparities = 32;
  p.p2 = p.p1;
  EXPECT_THROW(SemiGlobalMatcher{p}, std::invalid_argument);
  p = {};
  SemiGlobalMatcher sgm(p);
  cv::Mat a(40, 60, CV_8UC1, cv::Scalar(0)), b(40, 61, CV_8UC1, cv::Scalar(0));
  EXPECT_THROW(sgm.compute(a, b), std::invalid_argument);
  cv::Mat colour(40, 60, CV_8UC3);
  EXPECT_THROW(sgm.compute(colour, colour), std::invalid_argument);
  cv::Mat offsets(40, 60, CV_16SC1, cv::Scalar(60));  // beyond num_disparities - window
  EXPECT_THROW(sgm.compute(a, a, offsets, 16), std::invalid_argument);
  try {
    SgbmCtfParams cp;
    cp.fine_window = 24;
    CoarseToFineSgbm bad(cp);
    FAIL() << "fine_window 24 accepted";
  } catch (const std::invalid_argument& e) {
    EXPECT_NE(std::string(e.what()).find("fine_window"), std::string::npos);
  }
}
