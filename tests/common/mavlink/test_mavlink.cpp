// aerie_mavlink: test vectors of ../shared/mavlink/README.md, the catalogue against the official
// XML definitions, round trips, the parser's refusals and the signing rules.
#include <gtest/gtest.h>
#include <sys/stat.h>

#include <algorithm>
#include <filesystem>
#include <fstream>
#include <map>
#include <random>
#include <set>
#include <unistd.h>
#include <sstream>
#include <string>
#include <vector>

#include "common/mavlink/catalogue.hpp"
#include "common/mavlink/crc.hpp"
#include "common/mavlink/frame.hpp"
#include "common/mavlink/parser.hpp"
#include "common/mavlink/signing.hpp"
#include "tests/common/mavlink/sample_values.hpp"

namespace mav = aerie::mavlink;

namespace {

std::vector<uint8_t> from_hex(const std::string& hex) {
  std::vector<uint8_t> out;
  for (size_t i = 0; i + 1 < hex.size(); i += 2) out.push_back(static_cast<uint8_t>(std::stoi(hex.substr(i, 2), nullptr, 16)));
  return out;
}

std::string to_hex(const std::vector<uint8_t>& bytes) {
  static const char* digits = "0123456789abcdef";
  std::string out;
  for (uint8_t b : bytes) {
    out += digits[b >> 4];
    out += digits[b & 15];
  }
  return out;
}

mav::Key key_of(uint8_t byte) {
  mav::Key key;
  key.fill(byte);
  return key;
}

// A settable signing clock.
struct FakeClock {
  uint64_t now = 1000;
  mav::SigningClock fn() {
    return [this] { return now; };
  }
};

const char* kHeartbeatHex = "fd0900000001bf000000000000001208000403aec6";
const char* kHeartbeatSignedHex = "fd0901000201bf000000000000001208000403782a01e8030000000019f861a09574";
const char* kSetpointHex =
    "fd3500000101bf540000e80300000000000000000000000000000000803f00000000000000bf000000000000000000000000000000"
    "00cdcc4c3ec705010108fd91";

mav::Heartbeat vector_heartbeat() {
  mav::Heartbeat hb;
  hb.type = mav::mav_type::kOnboardController;
  hb.autopilot = mav::mav_autopilot::kInvalid;
  hb.system_status = mav::mav_state::kActive;
  hb.mavlink_version = 3;
  return hb;
}

mav::SetPositionTargetLocalNed vector_setpoint() {
  mav::SetPositionTargetLocalNed sp;
  sp.time_boot_ms = 1000;
  sp.target_system = 1;
  sp.target_component = 1;
  sp.vx = 1.0f;
  sp.vz = -0.5f;
  sp.yaw_rate = 0.2f;
  sp.type_mask = mav::type_mask::kVelocityYawRate;
  sp.coordinate_frame = mav::mav_frame::kBodyNed;
  return sp;
}

template <class M>
bool same_fields(const M& a, const M& b) {
  return mav::make_frame(a, {}).payload == mav::make_frame(b, {}).payload;
}

}  // namespace

// --- CRC and the README's test vectors ------------------------------------------------------

TEST(MavlinkCrc, CheckValueAndReadmeExtras) {
  const std::string check = "123456789";
  EXPECT_EQ(mav::crc16(std::span(reinterpret_cast<const uint8_t*>(check.data()), check.size())), 0x6F91);
  EXPECT_EQ(mav::crc_extra<mav::Heartbeat>(), 50);
  EXPECT_EQ(mav::crc_extra<mav::AttitudeQuaternion>(), 246);
  EXPECT_EQ(mav::crc_extra<mav::LocalPositionNed>(), 185);
  EXPECT_EQ(mav::crc_extra<mav::CommandLong>(), 152);
  EXPECT_EQ(mav::crc_extra<mav::CommandAck>(), 143);
  EXPECT_EQ(mav::crc_extra<mav::SetPositionTargetLocalNed>(), 143);
  EXPECT_EQ(mav::crc_extra<mav::PositionTargetLocalNed>(), 140);
  EXPECT_EQ(mav::crc_extra<mav::VisionPositionEstimate>(), 158);
  EXPECT_EQ(mav::crc_extra<mav::HighresImu>(), 93);
  EXPECT_EQ(mav::crc_extra<mav::LandingTarget>(), 200);
  EXPECT_EQ(mav::crc_extra<mav::Statustext>(), 83);
  EXPECT_EQ(mav::crc_extra<mav::Odometry>(), 91);
  EXPECT_EQ(mav::min_length<mav::HighresImu>(), 62u);
  EXPECT_EQ(mav::max_length<mav::HighresImu>(), 63u);
  EXPECT_EQ(mav::min_length<mav::LandingTarget>(), 30u);
  EXPECT_EQ(mav::max_length<mav::LandingTarget>(), 60u);
}

TEST(MavlinkVectors, EncodeByteForByte) {
  EXPECT_EQ(to_hex(mav::encode(vector_heartbeat(), {.sysid = 1, .compid = 191, .seq = 0})), kHeartbeatHex);
  EXPECT_EQ(to_hex(mav::encode(vector_setpoint(), {.sysid = 1, .compid = 191, .seq = 1})), kSetpointHex);
  FakeClock clock;
  clock.now = 1000;
  mav::Signer signer(key_of(0x42), 1, 0, clock.fn());
  EXPECT_EQ(to_hex(mav::encode(vector_heartbeat(), {.sysid = 1, .compid = 191, .seq = 2}, signer)), kHeartbeatSignedHex);
}

