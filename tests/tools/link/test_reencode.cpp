#include <aerie/stereo_image_t.hpp>
#include <gtest/gtest.h>

#include <opencv2/core.hpp>
#include <opencv2/imgproc.hpp>

#include "common/image/image_message.hpp"
#include "tools/link/reencode.hpp"

using namespace aerie;

namespace {

cv::Mat scene(int type) {
  cv::Mat img(240, 320, type);
  cv::randu(img, 0, 40);
  cv::GaussianBlur(img, img, cv::Size(9, 9), 3);
  cv::circle(img, {160, 120}, 60, cv::Scalar::all(200), -1);
  cv::rectangle(img, {20, 20}, {90, 70}, cv::Scalar::all(120), -1);
  return img;
}

template <typename Msg>
std::vector<uint8_t> bytes(const Msg& m) {
  std::vector<uint8_t> b(static_cast<size_t>(m.getEncodedSize()));
  m.encode(b.data(), 0, static_cast<int>(b.size()));
  return b;
}

template <typename Msg>
Msg decode(const std::vector<uint8_t>& b) {
  Msg m;
  EXPECT_EQ(m.decode(b.data(), 0, static_cast<int>(b.size())), static_cast<int>(b.size()));
  return m;
}

}  // namespace

TEST(Reencode, RawImageBecomesASmallerFaithfulJpeg) {
  for (int type : {CV_8UC1, CV_8UC3}) {
    const cv::Mat img = scene(type);
    auto msg = image::to_message(img, 123456, 7);
    image::set_metadata(msg, "camera", "left");
    const auto in = bytes(msg);
    const auto out = link::reencode_jpeg(in, 90);
    ASSERT_TRUE(out.has_value());
    EXPECT_LT(out->size(), in.size() / 3);
    const auto m = decode<aerie::image_t>(*out);
    EXPECT_EQ(m.utime, 123456);
    EXPECT_EQ(m.pixelformat, aerie::image_t::PIXEL_FORMAT_MJPEG);
    EXPECT_EQ(image::metadata(m, "camera"), "left");
    EXPECT_EQ(image::sequence_number(m), 7);
    const cv::Mat back = image::from_message(m);
    EXPECT_GT(cv::PSNR(back, img), 30.0);
  }
}

TEST(Reencode, StereoPairBothImages) {
  aerie::stereo_image_t s;
  s.utime = 99;
  s.seq = 3;
  s.left = image::to_message(scene(CV_8UC1), 99, 3);
  s.right = image::to_message(scene(CV_8UC1), 99, 3);
  s.fx = s.fy = 400;
  s.cx = 160;
  s.cy = 120;
  s.baseline_m = 0.12;
  const auto in = bytes(s);
  const auto out = link::reencode_jpeg(in, 60);
  ASSERT_TRUE(out.has_value());
  const auto m = decode<aerie::stereo_image_t>(*out);
  EXPECT_EQ(m.seq, 3);
  EXPECT_DOUBLE_EQ(m.baseline_m, 0.12);
  EXPECT_EQ(m.left.pixelformat, aerie::image_t::PIXEL_FORMAT_MJPEG);
  EXPECT_EQ(m.right.pixelformat, aerie::image_t::PIXEL_FORMAT_MJPEG);
  EXPECT_GT(cv::PSNR(image::from_message(m.right), scene(CV_8UC1)), 28.0);
}

TEST(Reencode, OtherPayloadsPassUntouched) {
  aerie::stereo_image_t s;  // not an image_t: decoding as one would fail
  std::vector<uint8_t> junk(100, 0xab);
  EXPECT_FALSE(link::reencode_jpeg(junk, 50).has_value());
  EXPECT_FALSE(link::reencode_jpeg({}, 50).has_value());
  // A JPEG at low quality is not re-encoded at a higher one (it would grow).
  const auto small = bytes(image::to_message(scene(CV_8UC1), 1, 1, image::Encoding::Jpeg, 20));
  EXPECT_FALSE(link::reencode_jpeg(small, 95).has_value());
  // A truncated image payload is left alone.
  auto raw = bytes(image::to_message(scene(CV_8UC1), 1, 1));
  raw.resize(raw.size() / 2);
  EXPECT_FALSE(link::reencode_jpeg(raw, 50).has_value());
}
