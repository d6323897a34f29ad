// The world option helipad_image: a drawing painted over the helipad's square instead of the H.
#include <gtest/gtest.h>

#include <opencv2/core.hpp>

#include <string>

#include "tests/air/track/pad_views.hpp"

using aerie::sim::World;
using aerie::sim::WorldConfig;

namespace {

cv::Mat view(const World& w, double heading = 20) {
  const aerie::sim::StereoRenderer r(w, aerie::sim::landing_rig());
  return aerie::track::test::pad_view(r, 2.0, heading, 0, 0).frame.left;
}

std::string error_of(const WorldConfig& cfg) {
  try {
    World::room(cfg);
  } catch (const std::invalid_argument& e) {
    return e.what();
  }
  return "no exception";
}

}  // namespace

TEST(HelipadImage, UnsetGivesTheSameFramesByteForByte) {
  WorldConfig unset, empty;
  empty.helipad_image = "";
  const cv::Mat a = view(World::room(unset)), b = view(World::room(empty));
  ASSERT_EQ(a.size(), b.size());
  EXPECT_EQ(cv::norm(a, b, cv::NORM_INF), 0.0);
}

TEST(HelipadImage, PaintsOnlyThePadsSquare) {
  WorldConfig cfg;
  cfg.helipad_image = AERIE_SOURCE_DIR "/config/pads/logo.pgm";
  const World h = World::room({}), logo = World::room(cfg);
  const aerie::sim::StereoRenderer r(h, aerie::sim::landing_rig());
  const auto truth = aerie::track::test::pad_view(r, 2.0, 20, 0, 0).frame;
  const cv::Mat a = view(h), b = view(logo);
  cv::Mat outside(a.size(), CV_8U, cv::Scalar(255));
  const cv::Rect2d box = truth.target_box;
  outside(cv::Rect(cv::Point(std::floor(box.x) - 4, std::floor(box.y) - 4), cv::Point(std::ceil(box.br().x) + 4, std::ceil(box.br().y) + 4)) &
          cv::Rect(0, 0, a.cols, a.rows))
      .setTo(0);
  cv::Mat diff;
  cv::absdiff(a, b, diff);
  // 4 px: the texture's coarser mip levels blend the pad's edge texels into the floor's.
  EXPECT_EQ(cv::countNonZero(diff & outside), 0) << "pixels off the pad's square changed";
  EXPECT_GT(cv::countNonZero(diff > 40), 200) << "the drawing is not the H";
  WorldConfig white = cfg;
  white.helipad_image = testing::TempDir() + "/white.pgm";
  {
    std::FILE* f = std::fopen(white.helipad_image.c_str(), "wb");
    std::fprintf(f, "P5\n# all white\n16 16\n255\n");
    for (int i = 0; i < 256; ++i) std::fputc(255, f);
    std::fclose(f);
  }
  const cv::Mat w = view(World::room(white));
  const cv::Point c(static_cast<int>(box.x + box.width / 2), static_cast<int>(box.y + box.height / 2));
  EXPECT_GT(w.at<uint8_t>(c), 180) << "an all-white drawing paints the square white";
}

TEST(HelipadImage, BadFilesAreNamed) {
  WorldConfig cfg;
  cfg.helipad_image = "/nonexistent/pad.pgm";
  EXPECT_NE(error_of(cfg).find("helipad_image '/nonexistent/pad.pgm': cannot be read"), std::string::npos) << error_of(cfg);
  cfg.helipad_image = AERIE_SOURCE_DIR "/config/pads/logo.png";
  EXPECT_NE(error_of(cfg).find("not a binary PGM (P5) or PPM (P6)"), std::string::npos) << error_of(cfg);
  cfg.helipad_image = testing::TempDir() + "/short.pgm";
  {
    std::FILE* f = std::fopen(cfg.helipad_image.c_str(), "wb");
    std::fprintf(f, "P5\n16 16\n255\n");
    std::fputc(0, f);
    std::fclose(f);
  }
  EXPECT_NE(error_of(cfg).find("truncated pixels"), std::string::npos) << error_of(cfg);
}