TEST(MavlinkVectors, DecodeByteForByte) {
  FakeClock clock;
  clock.now = 1000;
  mav::Parser parser;
  std::vector<mav::Frame> frames = parser.feed(from_hex(kHeartbeatHex));
  for (const auto& f : parser.feed(from_hex(kSetpointHex))) frames.push_back(f);
  ASSERT_EQ(frames.size(), 2u) << parser.last_error();
  const mav::Heartbeat hb = mav::decode<mav::Heartbeat>(frames[0]);
  EXPECT_EQ(hb.type, 18);
  EXPECT_EQ(hb.autopilot, 8);
  EXPECT_EQ(hb.system_status, 4);
  EXPECT_EQ(hb.mavlink_version, 3);
  EXPECT_EQ(frames[0].sysid, 1);
  EXPECT_EQ(frames[0].compid, 191);
  const auto sp = mav::decode<mav::SetPositionTargetLocalNed>(frames[1]);
  EXPECT_EQ(sp.vx, 1.0f);
  EXPECT_EQ(sp.vz, -0.5f);
  EXPECT_EQ(sp.yaw_rate, 0.2f);
  EXPECT_EQ(sp.type_mask, 0x05C7);
  EXPECT_EQ(sp.coordinate_frame, 8);
  EXPECT_EQ(sp.time_boot_ms, 1000u);
  EXPECT_EQ(frames[1].payload.size(), 53u);  // its last byte (coordinate_frame) is not zero
  // The signed vector, checked with the key and required signing.
  mav::Parser signed_parser;
  signed_parser.set_signing(key_of(0x42), true, clock.fn());
  const auto sframes = signed_parser.feed(from_hex(kHeartbeatSignedHex));
  ASSERT_EQ(sframes.size(), 1u) << signed_parser.last_error();
  ASSERT_TRUE(sframes[0].signature.has_value());
  EXPECT_EQ(sframes[0].signature->link_id, 1);
  EXPECT_EQ(sframes[0].signature->timestamp, 1000u);
  EXPECT_EQ(sframes[0].seq, 2);
  EXPECT_EQ(to_hex(mav::serialize(sframes[0])), kHeartbeatSignedHex);  // forwarded as it came
}

// --- the catalogue against the official definitions -----------------------------------------

namespace {

struct XmlField {
  std::string type;  // element type ("uint8_t_mavlink_version" -> "uint8_t")
  std::string name;
  size_t count = 1;
  bool is_array = false;
  bool extension = false;
};
struct XmlMessage {
  uint32_t id = 0;
  std::string name;
  std::vector<XmlField> fields;
};

std::string attribute(const std::string& tag, const std::string& key) {
  const std::string pattern = " " + key + "=\"";
  const size_t at = tag.find(pattern);
  if (at == std::string::npos) return "";
  const size_t start = at + pattern.size();
  return tag.substr(start, tag.find('"', start) - start);
}

// A small reader of the MAVLink XML: <message id name>, <field type name>, <extensions/>.
std::map<std::string, XmlMessage> read_definitions(const std::string& path) {
  std::ifstream in(path);
  if (!in) throw std::runtime_error(path + ": cannot read");
  std::stringstream ss;
  ss << in.rdbuf();
  std::string text = ss.str();
  for (size_t c; (c = text.find("<!--")) != std::string::npos;) text.erase(c, text.find("-->", c) + 3 - c);
  std::map<std::string, XmlMessage> out;
  size_t pos = 0;
  while ((pos = text.find("<message ", pos)) != std::string::npos) {
    const size_t tag_end = text.find('>', pos);
    const size_t end = text.find("</message>", tag_end);
    const std::string tag = text.substr(pos, tag_end - pos);
    XmlMessage msg;
    msg.id = static_cast<uint32_t>(std::stoul(attribute(tag, "id")));
    msg.name = attribute(tag, "name");
    bool extension = false;
    size_t p = tag_end;
    for (;;) {
      const size_t f = text.find("<field ", p);
      const size_t e = text.find("<extensions/>", p);
      const size_t next = std::min(f, e);
      if (next == std::string::npos || next > end) break;
      if (next == e) {
        extension = true;
        p = e + 1;
        continue;
      }
      const std::string ftag = text.substr(f, text.find('>', f) - f);
      XmlField field;
      field.name = attribute(ftag, "name");
      field.type = attribute(ftag, "type");
      field.extension = extension;
      if (const size_t b = field.type.find('['); b != std::string::npos) {
        field.is_array = true;
        field.count = std::stoul(field.type.substr(b + 1));
        field.type = field.type.substr(0, b);
      }
      if (field.type == "uint8_t_mavlink_version") field.type = "uint8_t";
      msg.fields.push_back(field);
      p = f + 1;
    }
    out[msg.name] = msg;
    pos = end;
  }
  return out;
}

size_t type_size(const std::string& type) {
  static const std::map<std::string, size_t> sizes{{"char", 1},     {"uint8_t", 1},  {"int8_t", 1},  {"uint16_t", 2},
                                                   {"int16_t", 2},  {"uint32_t", 4}, {"int32_t", 4}, {"float", 4},
                                                   {"uint64_t", 8}, {"int64_t", 8},  {"double", 8}};
  return sizes.at(type);
}

// The wire order and CRC_EXTRA computed from the XML, independently of message.hpp.
std::vector<XmlField> xml_wire_order(const XmlMessage& msg) {
  std::vector<XmlField> base, ext;
  for (const XmlField& f : msg.fields) (f.extension ? ext : base).push_back(f);
  std::stable_sort(base.begin(), base.end(),
                   [](const XmlField& a, const XmlField& b) { return type_size(a.type) > type_size(b.type); });
  base.insert(base.end(), ext.begin(), ext.end());
  return base;
}

uint8_t xml_crc_extra(const XmlMessage& msg) {
  mav::Crc16 crc;
  crc.add(msg.name + " ");
  for (const XmlField& f : xml_wire_order(msg)) {
    if (f.extension) continue;
    crc.add(f.type + " ");
    crc.add(f.name + " ");
    if (f.is_array) crc.add(static_cast<uint8_t>(f.count));
  }
  return static_cast<uint8_t>((crc.value() & 0xFF) ^ (crc.value() >> 8));
}

template <class M>
void check_against_xml(const std::map<std::string, XmlMessage>& defs) {
  using L = mav::Layout<M>;
  const auto it = defs.find(std::string(M::kName));
  ASSERT_NE(it, defs.end()) << M::kName << " is in the catalogue but not in the XML definitions";
  const XmlMessage& xml = it->second;
  SCOPED_TRACE(xml.name);
  EXPECT_EQ(M::kId, xml.id);
  ASSERT_EQ(L::kCount, xml.fields.size()) << "field count";
  size_t min_len = 0, max_len = 0;
  for (size_t i = 0; i < L::kCount; ++i) {
    const mav::FieldInfo& f = L::kFields[i];
    EXPECT_EQ(f.name, xml.fields[i].name) << "field " << i << " (XML order)";
    EXPECT_EQ(f.type, xml.fields[i].type) << f.name;
    EXPECT_EQ(f.is_array, xml.fields[i].is_array) << f.name;
    EXPECT_EQ(f.count, xml.fields[i].count) << f.name;
    EXPECT_EQ(f.is_extension, xml.fields[i].extension) << f.name;
    const size_t bytes = type_size(xml.fields[i].type) * xml.fields[i].count;
    max_len += bytes;
    if (!xml.fields[i].extension) min_len += bytes;
  }
  EXPECT_EQ(mav::crc_extra<M>(), xml_crc_extra(xml));
  EXPECT_EQ(mav::min_length<M>(), min_len);
  EXPECT_EQ(mav::max_length<M>(), max_len);
  const std::vector<XmlField> order = xml_wire_order(xml);
  for (size_t k = 0; k < L::kCount; ++k) EXPECT_EQ(L::kFields[L::kOrder[k]].name, order[k].name) << "wire position " << k;
  // The registry agrees with the templates.
  const mav::MessageInfo* info = mav::find_message(M::kId);
  ASSERT_NE(info, nullptr);
  EXPECT_EQ(info->name, M::kName);
  EXPECT_EQ(info->crc_extra, mav::crc_extra<M>());
  EXPECT_EQ(info->min_length, mav::min_length<M>());
  EXPECT_EQ(info->max_length, mav::max_length<M>());
}

template <class... M>
void check_all_against_xml(const std::map<std::string, XmlMessage>& defs, std::variant<M...>*) {
  (check_against_xml<M>(defs), ...);
}

}  // namespace

