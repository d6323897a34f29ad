// MAVLink parser (common/mavlink/parser.hpp), two ways on every input:
//  * raw: the input as a byte stream, whole and in chunks, into a parser without signing and one
//    that requires it (garbage, resynchronisation, refusals; it must never throw);
//  * built: the input read as a recipe of frames that get valid CRCs and, where the recipe says,
//    valid signatures, so that mutations reach the payload decoders. Each recipe record:
//      1 byte  catalogue index (modulo its size)
//      1 byte  flags: bit 0 signed, bit 1 MAVLink 1 (ids < 256), bit 2 flip one byte after framing
//      1 byte  payload length (a length over the message's maximum is refused by the parser)
//      N bytes payload (fewer when the input ends)
//    Every accepted frame is decoded, and its message encoded again must give the frame's payload
//    zero-filled to the message's length and then truncated (MAVLink 2 rules).
#include <cstdint>
#include <cstdio>
#include <cstdlib>
#include <span>
#include <vector>

#include "common/mavlink/frame.hpp"
#include "common/mavlink/parser.hpp"
#include "common/mavlink/signing.hpp"

namespace {

namespace mav = aerie::mavlink;

constexpr uint64_t kNow = 400'000'000;

mav::Key fuzz_key() {
  mav::Key key;
  key.fill(0x5A);
  return key;
}

void check_frame(const mav::Frame& frame) {
  const mav::MessageInfo* info = mav::find_message(frame.msgid);
  if (!info) {
    std::fprintf(stderr, "the parser accepted message id %u that is not in the catalogue\n", frame.msgid);
    std::abort();
  }
  if (frame.payload.size() > info->max_length) {
    std::fprintf(stderr, "the parser accepted a %zu-byte payload for %u\n", frame.payload.size(), frame.msgid);
    std::abort();
  }
  const auto msg = mav::decode_message(frame);
  std::vector<uint8_t> expected(frame.payload);
  expected.resize(info->max_length, 0);
  while (expected.size() > 1 && expected.back() == 0) expected.pop_back();
  const std::vector<uint8_t> again =
      std::visit([&](const auto& m) { return mav::make_frame(m, {frame.sysid, frame.compid, frame.seq}).payload; }, *msg);
  if (again != expected) {
    std::fprintf(stderr, "%s: decode then encode does not give the payload back\n", std::string(info->name).c_str());
    std::abort();
  }
}

void feed_raw(const uint8_t* data, size_t size) {
  mav::Parser open;
  open.feed(std::span<const uint8_t>(data, size), check_frame);
  mav::Parser strict;
  strict.set_signing(fuzz_key(), true, [] { return kNow; });
  const size_t chunk = size ? 1 + data[0] % 17 : 1;
  for (size_t at = 0; at < size; at += chunk)
    strict.feed(std::span<const uint8_t>(data + at, std::min(chunk, size - at)), check_frame);
}

void feed_built(const uint8_t* data, size_t size) {
  uint64_t clock = kNow;
  mav::Signer signer(fuzz_key(), 1, 0, [&] { return clock; });
  std::vector<uint8_t> stream;
  size_t at = 0;
  uint8_t seq = 0;
  while (at + 3 <= size) {
    const mav::MessageInfo& info = mav::kCatalogue[data[at] % mav::kCatalogue.size()];
    const uint8_t flags = data[at + 1];
    const size_t len = std::min<size_t>(data[at + 2], size - at - 3);
    at += 3;
    mav::Frame frame;
    frame.msgid = info.id;
    frame.sysid = 1;
    frame.compid = 1;
    frame.seq = seq++;
    frame.payload.assign(data + at, data + at + len);
    at += len;
    if (frame.payload.empty()) frame.payload.push_back(0);
    const bool v1 = (flags & 2) && info.id < 256;
    if (v1) frame.version = 1;
    std::vector<uint8_t> bytes = (flags & 1) && !v1 ? mav::serialize(frame, signer) : mav::serialize(frame);
    if (flags & 4) bytes[(flags >> 3) % bytes.size()] ^= static_cast<uint8_t>(1 + (seq & 0x7F));
    stream.insert(stream.end(), bytes.begin(), bytes.end());
    clock += flags >> 4;  // the signer stays monotonic whatever the clock does
  }
  mav::Parser lenient;
  lenient.set_signing(fuzz_key(), false, [] { return kNow; });
  lenient.feed(stream, check_frame);
  mav::Parser strict;
  strict.set_signing(fuzz_key(), true, [] { return kNow; });
  strict.feed(stream, check_frame);
}

}  // namespace

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
  feed_raw(data, size);
  feed_built(data, size);
  return 0;
}
