#include <gtest/gtest.h>

#include <opencv2/imgproc.hpp>

#include "common/image/image_message.hpp"

using namespace aerie::image;

static cv::Mat pattern(int type) {
  cv::Mat img(48, 64, type);
  cv::randu(img, 0, 255);
  cv::GaussianBlur(img, img, {5, 5}, 1.5);  // smooth, so JPEG stays close
  return img;
}

TEST(ImageMessage, RawGrayAndBgrRoundTripExactly) {
  for (int type : {CV_8UC1, CV_8UC3}) {
    const cv::Mat img = pattern(type);
    const auto msg = to_message(img, 123456, 42);
    EXPECT_EQ(msg.size, img.total() * img.elemSize());
    EXPECT_EQ(sequence_number(msg), 42);
    const cv::Mat back = from_message(msg);
    EXPECT_EQ(cv::norm(back, img, cv::NORM_INF), 0);
  }
}

TEST(ImageMessage, PngIsLosslessJpegIsClose) {
  const cv::Mat img = pattern(CV_8UC3);
  EXPECT_EQ(cv::norm(from_message(to_message(img, 1, 1, Encoding::Png)), img, cv::NORM_INF), 0);
  const auto jpeg = to_message(img, 1, 1, Encoding::Jpeg, 95);
  EXPECT_EQ(jpeg.pixelformat, aerie::image_t::PIXEL_FORMAT_MJPEG);
  EXPECT_LT(cv::norm(from_message(jpeg), img, cv::NORM_L1) / img.total() / 3, 4.0);
}

TEST(ImageMessage, RgbPayloadIsSwappedToBgr) {
  cv::Mat bgr(2, 2, CV_8UC3, cv::Scalar(10, 20, 30));
  auto msg = to_message(bgr, 0, 0);
  msg.pixelformat = aerie::image_t::PIXEL_FORMAT_RGB;  // same bytes now mean R=10, B=30
  const cv::Mat out = from_message(msg);
  EXPECT_EQ(out.at<cv::Vec3b>(0, 0), cv::Vec3b(30, 20, 10));
}

TEST(ImageMessage, LcmEncodeDecodeRoundTrip) {
  const auto msg = to_message(pattern(CV_8UC1), 99, 7, Encoding::Raw);
  std::vector<uint8_t> buf(msg.getEncodedSize());
  ASSERT_EQ(msg.encode(buf.data(), 0, static_cast<int>(buf.size())), static_cast<int>(buf.size()));
  aerie::image_t back;
  ASSERT_EQ(back.decode(buf.data(), 0, static_cast<int>(buf.size())), static_cast<int>(buf.size()));
  EXPECT_EQ(back.data, msg.data);
  EXPECT_EQ(sequence_number(back), 7);
}

TEST(ImageMessage, BadMessagesAreRejectedWithAReason) {
  auto msg = to_message(pattern(CV_8UC1), 5, 0);
  auto expect_error = [](const aerie::image_t& m, const std::string& fragment) {
    try {
      from_message(m);
      FAIL() << "accepted a bad message, expected: " << fragment;
    } catch (const std::invalid_argument& e) {
      EXPECT_NE(std::string(e.what()).find(fragment), std::string::npos) << e.what();
    }
  };
  auto short_payload = msg;
  short_payload.data.resize(100);
  short_payload.size = 100;
  expect_error(short_payload, "too short");
  auto wrong_size = msg;
  wrong_size.size += 1;
  expect_error(wrong_size, "size field");
  auto zero = msg;
  zero.width = 0;
  expect_error(zero, "invalid size");
  auto unknown = msg;
  unknown.pixelformat = 1234;
  expect_error(unknown, "unsupported pixel format");
  auto garbage = to_message(pattern(CV_8UC1), 5, 0, Encoding::Jpeg);
  std::fill(garbage.data.begin(), garbage.data.end(), 0);
  expect_error(garbage, "cannot be decoded");
  EXPECT_THROW(to_message(cv::Mat(), 0, 0), std::invalid_argument);
  EXPECT_THROW(encoding_from_string("gif"), std::invalid_argument);
}

TEST(ImageMessage, DeclaredSizeIsCheckedBeforeDecoding) {
  const cv::Mat img(48, 64, CV_8UC1, cv::Scalar(128));
  for (auto enc : {Encoding::Png, Encoding::Jpeg}) {
    aerie::image_t m = to_message(img, 1, 1, enc);
    const auto declared = encoded_size(m.data.data(), m.data.size(), enc == Encoding::Png);
    ASSERT_TRUE(declared.has_value());
    EXPECT_EQ(*declared, cv::Size(64, 48));
    // The message claims less than the payload declares: refused, naming both, not decoded.
    m.width = 32;
    m.height = 24;
    try {
      from_message(m);
      FAIL();
    } catch (const std::invalid_argument& e) {
      EXPECT_NE(std::string(e.what()).find("payload declares 64x48, header says 32x24 (not decoded)"), std::string::npos)
          << e.what();
    }
    // A cap below the image's size.
    m = to_message(img, 1, 1, enc);
    try {
      from_message(m, 64 * 48 - 1);
      FAIL();
    } catch (const std::invalid_argument& e) {
      EXPECT_NE(std::string(e.what()).find("64x48 is larger than the limit of 3071 pixels"), std::string::npos) << e.what();
    }
  }
  const uint8_t junk[8] = {1, 2, 3, 4, 5, 6, 7, 8};
  EXPECT_FALSE(encoded_size(junk, sizeof junk, true).has_value());
  EXPECT_FALSE(encoded_size(junk, sizeof junk, false).has_value());
}