TEST(MavlinkCatalogue, EveryMessageMatchesTheXmlDefinitions) {
  const std::string dir = std::string(AERIE_SOURCE_DIR) + "/../shared/mavlink/";
  std::map<std::string, XmlMessage> defs;
  for (const char* file : {"minimal.xml", "standard.xml", "common.xml"}) defs.merge(read_definitions(dir + file));
  ASSERT_GT(defs.size(), 200u) << "the XML reader found too few messages in " << dir;
  // The reader itself, on the README's table.
  EXPECT_EQ(xml_crc_extra(defs.at("HEARTBEAT")), 50);
  EXPECT_EQ(xml_crc_extra(defs.at("ODOMETRY")), 91);
  EXPECT_EQ(xml_crc_extra(defs.at("STATUSTEXT")), 83);
  check_all_against_xml(defs, static_cast<mav::Message*>(nullptr));
  EXPECT_EQ(std::variant_size_v<mav::Message>, mav::kCatalogue.size());
  EXPECT_EQ(defs.count("AUTOPILOT_VERSION_REQUEST"), 0u) << "dropped from the catalogue: not in the definitions";
  // Ids unique.
  std::set<uint32_t> ids;
  for (const auto& info : mav::kCatalogue) EXPECT_TRUE(ids.insert(info.id).second) << info.name;
}

TEST(MavlinkCatalogue, EnumNames) {
  EXPECT_EQ(mav::mav_result::to_string(mav::mav_result::kAccepted), "ACCEPTED");
  EXPECT_EQ(mav::mav_result::to_string(mav::mav_result::kTemporarilyRejected), "TEMPORARILY_REJECTED");
  EXPECT_EQ(mav::mav_result::to_string(mav::mav_result::kDenied), "DENIED");
  EXPECT_EQ(mav::mav_result::to_string(mav::mav_result::kInProgress), "IN_PROGRESS");
  EXPECT_EQ(mav::mav_result::to_string(200), "UNKNOWN (200)");
  EXPECT_EQ(mav::mav_state::to_string(mav::mav_state::kStandby), "STANDBY");
  EXPECT_EQ(mav::mav_state::to_string(mav::mav_state::kFlightTermination), "FLIGHT_TERMINATION");
  EXPECT_EQ(mav::mav_state::to_string(9), "UNKNOWN (9)");
  EXPECT_EQ(mav::type_mask::kVelocityYawRate, 1479);
}

// --- round trips ------------------------------------------------------------------------------

