#pragma once
// Optional image compression on the link: aerie.image_t and aerie.stereo_image_t
// payloads re-encoded as JPEG at a given quality so that camera streams fit a slow
// radio. Other types pass untouched (recognised by their LCM fingerprint).
#include <cstdint>
#include <optional>
#include <vector>

namespace aerie::link {

// The re-encoded payload; nullopt when it is not an image type, cannot be decoded,
// or would not get smaller.
std::optional<std::vector<uint8_t>> reencode_jpeg(const std::vector<uint8_t>& payload, int quality);

}  // namespace aerie::link
