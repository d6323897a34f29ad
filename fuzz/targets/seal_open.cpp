// The sealed door's receive path (common/seal/seal.hpp: Opener::open), with a fixed test key
// (bytes 0, 1, ..., 31). The first input byte picks what the rest is, modulo 3:
//   0  a datagram as it comes off the radio, opened as is (the seeds hold datagrams sealed with
//      the test key, so mutations of authentic ones are tried too);
//   1  an inner plaintext ([channel length][channel][payload], malformed or not), sealed with the
//      test key and opened: it must open exactly when the target's own reading of the rules
//      says it is well formed, with that channel and payload, and be refused otherwise;
//   2  [position u16 LE][xor byte][payload...]: the payload is sealed on channel "FUZZ", one
//      byte of the datagram is changed, and the result must be refused (unless unchanged); the
//      genuine datagram must then open once and its replay be refused.
// Anything else, or an exception from open(), aborts.
#include <algorithm>
#include <cstdio>
#include <cstdlib>
#include <string>
#include <span>
#include <vector>

#include "common/seal/seal.hpp"
#include "common/seal/testing.hpp"

namespace {

using namespace aerie;

const seal::SecretKey& test_key() {
  static const seal::SecretKey key = seal::for_tests::counting_key(0);
  return key;
}

[[noreturn]] void fail(const char* what, const seal::Opened& o) {
  std::fprintf(stderr, "seal_open: %s (refusal \"%s\": %s)\n", what, seal::to_string(o.refusal), o.why.c_str());
  std::abort();
}

void check_opened(const seal::Opened& o) {
  if (!o.ok()) return;
  if (!seal::valid_channel(o.channel)) fail("opened an invalid channel name", o);
  if (o.payload.size() > seal::kMaxPayload) fail("opened an oversize payload", o);
}

void raw(std::span<const uint8_t> d) {
  seal::Opener opener(test_key(), {.direction = seal::Direction::AirToGround});
  const seal::Opened first = opener.open(d, 0);
  check_opened(first);
  const seal::Opened again = opener.open(d, 0);
  if (again.ok()) fail("the same datagram opened twice", again);
  if (opener.counters().opened + opener.counters().refused_total() != 2) fail("a datagram was not counted", again);
}

void inner(std::span<const uint8_t> plain) {
  seal::Opener opener(test_key(), {.direction = seal::Direction::AirToGround});
  seal::for_tests::RawHeader h;
  h.sender = 9;
  const seal::Opened o = opener.open(seal::for_tests::seal_plaintext(test_key(), h, plain), 0);
  // The rules, read independently of seal.cpp.
  bool well_formed = !plain.empty() && plain[0] >= 1 && plain[0] <= seal::kMaxChannel && 1u + plain[0] <= plain.size();
  if (well_formed)
    for (size_t i = 1; i <= plain[0]; ++i) well_formed = well_formed && plain[i] >= 0x21 && plain[i] <= 0x7e;
  if (well_formed) well_formed = plain.size() - 1 - plain[0] <= seal::kMaxPayload;
  const bool fits = seal::kHeaderSize + plain.size() + seal::kTagSize <= seal::kMaxDatagram &&
                    seal::kHeaderSize + plain.size() + seal::kTagSize >= seal::kMinDatagram;
  if (!fits) {
    if (o.ok()) fail("opened a datagram outside the size limits", o);
    return;
  }
  if (well_formed != o.ok()) fail(well_formed ? "refused a well-formed plaintext" : "opened a malformed plaintext", o);
  if (o.ok()) {
    const std::string channel(reinterpret_cast<const char*>(plain.data() + 1), plain[0]);
    if (o.channel != channel) fail("opened another channel name", o);
    if (!std::equal(o.payload.begin(), o.payload.end(), plain.begin() + 1 + plain[0], plain.end()) ||
        o.payload.size() != plain.size() - 1 - plain[0])
      fail("opened another payload", o);
  } else if (o.refusal != seal::Refusal::ChannelMalformed && o.refusal != seal::Refusal::Oversize) {
    fail("refused a malformed plaintext for another reason", o);
  }
}

void tampered(std::span<const uint8_t> in) {
  if (in.size() < 3) return;
  const size_t position = in[0] | (size_t{in[1]} << 8);
  const uint8_t flip = in[2];
  std::span<const uint8_t> payload = in.subspan(3);
  if (payload.size() > seal::kMaxPayload) payload = payload.first(seal::kMaxPayload);
  seal::Sealer sealer(test_key(), seal::Direction::AirToGround, 3, 0, 0.0);
  seal::Opener opener(test_key(), {.direction = seal::Direction::AirToGround});
  const std::vector<uint8_t> genuine = sealer.seal("FUZZ", payload, 0);
  std::vector<uint8_t> t = genuine;
  t[position % t.size()] ^= flip;
  const seal::Opened o = opener.open(t, 0);
  if (flip != 0 && o.ok()) fail("opened a tampered datagram", o);
  if (flip == 0 && !o.ok()) fail("refused an untouched datagram", o);
  if (flip != 0) {
    const seal::Opened g = opener.open(genuine, 0);
    if (!g.ok() || g.channel != "FUZZ" || !std::equal(g.payload.begin(), g.payload.end(), payload.begin(), payload.end()))
      fail("the genuine datagram did not open after a tampered one", g);
  }
  const seal::Opened replay = opener.open(genuine, 0);
  if (replay.ok() || replay.refusal != seal::Refusal::Replayed) fail("a replay was not refused as replayed", replay);
}

}  // namespace

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
  if (size == 0) return 0;
  const std::span<const uint8_t> rest(data + 1, size - 1);
  switch (data[0] % 3) {
    case 0: raw(rest); break;
    case 1: inner(rest); break;
    default: tampered(rest); break;
  }
  return 0;
}