namespace {

template <class M>
void round_trip() {
  SCOPED_TRACE(std::string(M::kName));
  const M msg = mav::testing::sample<M>(3);
  const std::vector<uint8_t> bytes = mav::encode(msg, {.sysid = 7, .compid = 191, .seq = 9});
  mav::Parser parser;
  const auto frames = parser.feed(bytes);
  ASSERT_EQ(frames.size(), 1u) << parser.last_error();
  EXPECT_EQ(frames[0].msgid, M::kId);
  EXPECT_EQ(frames[0].sysid, 7);
  EXPECT_EQ(frames[0].compid, 191);
  EXPECT_EQ(frames[0].seq, 9);
  EXPECT_EQ(frames[0].payload.size(), mav::max_length<M>()) << "every field non-zero: nothing to truncate";
  const M back = mav::decode<M>(frames[0]);
  EXPECT_EQ(mav::testing::fields_json(back), mav::testing::fields_json(msg));
  const auto any = mav::decode_message(frames[0]);
  ASSERT_TRUE(any.has_value());
  ASSERT_TRUE(std::holds_alternative<M>(*any));
  EXPECT_TRUE(same_fields(std::get<M>(*any), msg));
  bool visited_as_m = false;
  EXPECT_TRUE(mav::visit_frame(frames[0], [&](const auto& m) {
    if constexpr (std::is_same_v<std::decay_t<decltype(m)>, M>) visited_as_m = same_fields(m, msg);
  }));
  EXPECT_TRUE(visited_as_m);
  // An all-zero message keeps one payload byte, and decodes back to zeros.
  const auto zero_frames = parser.feed(mav::encode(M{}, {1, 1, 0}));
  ASSERT_EQ(zero_frames.size(), 1u);
  EXPECT_EQ(zero_frames[0].payload.size(), 1u);
  EXPECT_EQ(mav::testing::fields_json(mav::decode<M>(zero_frames[0])), mav::testing::fields_json(M{}));
}

template <class... M>
void round_trip_all(std::variant<M...>*) {
  (round_trip<M>(), ...);
}

}  // namespace

TEST(MavlinkCodec, RoundTripOfEveryMessage) { round_trip_all(static_cast<mav::Message*>(nullptr)); }

TEST(MavlinkCodec, TrailingZerosTruncatedAndZeroFilled) {
  mav::CommandAck ack;
  ack.command = mav::mav_cmd::kComponentArmDisarm;
  ack.result = mav::mav_result::kDenied;
  const mav::Frame frame = mav::make_frame(ack, {1, 1, 0});
  EXPECT_EQ(frame.payload.size(), 3u);  // extensions all zero: dropped
  ack.result_param2 = 0x100;            // bytes 4..7 of the wire payload
  const mav::Frame longer = mav::make_frame(ack, {1, 1, 0});
  EXPECT_EQ(longer.payload.size(), 6u);
  // A sender with fewer fields (an older definition): the rest reads as zero.
  mav::Frame short_frame;
  short_frame.msgid = mav::AttitudeQuaternion::kId;
  short_frame.payload = {0x10, 0, 0, 0};
  const auto att = mav::decode<mav::AttitudeQuaternion>(short_frame);
  EXPECT_EQ(att.time_boot_ms, 16u);
  EXPECT_EQ(att.q1, 0.0f);
  EXPECT_EQ(att.repr_offset_q[3], 0.0f);
  // decode refuses another message and an overlong payload, naming them.
  try {
    mav::decode<mav::Heartbeat>(short_frame);
    FAIL() << "expected a refusal";
  } catch (const std::invalid_argument& e) {
    EXPECT_NE(std::string(e.what()).find("HEARTBEAT"), std::string::npos) << e.what();
  }
  mav::Frame overlong;
  overlong.msgid = mav::Heartbeat::kId;
  overlong.payload.assign(10, 1);
  EXPECT_THROW(mav::decode<mav::Heartbeat>(overlong), std::invalid_argument);
  mav::Frame unknown;
  unknown.msgid = 999;
  unknown.payload = {1};
  EXPECT_FALSE(mav::decode_message(unknown).has_value());
  EXPECT_THROW(mav::serialize(unknown), std::invalid_argument);
}

TEST(MavlinkCodec, MavlinkOneFrames) {
  const mav::Heartbeat hb = vector_heartbeat();
  const auto bytes = mav::encode_v1(hb, {1, 1, 5});
  ASSERT_EQ(bytes.size(), 6u + 9u + 2u);
  EXPECT_EQ(bytes[0], 0xFE);
  mav::Parser parser;
  const auto frames = parser.feed(bytes);
  ASSERT_EQ(frames.size(), 1u);
  EXPECT_EQ(frames[0].version, 1);
  EXPECT_EQ(frames[0].seq, 5);
  EXPECT_EQ(mav::decode<mav::Heartbeat>(frames[0]).type, 18);
  // v1 sends no extensions.
  const auto att = mav::encode_v1(mav::testing::sample<mav::AttitudeQuaternion>(), {1, 1, 0});
  EXPECT_EQ(att.size(), 6u + 32u + 2u);
  EXPECT_EQ(parser.feed(att).size(), 1u);
}

// --- the parser ---------------------------------------------------------------------------------

namespace {

bool magic_only_at_start(const std::vector<uint8_t>& bytes) {
  return std::none_of(bytes.begin() + 1, bytes.end(), [](uint8_t b) { return b == 0xFD || b == 0xFE; });
}

// Serialises `frame` (with `crc_extra`) with the first seq for which no byte after the start byte is
// a start byte, so that the frame's refusal is the only candidate it makes.
std::vector<uint8_t> clean_bytes(mav::Frame frame, std::optional<uint8_t> crc_extra = std::nullopt) {
  for (int seq = 0; seq < 256; ++seq) {
    frame.seq = static_cast<uint8_t>(seq);
    auto bytes = crc_extra ? mav::serialize_with_crc_extra(frame, *crc_extra) : mav::serialize(frame);
    if (magic_only_at_start(bytes)) return bytes;
  }
  throw std::runtime_error("no clean sequence number");
}

template <class M>
std::vector<uint8_t> clean_signed(const M& msg, mav::Header header, mav::Signer& signer) {
  for (int seq = 0; seq < 256; ++seq) {
    header.seq = static_cast<uint8_t>(seq);
    auto bytes = mav::encode(msg, header, signer);
    if (magic_only_at_start(bytes)) return bytes;
  }
  throw std::runtime_error("no clean sequence number");
}

void append(std::vector<uint8_t>& out, const std::vector<uint8_t>& bytes) { out.insert(out.end(), bytes.begin(), bytes.end()); }

}  // namespace

