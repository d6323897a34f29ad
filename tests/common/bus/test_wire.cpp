// Bounded decoding (common/bus/wire.hpp): the reproducers of the reliability issue are refused
// with a reason naming type, field and value; random valid messages of every type round-trip;
// every truncation and random corruption is refused or decodes exactly.
#include <gtest/gtest.h>

#include <algorithm>
#include <cstring>
#include <random>

#include "catalogue_types.hpp"
#include "common/bus/wire.hpp"
#include "tests/common/bus/reliability_data.hpp"

namespace fs = std::filesystem;
using aerie::bus::decode_bounded;
using aerie::bus::wire_error;
namespace wire = aerie::bus::wire;

namespace {

const wire::Entry* find_entry(const std::vector<uint8_t>& payload) {
  if (payload.size() < 8) return nullptr;
  uint64_t fp = 0;
  for (int i = 0; i < 8; ++i) fp = (fp << 8) | payload[i];
  for (const wire::Entry& e : wire::catalogue())
    if (static_cast<uint64_t>(e.hash()) == fp) return &e;
  return nullptr;
}

// A random well-formed encoding of a type, built from its wire schema: small counts and
// strings, random scalars (finite floats, so that a decode/encode round trip is bit exact).
class RandomPayload {
 public:
  explicit RandomPayload(uint32_t seed) : rng_(seed) {}

  std::vector<uint8_t> make(int64_t hash) {
    out_.clear();
    put(static_cast<uint64_t>(hash), 8);
    for (const wire::Entry& e : wire::catalogue())
      if (e.hash() == hash) fill(*e.type);
    return out_;
  }

 private:
  void put(uint64_t v, size_t bytes) {
    for (size_t i = bytes; i-- > 0;) out_.push_back(static_cast<uint8_t>(v >> (8 * i)));
  }

  void fill(const wire::Type& t) {
    std::vector<int64_t> counts(t.fields.size(), 0);
    for (size_t i = 0; i < t.fields.size(); ++i) {
      const wire::Field& f = t.fields[i];
      int64_t n = 1;
      for (const wire::Dim& d : f.dims) n *= d.field < 0 ? d.size : counts[static_cast<size_t>(d.field)];
      for (int64_t k = 0; k < n; ++k) element(f, counts[i]);
    }
  }

  void element(const wire::Field& f, int64_t& count) {
    const size_t bytes = wire::primitive_bytes(f.kind);
    switch (f.kind) {
      case wire::Kind::String: {
        const auto len = static_cast<uint32_t>(rng_() % 12);
        put(len + 1, 4);
        for (uint32_t c = 0; c < len; ++c) put(' ' + rng_() % 95, 1);
        put(0, 1);
        break;
      }
      case wire::Kind::Struct: fill(*f.type); break;
      case wire::Kind::Boolean: put(rng_() % 2, 1); break;
      case wire::Kind::Float: {
        const float v = std::uniform_real_distribution<float>(-1e6f, 1e6f)(rng_);
        uint32_t u;
        std::memcpy(&u, &v, 4);
        put(u, 4);
        break;
      }
      case wire::Kind::Double: {
        const double v = std::uniform_real_distribution<double>(-1e9, 1e9)(rng_);
        uint64_t u;
        std::memcpy(&u, &v, 8);
        put(u, 8);
        break;
      }
      default:  // integers; those that may be counts stay small
        count = f.dims.empty() ? static_cast<int64_t>(rng_() % 4) : 0;
        put(f.dims.empty() ? static_cast<uint64_t>(count) : rng_(), bytes);
    }
  }

  std::mt19937_64 rng_;
  std::vector<uint8_t> out_;
};

template <typename Msg>
std::vector<uint8_t> encode(const Msg& m) {
  std::vector<uint8_t> out(static_cast<size_t>(m.getEncodedSize()));
  EXPECT_EQ(m.encode(out.data(), 0, static_cast<int>(out.size())), static_cast<int>(out.size()));
  return out;
}

}  // namespace

TEST(WireReproducers, EveryCraftedLengthIsRefusedWithItsReason) {
  for (const auto& r : aerie::test::kWireReproducers) {
    const auto bytes = aerie::test::read_bytes(aerie::test::reliability_data_dir() / r.file);
    const wire::Entry* e = find_entry(bytes);
    ASSERT_NE(e, nullptr) << r.file << ": fingerprint of no catalogue type";
    const auto why = wire_error(e->hash(), bytes.data(), bytes.size());
    ASSERT_TRUE(why) << r.file << " accepted";
    EXPECT_NE(why->find(r.reason), std::string::npos) << r.file << ": " << *why;
  }
}

// Every payload of ../shared/reliability/repro: the copies here hold the same bytes, and those
// not in the list above are well-formed messages with hostile values (for the nodes to refuse).
TEST(WireReproducers, SharedPayloadsAreCopiedAndTheRestAreWellFormed) {
  const fs::path shared = AERIE_SOURCE_DIR "/../shared/reliability/repro";
  if (!fs::is_directory(shared)) GTEST_SKIP() << shared << " is absent";
  for (const auto& entry : fs::directory_iterator(shared)) {
    if (entry.path().extension() != ".bin") continue;
    const auto bytes = aerie::test::read_bytes(entry.path());
    const fs::path copy = aerie::test::reliability_data_dir() / entry.path().filename();
    if (bytes.size() <= 300 * 1024) {
      EXPECT_EQ(aerie::test::read_bytes(copy), bytes) << copy << " differs";
    }
    const wire::Entry* e = find_entry(bytes);
    ASSERT_NE(e, nullptr) << entry.path() << ": fingerprint of no catalogue type";
    const bool listed = std::any_of(aerie::test::kWireReproducers.begin(), aerie::test::kWireReproducers.end(),
                                    [&](const auto& r) { return entry.path().filename() == r.file; });
    EXPECT_EQ(wire_error(e->hash(), bytes.data(), bytes.size()).has_value(), listed) << entry.path();
  }
}

