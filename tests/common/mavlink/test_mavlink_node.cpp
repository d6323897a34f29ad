// Cross-check against node-mavlink 2.3.0 (npm, an independent implementation): every frame Aerie
// writes, signed ones included, is decoded by node-mavlink with CRC and signature accepted and the
// same field values; every frame node-mavlink writes, signed ones included, is decoded by Aerie.
// node-mavlink is installed into the build tree by the CTest fixture mavlink_node_install. Without
// `node` on the machine the tests skip; with node, any disagreement (or a missing install) fails.
#include <gtest/gtest.h>

#include <cstdio>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <string>
#include <vector>

#include "common/mavlink/frame.hpp"
#include "common/mavlink/parser.hpp"
#include "common/mavlink/signing.hpp"
#include "tests/common/mavlink/sample_values.hpp"

namespace mav = aerie::mavlink;
namespace fs = std::filesystem;

namespace {

constexpr uint64_t kT0 = 1'000'000'000;  // signing ticks (2015 + 10 000 s)

const std::string kScript = std::string(AERIE_SOURCE_DIR) + "/tests/common/mavlink/node_crosscheck.cjs";

mav::Key test_key() {
  mav::Key key;
  for (size_t i = 0; i < key.size(); ++i) key[i] = static_cast<uint8_t>(0x42 + 3 * i);
  return key;
}

std::string key_hex(const mav::Key& key) {
  static const char* digits = "0123456789abcdef";
  std::string out;
  for (uint8_t b : key) {
    out += digits[b >> 4];
    out += digits[b & 15];
  }
  return out;
}

bool have_node() { return std::system("command -v node >/dev/null 2>&1") == 0; }

struct CommandResult {
  int status;
  std::string output;
};

CommandResult run(const std::string& command) {
  CommandResult r{-1, ""};
  FILE* p = ::popen((command + " 2>&1").c_str(), "r");
  if (!p) return r;
  char buf[4096];
  size_t n;
  while ((n = std::fread(buf, 1, sizeof buf, p)) > 0) r.output.append(buf, n);
  r.status = ::pclose(p);
  return r;
}

fs::path work_dir(const std::string& name) {
  const fs::path dir = fs::path(AERIE_BINARY_DIR) / "tests" / "mavlink_node" / name;
  fs::remove_all(dir);
  fs::create_directories(dir);
  return dir;
}

struct Entry {
  std::string json;          // one line of EXPECTED
  mav::Message message;      // what it holds
  mav::Header header;
  bool is_signed;
  uint8_t link;
  uint64_t timestamp;
};

template <class M>
void add_entries(std::vector<Entry>& out, int seed, uint8_t& seq, uint64_t& ts) {
  for (const bool is_signed : {false, true}) {
    const M msg = mav::testing::sample<M>(seed + (is_signed ? 1 : 0));
    Entry e{"", msg, {static_cast<uint8_t>(is_signed ? 2 : 1), 191, seq++}, is_signed, 3, is_signed ? (ts += 100) : 0};
    e.json = "{\"name\":\"" + std::string(M::kName) + "\",\"msgid\":" + std::to_string(M::kId) +
             ",\"sysid\":" + std::to_string(e.header.sysid) + ",\"compid\":" + std::to_string(e.header.compid) +
             ",\"seq\":" + std::to_string(e.header.seq) + ",\"signed\":" + (is_signed ? "true" : "false") +
             ",\"link\":" + std::to_string(e.link) + ",\"timestamp\":\"" + std::to_string(e.timestamp) +
             "\",\"fields\":" + mav::testing::fields_json(msg) + "}";
    out.push_back(std::move(e));
  }
}

template <class... M>
std::vector<Entry> entries(int seed, std::variant<M...>*) {
  std::vector<Entry> out;
  uint8_t seq = 0;
  uint64_t ts = kT0;
  (add_entries<M>(out, seed, seq, ts), ...);
  return out;
}

void write_expected(const fs::path& file, const std::vector<Entry>& list) {
  std::ofstream out(file);
  for (const Entry& e : list) out << e.json << "\n";
}

std::string modules_dir() { return AERIE_NODE_MAVLINK_DIR; }

void require_install() {
  ASSERT_TRUE(fs::exists(fs::path(modules_dir()) / "node_modules" / "node-mavlink" / "package.json"))
      << "node is on this machine but node-mavlink is not installed in " << modules_dir()
      << " (the fixture test mavlink_node_install installs it)";
}

}  // namespace

