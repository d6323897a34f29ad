#include "common/image/image_message.hpp"

#include <algorithm>
#include <charconv>
#include <cstdint>
#include <cstring>
#include <opencv2/imgcodecs.hpp>
#include <opencv2/imgproc.hpp>
#include <stdexcept>

namespace aerie::image {

Encoding encoding_from_string(const std::string& name) {
  if (name == "raw") return Encoding::Raw;
  if (name == "jpeg" || name == "jpg") return Encoding::Jpeg;
  if (name == "png") return Encoding::Png;
  throw std::invalid_argument("unknown image encoding '" + name + "' (expected raw, jpeg or png)");
}

std::string pixel_format_name(int32_t f) {
  switch (f) {
    case aerie::image_t::PIXEL_FORMAT_GRAY: return "GRAY";
    case aerie::image_t::PIXEL_FORMAT_RGB: return "RGB";
    case aerie::image_t::PIXEL_FORMAT_BGR: return "BGR";
    case aerie::image_t::PIXEL_FORMAT_MJPEG: return "MJPEG";
    case aerie::image_t::PIXEL_FORMAT_PNG: return "PNG";
    default: return "unknown(" + std::to_string(f) + ")";
  }
}

aerie::image_t to_message(const cv::Mat& img, int64_t utime, int64_t seq, Encoding encoding, int jpeg_quality) {
  if (img.empty()) throw std::invalid_argument("to_message: empty image");
  if (img.type() != CV_8UC1 && img.type() != CV_8UC3)
    throw std::invalid_argument("to_message: only 8-bit gray or BGR images are supported");
  aerie::image_t msg;
  msg.utime = utime;
  msg.width = img.cols;
  msg.height = img.rows;
  msg.nmetadata = 0;
  if (encoding == Encoding::Raw) {
    msg.pixelformat = img.channels() == 1 ? int32_t{aerie::image_t::PIXEL_FORMAT_GRAY} : int32_t{aerie::image_t::PIXEL_FORMAT_BGR};
    msg.row_stride = static_cast<int32_t>(img.cols * img.elemSize());
    msg.data.resize(static_cast<size_t>(msg.row_stride) * img.rows);
    for (int r = 0; r < img.rows; ++r)
      std::memcpy(msg.data.data() + static_cast<size_t>(r) * msg.row_stride, img.ptr(r), msg.row_stride);
  } else {
    std::vector<uchar> buf;
    const bool jpeg = encoding == Encoding::Jpeg;
    std::vector<int> params;
    if (jpeg) params = {cv::IMWRITE_JPEG_QUALITY, jpeg_quality};
    if (!cv::imencode(jpeg ? ".jpg" : ".png", img, buf, params))
      throw std::runtime_error("to_message: image encoding failed");
    msg.pixelformat = jpeg ? int32_t{aerie::image_t::PIXEL_FORMAT_MJPEG} : int32_t{aerie::image_t::PIXEL_FORMAT_PNG};
    msg.row_stride = 0;
    msg.data.assign(buf.begin(), buf.end());
  }
  msg.size = static_cast<int32_t>(msg.data.size());
  set_metadata(msg, "seq", std::to_string(seq));
  return msg;
}

std::optional<cv::Size> encoded_size(const uint8_t* d, size_t n, bool png) {
  const auto be16 = [&](size_t i) { return (int{d[i]} << 8) | d[i + 1]; };
  const auto be32 = [&](size_t i) {
    return (uint32_t{d[i]} << 24) | (uint32_t{d[i + 1]} << 16) | (uint32_t{d[i + 2]} << 8) | d[i + 3];
  };
  if (png) {  // signature, then the IHDR chunk: length, "IHDR", width, height (big-endian)
    static const uint8_t sig[8] = {0x89, 'P', 'N', 'G', '\r', '\n', 0x1a, '\n'};
    if (n < 24 || !std::equal(sig, sig + 8, d) || !std::equal(d + 12, d + 16, "IHDR")) return std::nullopt;
    const uint32_t w = be32(16), h = be32(20);
    if (w > INT32_MAX || h > INT32_MAX) return std::nullopt;
    return cv::Size(static_cast<int>(w), static_cast<int>(h));
  }
  if (n < 4 || d[0] != 0xFF || d[1] != 0xD8) return std::nullopt;  // SOI, then segments up to the frame header
  size_t i = 2;
  while (i + 4 <= n) {
    if (d[i] != 0xFF) return std::nullopt;
    const uint8_t marker = d[i + 1];
    if (marker == 0xFF) {  // fill byte
      ++i;
      continue;
    }
    const bool sof = marker >= 0xC0 && marker <= 0xCF && marker != 0xC4 && marker != 0xC8 && marker != 0xCC;
    if (sof) {
      if (i + 9 > n) return std::nullopt;
      return cv::Size(be16(i + 7), be16(i + 5));
    }
    if (marker == 0xDA || marker == 0xD9) return std::nullopt;  // scan or end before any frame header
    i += 2 + static_cast<size_t>(be16(i + 2));
  }
  return std::nullopt;
}

cv::Mat from_message(const aerie::image_t& msg, int64_t max_pixels) {
  auto bad = [&](const std::string& what) {
    throw std::invalid_argument("image message (utime " + std::to_string(msg.utime) + ", " +
                                pixel_format_name(msg.pixelformat) + "): " + what);
  };
  if (msg.width <= 0 || msg.height <= 0)
    bad("invalid size " + std::to_string(msg.width) + "x" + std::to_string(msg.height));
  if (static_cast<int64_t>(msg.width) * msg.height > max_pixels)
    bad("image of " + std::to_string(msg.width) + "x" + std::to_string(msg.height) + " is larger than the limit of " +
        std::to_string(max_pixels) + " pixels");
  if (msg.size != static_cast<int32_t>(msg.data.size())) bad("size field disagrees with the payload length");
  switch (msg.pixelformat) {
    case aerie::image_t::PIXEL_FORMAT_GRAY:
    case aerie::image_t::PIXEL_FORMAT_RGB:
    case aerie::image_t::PIXEL_FORMAT_BGR: {
      const int channels = msg.pixelformat == aerie::image_t::PIXEL_FORMAT_GRAY ? 1 : 3;
      const int64_t row_bytes = static_cast<int64_t>(msg.width) * channels;
      if (msg.row_stride < row_bytes) bad("row_stride " + std::to_string(msg.row_stride) + " is shorter than a row");
      if (static_cast<int64_t>(msg.row_stride) * msg.height > msg.size)
        bad("payload of " + std::to_string(msg.size) + " bytes is too short for " + std::to_string(msg.height) +
            " rows of stride " + std::to_string(msg.row_stride));
      const cv::Mat view(msg.height, msg.width, channels == 1 ? CV_8UC1 : CV_8UC3,
                         const_cast<uint8_t*>(msg.data.data()), static_cast<size_t>(msg.row_stride));
      cv::Mat out;
      if (msg.pixelformat == aerie::image_t::PIXEL_FORMAT_RGB)
        cv::cvtColor(view, out, cv::COLOR_RGB2BGR);
      else
        out = view.clone();
      return out;
    }
    case aerie::image_t::PIXEL_FORMAT_MJPEG:
    case aerie::image_t::PIXEL_FORMAT_PNG: {
      const auto declared = encoded_size(msg.data.data(), msg.data.size(), msg.pixelformat == aerie::image_t::PIXEL_FORMAT_PNG);
      if (!declared) bad("payload cannot be decoded: no readable " + pixel_format_name(msg.pixelformat) + " header");
      if (declared->width != msg.width || declared->height != msg.height)
        bad("payload declares " + std::to_string(declared->width) + "x" + std::to_string(declared->height) +
            ", header says " + std::to_string(msg.width) + "x" + std::to_string(msg.height) + " (not decoded)");
      const cv::Mat buf(1, msg.size, CV_8UC1, const_cast<uint8_t*>(msg.data.data()));
      cv::Mat out = cv::imdecode(buf, cv::IMREAD_UNCHANGED);
      if (out.empty()) bad("payload cannot be decoded");
      if (out.cols != msg.width || out.rows != msg.height)
        bad("decoded image is " + std::to_string(out.cols) + "x" + std::to_string(out.rows) + ", header says " +
            std::to_string(msg.width) + "x" + std::to_string(msg.height));
      if (out.depth() != CV_8U) bad("only 8-bit images are supported");
      if (out.channels() == 4) cv::cvtColor(out, out, cv::COLOR_BGRA2BGR);
      return out;
    }
    default: bad("unsupported pixel format");
  }
  return {};
}

cv::Mat gray_from_message(const aerie::image_t& msg, int64_t max_pixels) {
  cv::Mat img = from_message(msg, max_pixels);
  if (img.channels() == 3) cv::cvtColor(img, img, cv::COLOR_BGR2GRAY);
  return img;
}

void set_metadata(aerie::image_t& msg, const std::string& key, const std::string& value) {
  for (auto& m : msg.metadata) {
    if (m.key == key) {
      m.value.assign(value.begin(), value.end());
      m.n = static_cast<int32_t>(m.value.size());
      return;
    }
  }
  aerie::image_metadata_t m;
  m.key = key;
  m.value.assign(value.begin(), value.end());
  m.n = static_cast<int32_t>(m.value.size());
  msg.metadata.push_back(m);
  msg.nmetadata = static_cast<int32_t>(msg.metadata.size());
}

std::optional<std::string> metadata(const aerie::image_t& msg, const std::string& key) {
  for (const auto& m : msg.metadata)
    if (m.key == key) return std::string(m.value.begin(), m.value.end());
  return std::nullopt;
}

int64_t sequence_number(const aerie::image_t& msg) {
  const auto s = metadata(msg, "seq");
  if (!s) return -1;
  int64_t v = -1;
  const auto [p, ec] = std::from_chars(s->data(), s->data() + s->size(), v);
  return (ec == std::errc() && p == s->data() + s->size()) ? v : -1;
}

aerie::gt_box_t gt_box_message(int64_t utime, int64_t seq, const std::string& target, const std::string& camera,
                               bool visible, const cv::Rect2d& box, const std::array<cv::Point2d, 4>& corners) {
  aerie::gt_box_t g{};
  g.utime = utime;
  g.seq = seq;
  g.target = target;
  g.camera = camera;
  g.visible = visible;
  g.x = box.x;
  g.y = box.y;
  g.width = box.width;
  g.height = box.height;
  for (size_t i = 0; i < corners.size(); ++i) {
    g.corners[i][0] = corners[i].x;
    g.corners[i][1] = corners[i].y;
  }
  return g;
}

}  // namespace aerie::image
