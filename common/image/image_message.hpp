#pragma once
// cv::Mat <-> aerie::image_t (bot_core.image_t layout): raw GRAY/RGB/BGR, JPEG, PNG.
#include <aerie/gt_box_t.hpp>
#include <aerie/image_t.hpp>

#include <array>
#include <cstdint>
#include <opencv2/core.hpp>
#include <optional>
#include <string>

namespace aerie::image {

enum class Encoding { Raw, Jpeg, Png };
Encoding encoding_from_string(const std::string& name);  // "raw", "jpeg", "png"; throws otherwise

// img: CV_8UC1 (GRAY) or CV_8UC3 in OpenCV's BGR order. Raw colour is sent as BGR.
aerie::image_t to_message(const cv::Mat& img, int64_t utime, int64_t seq, Encoding encoding = Encoding::Raw,
                          int jpeg_quality = 90);

// Largest image from_message decodes by default (pixels): 4096 x 4096.
inline constexpr int64_t kMaxPixels = int64_t{4096} * 4096;

// The width x height a PNG (IHDR) or JPEG (SOFn) payload declares in its header, read
// without decoding; nullopt when the header cannot be read.
std::optional<cv::Size> encoded_size(const uint8_t* data, size_t size, bool png);

// Decodes any supported payload to CV_8UC1 or CV_8UC3 (BGR). Throws
// std::invalid_argument naming what is inconsistent (size vs width*height, unknown
// pixel format, undecodable JPEG/PNG, ...). The result never aliases msg.data.
// Images of more than max_pixels are refused, and a PNG/JPEG whose header declares another
// size than width x height is refused before it is decoded (a 249 KB PNG can declare
// 16000 x 16000 and inflate to 256 MB).
cv::Mat from_message(const aerie::image_t& msg, int64_t max_pixels = kMaxPixels);
// As from_message, converted to 8-bit gray.
cv::Mat gray_from_message(const aerie::image_t& msg, int64_t max_pixels = kMaxPixels);

std::string pixel_format_name(int32_t pixelformat);

void set_metadata(aerie::image_t& msg, const std::string& key, const std::string& value);
std::optional<std::string> metadata(const aerie::image_t& msg, const std::string& key);
// metadata["seq"], or -1 when absent or not a number.
int64_t sequence_number(const aerie::image_t& msg);

// A target's true box in the image of `camera` (GT_TRACK): axis-aligned box (top-left
// corner and size) and projected corners, pixels.
aerie::gt_box_t gt_box_message(int64_t utime, int64_t seq, const std::string& target, const std::string& camera,
                               bool visible, const cv::Rect2d& box, const std::array<cv::Point2d, 4>& corners);

}  // namespace aerie::image