TEST(MavlinkParser, EveryRefusalCountedOnce) {
  FakeClock clock;
  clock.now = 100'000'000;
  const mav::Key key = key_of(0x42);
  mav::Signer signer(key, 1, 0, clock.fn());
  mav::Signer wrong(key_of(0x43), 1, 0, clock.fn());

  std::vector<uint8_t> in;
  uint64_t expected_garbage = 0;
  mav::Parser parser;
  parser.set_signing(key, true, clock.fn());
  auto expect_only = [&](const std::vector<uint8_t>& bytes, uint64_t mav::ParserCounters::*counter,
                         const std::string& error_part) {
    const mav::ParserCounters before = parser.counters();
    const auto frames = parser.feed(bytes);
    EXPECT_TRUE(frames.empty());
    EXPECT_EQ(parser.counters().*counter, before.*counter + 1) << error_part;
    EXPECT_EQ(parser.counters().refused(), before.refused() + 1) << error_part << ": " << parser.last_error();
    EXPECT_NE(parser.last_error().find(error_part), std::string::npos) << parser.last_error();
    append(in, bytes);
  };

  // bad CRC: a payload byte altered.
  auto corrupt = clean_bytes(mav::make_frame(vector_heartbeat(), {1, 1, 0}));
  corrupt[12] ^= 0x20;
  expect_only(corrupt, &mav::ParserCounters::bad_crc, "HEARTBEAT (0) from 1/1");
  expected_garbage += corrupt.size() - 1;
  // unknown message id.
  mav::Frame unknown;
  unknown.msgid = 4242;
  unknown.sysid = 3;
  unknown.payload = {1, 2, 3};
  const auto unknown_bytes = clean_bytes(unknown, 77);
  expect_only(unknown_bytes, &mav::ParserCounters::unknown_message, "message 4242");
  expected_garbage += unknown_bytes.size() - 1;
  // an incompat flag other than "signed".
  mav::Frame flagged = mav::make_frame(vector_heartbeat(), {1, 1, 0});
  flagged.incompat_flags = 0x04;
  const auto flagged_bytes = clean_bytes(flagged);
  expect_only(flagged_bytes, &mav::ParserCounters::bad_incompat_flags, "0x04");
  expected_garbage += flagged_bytes.size() - 1;
  // payload longer than the message's (valid CRC).
  mav::Frame overlong = mav::make_frame(vector_heartbeat(), {1, 1, 0});
  overlong.payload.assign(12, 0x11);
  expect_only(clean_bytes(overlong), &mav::ParserCounters::payload_too_long, "payload of 12 bytes, at most 9");
  // MAVLink 1 while signing is required.
  expect_only(mav::encode_v1(vector_heartbeat(), {1, 1, 0}), &mav::ParserCounters::mavlink1_refused, "MAVLink 1");
  // unsigned COMMAND_LONG while signing is required.
  expect_only(clean_bytes(mav::make_frame(mav::testing::sample<mav::CommandLong>(), {1, 1, 0})),
              &mav::ParserCounters::unsigned_refused, "COMMAND_LONG (76)");
  // signed with another key.
  expect_only(clean_signed(vector_setpoint(), {1, 191, 0}, wrong), &mav::ParserCounters::bad_signature,
              "bad signature");
  // a good one, then the same bytes again: replayed.
  const auto good = clean_signed(vector_setpoint(), {1, 191, 0}, signer);
  EXPECT_EQ(parser.feed(good).size(), 1u) << parser.last_error();
  append(in, good);
  expect_only(good, &mav::ParserCounters::replayed_timestamp, "replayed");
  // a new stream (sysid 2) more than a minute behind local time and older than the newest seen.
  FakeClock past;
  past.now = clock.now - mav::kOneMinuteTicks - 1000;
  mav::Signer old(key, 1, 0, past.fn());
  expect_only(clean_signed(vector_setpoint(), {2, 191, 0}, old), &mav::ParserCounters::stale_timestamp,
              "more than a minute");
  // garbage without start bytes.
  const std::vector<uint8_t> garbage{0x01, 0x02, 0x55, 0xAA, 0x00};
  parser.feed(garbage);
  append(in, garbage);
  expected_garbage += garbage.size();

  const mav::ParserCounters c = parser.counters();
  EXPECT_EQ(c.frames, 1u);
  EXPECT_EQ(c.bad_crc, 1u);
  EXPECT_EQ(c.unknown_message, 1u);
  EXPECT_EQ(c.payload_too_long, 1u);
  EXPECT_EQ(c.bad_incompat_flags, 1u);
  EXPECT_EQ(c.mavlink1_refused, 1u);
  EXPECT_EQ(c.unsigned_refused, 1u);
  EXPECT_EQ(c.bad_signature, 1u);
  EXPECT_EQ(c.replayed_timestamp, 1u);
  EXPECT_EQ(c.stale_timestamp, 1u);
  EXPECT_EQ(c.garbage_bytes, expected_garbage);
  EXPECT_EQ(c.refused(), 9u);

  // The same input one byte at a time gives the same counts (a fresh parser, same clock).
  mav::Parser bytewise;
  bytewise.set_signing(key, true, clock.fn());
  for (uint8_t b : in) bytewise.feed(std::span<const uint8_t>(&b, 1), nullptr);
  const mav::ParserCounters d = bytewise.counters();
  EXPECT_EQ(d.frames, c.frames);
  EXPECT_EQ(d.refused(), c.refused());
  EXPECT_EQ(d.bad_crc, 1u);
  EXPECT_EQ(d.stale_timestamp, 1u);
  EXPECT_EQ(d.garbage_bytes, c.garbage_bytes);
}

