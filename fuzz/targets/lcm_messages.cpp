// Every LCM message type of lcmtypes/ through the bounded decoder every subscription uses
// (bus::decode_bounded, common/bus/wire.hpp). One target for the whole catalogue: the input is
// one payload as it arrives on a channel (8-byte fingerprint + fields), and every type tries it
// as a subscriber of that type would, so the fingerprint selects the type that gets past the
// first check (libFuzzer learns the fingerprints from the seeds and from the comparisons).
// A payload a type accepts must encode again into a payload the decoder accepts (what a relay
// such as aerie-link forwards), and then goes through the conversion its subscribers apply:
// images decoded, VO_DEPTH unpacked (MAP_OCTOMAP's tree is read by the octomap target).
#include <cstdio>
#include <cstdlib>
#include <vector>

#include "common/bus/wire.hpp"
#include "common/image/image_message.hpp"
#include "common/spherical/spherical_message.hpp"
#include "fuzz/fuzz_support.hpp"
#include "fuzz_catalogue.hpp"

namespace {

using namespace aerie;

template <typename Msg>
void convert(const Msg&) {}
void convert(const aerie::image_t& m) { image::from_message(m); }
void convert(const aerie::stereo_image_t& m) {
  image::from_message(m.left);
  image::from_message(m.right);
}
void convert(const aerie::spherical_depth_t& m) {
  spherical::pose_of(m);
  spherical::from_message(m);
}

template <typename Msg>
void decode_as(const uint8_t* data, size_t size) {
  Msg msg{};
  if (!bus::decode_bounded(data, size, msg)) return;
  std::vector<uint8_t> again(static_cast<size_t>(msg.getEncodedSize()));
  Msg twice{};
  std::string why;
  if (msg.encode(again.data(), 0, static_cast<int>(again.size())) != static_cast<int>(again.size()) ||
      !bus::decode_bounded(again.data(), again.size(), twice, &why)) {
    std::fprintf(stderr, "%s: an accepted payload does not encode into an accepted one: %s\n", Msg::getTypeName(),
                 why.c_str());
    std::abort();
  }
  fuzz::refusal_ok([&] { convert(msg); });
}

template <typename... Msg>
void decode_as_every(fuzz::TypeList<Msg...>, const uint8_t* data, size_t size) {
  (decode_as<Msg>(data, size), ...);
}

}  // namespace

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
  fuzz::quiet();
  decode_as_every(fuzz::Catalogue{}, data, size);
  return 0;
}