TEST(MavlinkNode, AerieFramesDecodedByNodeMavlink) {
  if (!have_node()) GTEST_SKIP() << "node is not installed: no cross-check possible";
  require_install();
  const fs::path dir = work_dir("aerie_to_node");
  const auto list = entries(10, static_cast<mav::Message*>(nullptr));
  ASSERT_EQ(list.size(), 2 * std::variant_size_v<mav::Message>);
  write_expected(dir / "expected.jsonl", list);

  uint64_t clock_now = kT0;
  mav::Signer signer(test_key(), 3, 0, [&] { return clock_now; });
  std::vector<uint8_t> bytes;
  for (const Entry& e : list) {
    std::vector<uint8_t> frame;
    if (e.is_signed) {
      clock_now = e.timestamp;  // the signer takes max(clock, last + 1): exactly this timestamp
      frame = std::visit([&](const auto& m) { return mav::encode(m, e.header, signer); }, e.message);
    } else {
      frame = std::visit([&](const auto& m) { return mav::encode(m, e.header); }, e.message);
    }
    bytes.insert(bytes.end(), frame.begin(), frame.end());
  }
  std::ofstream(dir / "frames.bin", std::ios::binary).write(reinterpret_cast<const char*>(bytes.data()),
                                                            static_cast<std::streamsize>(bytes.size()));
  const CommandResult r = run("node '" + kScript + "' check '" + modules_dir() + "' '" + (dir / "frames.bin").string() + "' '" +
                    (dir / "expected.jsonl").string() + "' " + key_hex(test_key()));
  EXPECT_EQ(r.status, 0) << r.output;
  EXPECT_NE(r.output.find("OK " + std::to_string(list.size()) + " frames"), std::string::npos) << r.output;
}

TEST(MavlinkNode, NodeMavlinkFramesDecodedByAerie) {
  if (!have_node()) GTEST_SKIP() << "node is not installed: no cross-check possible";
  require_install();
  const fs::path dir = work_dir("node_to_aerie");
  const auto list = entries(20, static_cast<mav::Message*>(nullptr));
  write_expected(dir / "expected.jsonl", list);
  const CommandResult r = run("node '" + kScript + "' write '" + modules_dir() + "' '" + (dir / "expected.jsonl").string() + "' '" +
                    (dir / "frames.bin").string() + "' " + key_hex(test_key()));
  ASSERT_EQ(r.status, 0) << r.output;

  std::ifstream in(dir / "frames.bin", std::ios::binary);
  const std::vector<uint8_t> bytes((std::istreambuf_iterator<char>(in)), std::istreambuf_iterator<char>());
  mav::Parser parser;
  // Signing required: node-mavlink's unsigned frames are refused but those PX4 accepts unsigned.
  parser.set_signing(test_key(), true, [] { return kT0; });
  const auto strict = parser.feed(bytes);
  size_t expected_strict = 0;
  for (const Entry& e : list) {
    const uint32_t id = std::visit([](const auto& m) { return std::decay_t<decltype(m)>::kId; }, e.message);
    if (e.is_signed || mav::accepted_unsigned(id)) ++expected_strict;
  }
  EXPECT_EQ(strict.size(), expected_strict) << parser.last_error();
  EXPECT_EQ(parser.counters().unsigned_refused, list.size() - expected_strict);
  EXPECT_EQ(parser.counters().bad_signature, 0u) << parser.last_error();
  EXPECT_EQ(parser.counters().refused(), list.size() - expected_strict) << parser.last_error();

  mav::Parser lenient;
  lenient.set_signing(test_key(), false, [] { return kT0; });
  const auto frames = lenient.feed(bytes);
  EXPECT_EQ(lenient.counters().refused(), 0u) << lenient.last_error();
  EXPECT_EQ(lenient.counters().garbage_bytes, 0u);
  ASSERT_EQ(frames.size(), list.size()) << lenient.last_error();
  for (size_t i = 0; i < list.size(); ++i) {
    const Entry& e = list[i];
    const mav::Frame& f = frames[i];
    SCOPED_TRACE(e.json.substr(0, 60));
    EXPECT_EQ(f.sysid, e.header.sysid);
    EXPECT_EQ(f.compid, e.header.compid);
    EXPECT_EQ(f.seq, e.header.seq);
    ASSERT_EQ(f.signature.has_value(), e.is_signed);
    if (e.is_signed) {
      EXPECT_EQ(f.signature->link_id, e.link);
      EXPECT_EQ(f.signature->timestamp, e.timestamp);
    }
    std::visit(
        [&](const auto& want) {
          using M = std::decay_t<decltype(want)>;
          ASSERT_EQ(f.msgid, M::kId);
          // node-mavlink truncates as Aerie does: the same payload bytes.
          EXPECT_EQ(f.payload, mav::make_frame(want, e.header).payload);
          EXPECT_EQ(mav::testing::fields_json(mav::decode<M>(f)), mav::testing::fields_json(want));
        },
        e.message);
  }
}