TEST(MavlinkParser, UnsignedExceptionsWhileSigningIsRequired) {
  mav::Parser parser;
  parser.set_signing(key_of(1), true);
  EXPECT_EQ(parser.feed(mav::encode(vector_heartbeat(), {1, 1, 0})).size(), 1u);
  EXPECT_EQ(parser.feed(mav::encode(mav::testing::sample<mav::RadioStatus>(), {1, 1, 1})).size(), 1u);
  EXPECT_EQ(parser.feed(mav::encode(vector_setpoint(), {1, 1, 2})).size(), 0u);
  EXPECT_TRUE(mav::accepted_unsigned(246) && mav::accepted_unsigned(247) && !mav::accepted_unsigned(76));
  // Signing on but not required: unsigned and MAVLink 1 pass, signed ones are still checked.
  mav::Parser lenient;
  lenient.set_signing(key_of(1), false);
  EXPECT_EQ(lenient.feed(mav::encode(vector_setpoint(), {1, 1, 2})).size(), 1u);
  EXPECT_EQ(lenient.feed(mav::encode_v1(vector_setpoint(), {1, 1, 3})).size(), 1u);
  mav::Signer wrong(key_of(2), 0);
  EXPECT_EQ(lenient.feed(mav::encode(vector_setpoint(), {1, 1, 4}, wrong)).size(), 0u);
  EXPECT_EQ(lenient.counters().bad_signature, 1u);
  // No signing at all: MAVLink 1 accepted, signed frames passed on unchecked.
  mav::Parser open;
  EXPECT_EQ(open.feed(mav::encode_v1(vector_heartbeat(), {1, 1, 0})).size(), 1u);
  const auto frames = open.feed(mav::encode(vector_setpoint(), {1, 1, 4}, wrong));
  ASSERT_EQ(frames.size(), 1u);
  EXPECT_TRUE(frames[0].signature.has_value());
}

TEST(MavlinkParser, GarbageBetweenFramesAndAnyChunking) {
  std::vector<uint8_t> stream;
  std::vector<mav::Frame> sent;
  uint64_t garbage = 0;
  for (int i = 0; i < 20; ++i) {
    const auto frame = mav::make_frame(mav::testing::sample<mav::HighresImu>(i), {1, 1, static_cast<uint8_t>(i)});
    const auto bytes = mav::serialize(frame);
    append(stream, bytes);
    sent.push_back(frame);
    for (int g = 0; g < i % 4; ++g) {
      stream.push_back(static_cast<uint8_t>(0x10 + g));
      ++garbage;
    }
  }
  const std::vector<uint8_t> leading{0x00, 0x99, 0x42};
  stream.insert(stream.begin(), leading.begin(), leading.end());
  garbage += leading.size();

  auto check = [&](const std::vector<mav::Frame>& got, const mav::Parser& parser) {
    ASSERT_EQ(got.size(), sent.size()) << parser.last_error();
    for (size_t i = 0; i < got.size(); ++i) {
      EXPECT_EQ(got[i].payload, sent[i].payload);
      EXPECT_EQ(got[i].seq, sent[i].seq);
    }
    EXPECT_EQ(parser.counters().refused(), 0u);
  };
  {
    mav::Parser parser;
    const auto got = parser.feed(stream);
    check(got, parser);
    if (!magic_only_at_start(stream)) SUCCEED();  // sample payloads may hold start bytes; counts then differ
  }
  {
    mav::Parser parser;
    std::vector<mav::Frame> got;
    for (uint8_t b : stream)
      parser.feed(std::span<const uint8_t>(&b, 1), [&](const mav::Frame& f) { got.push_back(f); });
    check(got, parser);
  }
  std::mt19937 rng(7);
  for (int round = 0; round < 20; ++round) {
    mav::Parser parser;
    std::vector<mav::Frame> got;
    size_t at = 0;
    while (at < stream.size()) {
      const size_t n = std::min<size_t>(stream.size() - at, 1 + rng() % 90);
      parser.feed(std::span<const uint8_t>(stream.data() + at, n), [&](const mav::Frame& f) { got.push_back(f); });
      at += n;
    }
    check(got, parser);
  }
  // Garbage counted exactly when nothing in the garbage or the frames looks like a start byte.
  std::vector<uint8_t> clean;
  uint64_t clean_garbage = 0;
  for (int i = 0; i < 5; ++i) {
    append(clean, clean_bytes(mav::make_frame(vector_heartbeat(), {1, 1, 0})));
    for (int g = 0; g <= i; ++g, ++clean_garbage) clean.push_back(0x33);
  }
  mav::Parser parser;
  EXPECT_EQ(parser.feed(clean).size(), 5u);
  EXPECT_EQ(parser.counters().garbage_bytes, clean_garbage);
}

TEST(MavlinkParser, RandomFloodIsBoundedAndRecovers) {
  std::mt19937 rng(45);
  mav::Parser parser;
  parser.set_signing(key_of(9), true);
  std::vector<uint8_t> chunk(4096);
  for (int i = 0; i < 256; ++i) {  // 1 MiB
    for (auto& b : chunk) b = static_cast<uint8_t>(rng());
    if (i % 3 == 0)
      for (size_t k = 0; k < chunk.size(); k += 7) chunk[k] = 0xFD;  // many start bytes
    parser.feed(chunk, nullptr);
  }
  EXPECT_GT(parser.counters().garbage_bytes + parser.counters().refused(), 1000u);
  // The parser holds one frame's bytes at most, whatever came in.
  EXPECT_LE(sizeof(mav::Parser), mav::kMaxFrameLength + 1024);
  // A valid frame right after the flood is found (a pending candidate resynchronises onto it).
  mav::Signer signer(key_of(9), 0);
  std::vector<mav::Frame> got;
  for (int i = 0; i < 2; ++i)
    parser.feed(mav::encode(vector_setpoint(), {1, 1, static_cast<uint8_t>(i)}, signer),
                [&](const mav::Frame& f) { got.push_back(f); });
  ASSERT_GE(got.size(), 1u) << parser.last_error();
  EXPECT_EQ(got.back().msgid, mav::SetPositionTargetLocalNed::kId);
}