template <typename Msg>
class WireTyped : public ::testing::Test {};
TYPED_TEST_SUITE(WireTyped, CatalogueTypes);

TYPED_TEST(WireTyped, RandomMessagesRoundTrip) {
  for (uint32_t seed = 0; seed < 40; ++seed) {
    const auto bytes = RandomPayload(seed).make(TypeParam::getHash());
    TypeParam msg;
    std::string why;
    ASSERT_TRUE(decode_bounded(bytes.data(), bytes.size(), msg, &why)) << why;
    const auto encoded = encode(msg);  // encode -> validate -> decode -> encode
    ASSERT_EQ(encoded, bytes);
    EXPECT_FALSE(wire_error(TypeParam::getHash(), encoded.data(), encoded.size()));
    EXPECT_EQ(encode(decode_bounded<TypeParam>(encoded.data(), encoded.size())), encoded);
  }
}

TYPED_TEST(WireTyped, EveryTruncationAndTrailingByteIsRefused) {
  for (uint32_t seed = 0; seed < 4; ++seed) {
    const auto bytes = RandomPayload(seed).make(TypeParam::getHash());
    for (size_t n = 0; n < bytes.size(); ++n) {
      const std::vector<uint8_t> cut(bytes.begin(), bytes.begin() + static_cast<std::ptrdiff_t>(n));
      TypeParam msg;
      EXPECT_FALSE(decode_bounded(cut.data(), cut.size(), msg)) << n << " of " << bytes.size() << " bytes accepted";
    }
    auto longer = bytes;
    longer.push_back(0);
    EXPECT_TRUE(wire_error(TypeParam::getHash(), longer.data(), longer.size()));
  }
}

// Random corruption, with a bias to hostile length prefixes: whatever the check accepts, the
// lcm-gen decoder decodes to the last byte.
TYPED_TEST(WireTyped, CorruptedMessagesAreRefusedOrDecodeExactly) {
  std::mt19937 rng(7);
  const uint32_t hostile[] = {0x80000000u, 0xffffffffu, 0x7fffffffu, 0x20000001u, 0x40000001u, 0u, 1u};
  for (uint32_t seed = 0; seed < 300; ++seed) {
    auto bytes = RandomPayload(seed).make(TypeParam::getHash());
    const size_t at = 8 + rng() % (bytes.size() - 8);
    if (seed % 2 == 0 && at + 4 <= bytes.size()) {
      const uint32_t v = hostile[rng() % std::size(hostile)];
      for (int i = 0; i < 4; ++i) bytes[at + static_cast<size_t>(i)] = static_cast<uint8_t>(v >> (24 - 8 * i));
    } else {
      bytes[at] ^= static_cast<uint8_t>(1 + rng() % 255);
    }
    if (!wire_error(TypeParam::getHash(), bytes.data(), bytes.size())) {
      TypeParam msg;
      EXPECT_EQ(msg.decode(bytes.data(), 0, static_cast<int>(bytes.size())), static_cast<int>(bytes.size()));
    }
  }
}

TEST(Wire, ReasonsNameTypeFieldAndValue) {
  aerie::track_cmd_t cmd{};
  cmd.nparams = 1;
  cmd.param_names = {"sigma"};
  cmd.param_values = {"2"};
  auto bytes = encode(cmd);
  // utime, seq, command, tracker "", camera "", x y w h, nparams = 1, param_names[0] "sigma"
  const size_t names0 = 8 + 8 + 8 + 1 + 5 + 5 + 32 + 4;
  bytes[names0 + 3] = 0;  // length 6 -> 0
  EXPECT_EQ(wire_error(aerie::track_cmd_t::getHash(), bytes.data(), bytes.size()),
            "aerie.track_cmd_t.param_names[0]: string length 0 lacks the NUL terminator it counts");
  bytes = encode(cmd);
  bytes[names0 + 3 + 6] = 'x';  // the NUL of "sigma"
  EXPECT_EQ(wire_error(aerie::track_cmd_t::getHash(), bytes.data(), bytes.size()),
            "aerie.track_cmd_t.param_names[0]: string length 6 does not end with NUL");
  bytes = encode(cmd);
  bytes[names0 - 2] = 0x03;  // nparams 1 -> 769: under the cap, over what the bytes hold
  EXPECT_EQ(wire_error(aerie::track_cmd_t::getHash(), bytes.data(), bytes.size()),
            "aerie.track_cmd_t.param_names: count nparams = 769 of at least 5 bytes cannot fit in the 16 bytes left");
  aerie::pose_t pose{};
  const auto other = encode(pose);
  const auto why = wire_error(aerie::track_cmd_t::getHash(), other.data(), other.size());
  ASSERT_TRUE(why);
  EXPECT_EQ(why->rfind("aerie.track_cmd_t: fingerprint 0x", 0), 0u) << *why;
  EXPECT_THROW(decode_bounded<aerie::track_cmd_t>(other.data(), other.size()), std::invalid_argument);
}
