#include "tools/link/reencode.hpp"

#include <aerie/image_t.hpp>
#include <aerie/stereo_image_t.hpp>

#include <cstring>

#include "common/bus/wire.hpp"
#include "common/image/image_message.hpp"

namespace aerie::link {
namespace {

uint64_t fingerprint(const std::vector<uint8_t>& p) {
  uint64_t h = 0;
  for (size_t i = 0; i < 8 && i < p.size(); ++i) h = (h << 8) | p[i];
  return h;
}

// JPEG of the same picture, metadata kept.
aerie::image_t to_jpeg(const aerie::image_t& in, int quality) {
  const cv::Mat img = image::from_message(in);
  aerie::image_t out = image::to_message(img, in.utime, -1, image::Encoding::Jpeg, quality);
  out.metadata = in.metadata;
  out.nmetadata = in.nmetadata;
  return out;
}

template <typename Msg>
std::vector<uint8_t> encode(const Msg& m) {
  std::vector<uint8_t> out(static_cast<size_t>(m.getEncodedSize()));
  m.encode(out.data(), 0, static_cast<int>(out.size()));
  return out;
}

}  // namespace

std::optional<std::vector<uint8_t>> reencode_jpeg(const std::vector<uint8_t>& payload, int quality) {
  if (payload.size() < 8) return std::nullopt;
  const uint64_t fp = fingerprint(payload);
  std::vector<uint8_t> out;
  try {
    if (fp == static_cast<uint64_t>(aerie::image_t::getHash())) {
      aerie::image_t m;
      if (!bus::decode_bounded(payload.data(), payload.size(), m)) return std::nullopt;
      out = encode(to_jpeg(m, quality));
    } else if (fp == static_cast<uint64_t>(aerie::stereo_image_t::getHash())) {
      aerie::stereo_image_t m;
      if (!bus::decode_bounded(payload.data(), payload.size(), m)) return std::nullopt;
      m.left = to_jpeg(m.left, quality);
      m.right = to_jpeg(m.right, quality);
      out = encode(m);
    } else {
      return std::nullopt;
    }
  } catch (const std::exception&) {
    return std::nullopt;  // undecodable image: relayed as it is
  }
  if (out.size() >= payload.size()) return std::nullopt;
  return out;
}

}  // namespace aerie::link