// --- signing ------------------------------------------------------------------------------------

TEST(MavlinkSigning, SignedRoundTripAndRefusals) {
  FakeClock clock;
  clock.now = 50'000'000;
  const mav::Key key = key_of(0x42);
  mav::Signer signer(key, 3, 0, clock.fn());
  mav::Parser parser;
  parser.set_signing(key, true, clock.fn());

  const auto msg = mav::testing::sample<mav::Odometry>();
  const auto bytes = mav::encode(msg, {1, 191, 0}, signer);
  EXPECT_EQ(bytes[2] & mav::kIncompatSigned, mav::kIncompatSigned);
  EXPECT_EQ(bytes.size(), 10u + 233u + 2u + 13u);
  auto frames = parser.feed(bytes);
  ASSERT_EQ(frames.size(), 1u) << parser.last_error();
  ASSERT_TRUE(frames[0].signature);
  EXPECT_EQ(frames[0].signature->link_id, 3);
  EXPECT_EQ(frames[0].signature->timestamp, 50'000'000u);
  EXPECT_TRUE(same_fields(mav::decode<mav::Odometry>(frames[0]), msg));

  // Replayed: the same frame again.
  EXPECT_TRUE(parser.feed(bytes).empty());
  EXPECT_EQ(parser.counters().replayed_timestamp, 1u);
  // Backwards: a frame of the same stream with an older timestamp (another signer, clock behind).
  FakeClock behind;
  behind.now = 49'000'000;
  mav::Signer late(key, 3, 0, behind.fn());
  EXPECT_TRUE(parser.feed(mav::encode(msg, {1, 191, 1}, late)).empty());
  EXPECT_EQ(parser.counters().replayed_timestamp, 2u);
  // The next one of the right signer passes.
  EXPECT_EQ(parser.feed(mav::encode(msg, {1, 191, 2}, signer)).size(), 1u);
  // A different link id is another stream: an old timestamp is accepted if within a minute.
  mav::Signer other_link(key, 4, 0, behind.fn());
  EXPECT_EQ(parser.feed(mav::encode(msg, {1, 191, 3}, other_link)).size(), 1u);
  // A new stream more than a minute behind local time (and not newer than the newest seen): refused.
  FakeClock ancient;
  ancient.now = 50'000'000 - mav::kOneMinuteTicks - 1;
  mav::Signer stale(key, 5, 0, ancient.fn());
  EXPECT_TRUE(parser.feed(mav::encode(msg, {1, 191, 4}, stale)).empty());
  EXPECT_EQ(parser.counters().stale_timestamp, 1u);
  // A new stream that is newer than any seen is accepted even when local time is behind.
  FakeClock ahead;
  ahead.now = 90'000'000;
  mav::Signer future(key, 6, 0, ahead.fn());
  EXPECT_EQ(parser.feed(mav::encode(msg, {1, 191, 5}, future)).size(), 1u);
  // Wrong key.
  mav::Signer intruder(key_of(0x24), 3, 0, ahead.fn());
  EXPECT_TRUE(parser.feed(mav::encode(msg, {1, 191, 6}, intruder)).empty());
  EXPECT_EQ(parser.counters().bad_signature, 1u);
  // An altered signed frame with a recomputed CRC: the signature no longer matches.
  auto altered = mav::encode(msg, {1, 191, 7}, signer);
  mav::Frame f = parser.feed(mav::encode(msg, {1, 191, 8}, signer)).at(0);
  f.payload[0] ^= 1;
  EXPECT_TRUE(parser.feed(mav::serialize(f)).empty());  // CRC recomputed, old signature kept
  EXPECT_EQ(parser.counters().bad_signature, 2u);
  (void)altered;
}

TEST(MavlinkSigning, KeyChange) {
  FakeClock clock;
  clock.now = 10'000'000;
  const mav::Key old_key = key_of(1), new_key = key_of(2);
  mav::Signer old_signer(old_key, 0, 0, clock.fn());
  mav::Signer new_signer(new_key, 0, 0, clock.fn());
  mav::Parser parser;
  parser.set_signing(old_key, true, clock.fn());
  EXPECT_EQ(parser.feed(mav::encode(vector_setpoint(), {1, 1, 0}, old_signer)).size(), 1u);
  EXPECT_TRUE(parser.feed(mav::encode(vector_setpoint(), {1, 1, 1}, new_signer)).empty());
  parser.set_key(new_key);
  EXPECT_TRUE(parser.feed(mav::encode(vector_setpoint(), {1, 1, 2}, old_signer)).empty());
  EXPECT_EQ(parser.counters().bad_signature, 2u);
  EXPECT_EQ(parser.feed(mav::encode(vector_setpoint(), {1, 1, 3}, new_signer)).size(), 1u);
  // The signer's key can change too.
  old_signer.set_key(new_key);
  EXPECT_EQ(parser.feed(mav::encode(vector_setpoint(), {1, 1, 4}, old_signer)).size(), 1u);
}

