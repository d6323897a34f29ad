// aerie-link's relay (tools/link/relay.hpp: re-encoding of images as JPEG, then the link model:
// queue, bandwidth, loss, delay and jitter with config/link.yaml's fixed seeds) fed raw messages
// on both networks (fuzz_support.hpp: kLinkChannels, the first kLinkAirChannels published on the
// air bus, the others on the ground bus; record format there), with config/link.yaml's two
// directions as aerie-link loads them. The relays run as in the lock-step split deployments
// (tools/link/sim_link.hpp: SplitBus, two memq:// buses joined by a SimLink, the link's clock
// advancing 10 ms per message, and at the end 10 s more so that everything queued is delivered
// or dropped); aerie-link's own loop (link_main.cpp: sockets, the multicast echo filter,
// LINK_STATS) is not run. What comes out on the ground bus must be a message published on the
// air bus, byte for byte, or an image the relay re-encoded, which a receiver must accept (bounded
// decoding, both images of a stereo pair decoded): otherwise the target aborts.
#include <aerie/image_t.hpp>
#include <aerie/stereo_image_t.hpp>

#include <cstdio>
#include <cstdlib>
#include <set>
#include <utility>

#include "common/bus/wire.hpp"
#include "common/image/image_message.hpp"
#include "common/util/config.hpp"
#include "fuzz/fuzz_support.hpp"
#include "tools/link/link_config.hpp"
#include "tools/link/sim_link.hpp"

namespace {

using namespace aerie;
using Sent = std::set<std::pair<std::string, std::vector<uint8_t>>>;

const link::Split& split() {
  static const link::Split s = [] {
    const link::LinkConfig c = link::load_link_config(util::Config::load(fuzz::source_path("config/link.yaml")));
    link::Split s;
    s.down = c.air_to_ground;
    s.up = c.ground_to_air;
    return s;
  }();
  return s;
}

// What a receiver does with an image the relay re-encoded; false (and why) when it refuses it.
bool receivable(const uint8_t* data, size_t size, std::string& why) {
  try {
    aerie::image_t image;
    if (bus::decode_bounded(data, size, image, &why)) {
      image::from_message(image);
      return true;
    }
    aerie::stereo_image_t stereo;
    if (bus::decode_bounded(data, size, stereo, &why)) {
      image::from_message(stereo.left);
      image::from_message(stereo.right);
      return true;
    }
  } catch (const std::exception& e) {
    why = e.what();
  }
  return false;
}

}  // namespace

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
  fuzz::quiet();
  link::SplitBus buses(split());
  Sent from_air, from_ground;
  static link::ChannelMatcher jpeg(split().down.jpeg_channels);  // its regex compiled once
  buses.on(link::Side::kGround)
      .subscribe_raw(".*", [&](const uint8_t* d, size_t n, const bus::ReceiveInfo& info) {
        std::pair<std::string, std::vector<uint8_t>> m{info.channel, {d, d + n}};
        if (from_ground.count(m) || from_air.count(m)) return;  // published here, or relayed as it was
        std::string why = "not an image";
        if (jpeg(info.channel) && receivable(d, n, why)) return;
        std::fprintf(stderr, "link: %s delivered a %zu-byte message on %s that no one sent and no receiver accepts: %s\n",
                     split().down.name.c_str(), n, info.channel.c_str(), why.c_str());
        std::abort();
      }, 100000);
  const auto& ch = fuzz::kLinkChannels;
  int64_t now = 1'000'000;
  for (const fuzz::Record& r : fuzz::split_records(data, size, ch.size())) {
    const bool air = r.channel < fuzz::kLinkAirChannels;
    (air ? from_air : from_ground).insert({ch[r.channel], {r.payload.begin(), r.payload.end()}});
    buses.on(air ? link::Side::kAir : link::Side::kGround)
        .publish_raw(ch[r.channel], r.payload.data(), r.payload.size());
    buses.settle(now);
    now += 10'000;
  }
  buses.settle(now + 10'000'000);
  return 0;
}