TEST(MavlinkSigning, SignerTimestampsStrictlyIncreasing) {
  FakeClock clock;
  clock.now = 777;
  mav::Signer signer(key_of(1), 0, 0, clock.fn());
  uint64_t last = 0;
  for (int i = 0; i < 100; ++i) {
    const uint64_t t = signer.next_timestamp();
    EXPECT_GT(t, last);
    last = t;
  }
  EXPECT_EQ(last, 777u + 99u);  // the clock stood still
  clock.now = 500;              // and steps back
  EXPECT_EQ(signer.next_timestamp(), last + 1);
  clock.now = 1'000'000;  // and jumps ahead
  EXPECT_EQ(signer.next_timestamp(), 1'000'000u);
  // Resuming from a persisted timestamp: at least one minute past it, or now if later.
  FakeClock early;
  early.now = 5;
  mav::Signer resumed(key_of(1), 0, 20'000'000, early.fn());
  EXPECT_EQ(resumed.next_timestamp(), 20'000'000u + mav::kOneMinuteTicks);
  FakeClock late;
  late.now = 900'000'000;
  mav::Signer resumed_late(key_of(1), 0, 20'000'000, late.fn());
  EXPECT_EQ(resumed_late.next_timestamp(), 900'000'000u);
  // Persisting at least once a minute.
  EXPECT_TRUE(resumed_late.should_persist(late.now));
  EXPECT_EQ(resumed_late.mark_persisted(late.now), 900'000'000u);
  EXPECT_FALSE(resumed_late.should_persist(late.now + mav::kOneMinuteTicks - 1));
  EXPECT_TRUE(resumed_late.should_persist(late.now + mav::kOneMinuteTicks));
  // The signing clock's epoch is 2015-01-01 00:00 UTC.
  EXPECT_EQ(mav::to_signing_time(std::chrono::system_clock::time_point(std::chrono::seconds(1420070400 + 2))),
            200'000u);
  EXPECT_GT(mav::signing_time_now(), 10ull * 365 * 86400 * mav::kTicksPerSecond);
}

TEST(MavlinkSigning, VerifierStreamsAreBounded) {
  FakeClock clock;
  clock.now = 10'000'000;
  const mav::Key key = key_of(5);
  mav::Parser parser;
  parser.set_signing(key, true, clock.fn(), 4);
  mav::Signer signer(key, 0, 0, clock.fn());
  for (int sys = 1; sys <= 40; ++sys)
    EXPECT_EQ(parser.feed(mav::encode(vector_setpoint(), {static_cast<uint8_t>(sys), 1, 0}, signer)).size(), 1u);
  mav::Verifier verifier(key, clock.fn(), 4);
  for (int sys = 1; sys <= 40; ++sys) {
    auto bytes = mav::encode(vector_setpoint(), {static_cast<uint8_t>(sys), 1, 0}, signer);
    EXPECT_EQ(verifier.verify(bytes), mav::Verifier::Verdict::accepted);
  }
  EXPECT_EQ(verifier.stream_count(), 4u);
  EXPECT_EQ(mav::to_string(mav::Verifier::Verdict::replayed), "replayed timestamp");
}

TEST(MavlinkSigning, KeyAndTimestampFiles) {
  const auto dir = std::filesystem::temp_directory_path() / ("aerie_mavlink_test_" + std::to_string(::getpid()));
  std::filesystem::create_directories(dir);
  const std::string key_path = (dir / "link.key").string();
  const mav::Key key = mav::generate_key();
  EXPECT_NE(key, mav::generate_key());
  mav::save_key(key_path, key);
  struct stat st {};
  ASSERT_EQ(::stat(key_path.c_str(), &st), 0);
  EXPECT_EQ(st.st_mode & 0777, 0600u);
  EXPECT_EQ(mav::load_key(key_path), key);
  EXPECT_THROW(mav::save_key(key_path, key), std::runtime_error);  // no silent overwrite
  mav::save_key(key_path, key_of(7), true);
  EXPECT_EQ(mav::load_key(key_path), key_of(7));
  ::chmod(key_path.c_str(), 0644);
  try {
    mav::load_key(key_path);
    FAIL() << "a key readable by others must be refused";
  } catch (const std::runtime_error& e) {
    EXPECT_NE(std::string(e.what()).find(key_path), std::string::npos) << e.what();
  }
  // The fingerprint: 16 hex digits, not the key.
  const std::string fp = mav::fingerprint(key_of(0x42));
  EXPECT_EQ(fp.size(), 16u);
  EXPECT_EQ(fp.find("4242"), std::string::npos);
  EXPECT_EQ(fp, mav::fingerprint(key_of(0x42)));
  EXPECT_NE(fp, mav::fingerprint(key_of(0x43)));

  const std::string ts_path = (dir / "signing.timestamp").string();
  EXPECT_EQ(mav::load_timestamp(ts_path), 0u);  // none yet
  mav::save_timestamp(ts_path, 123'456'789'012ull);
  EXPECT_EQ(mav::load_timestamp(ts_path), 123'456'789'012ull);
  std::ofstream(ts_path) << "twelve\n";
  try {
    mav::load_timestamp(ts_path);
    FAIL() << "expected a refusal";
  } catch (const std::runtime_error& e) {
    EXPECT_NE(std::string(e.what()).find(ts_path), std::string::npos) << e.what();
  }
  std::filesystem::remove_all(dir);
}

TEST(MavlinkSigning, SetupSigningMessage) {
  const auto msg = mav::make_setup_signing(1, 1, key_of(0x42), 99'000'000);
  mav::Parser parser;
  const auto frames = parser.feed(mav::encode(msg, {255, 190, 0}));
  ASSERT_EQ(frames.size(), 1u);
  const auto back = mav::decode<mav::SetupSigning>(frames[0]);
  EXPECT_EQ(back.target_system, 1);
  EXPECT_EQ(back.target_component, 1);
  EXPECT_EQ(back.secret_key, key_of(0x42));
  EXPECT_EQ(back.initial_timestamp, 99'000'000u);
}
