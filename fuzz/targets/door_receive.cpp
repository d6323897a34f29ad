// The sealed door's receive path (tools/link/door.hpp: DoorReceiver::receive; issue 46 §4), with
// the fixed test key of seal_open (bytes 0, 1, ..., 31). One receiver per input, direction
// air->ground, policy kPolicy (CAM_DOWN rate-limited), limits() (small pending caps, so
// eviction and timeouts are reached). The first input byte picks what the rest is, modulo 4:
//   0  datagrams as they come off the radio, to a secure receiver: records [length u16 LE][bytes]
//      (a short tail is one datagram), the clock +10 ms each; the seeds hold datagrams sealed by
//      a DoorSender with the test key, so mutations of authentic ones are tried too;
//   1  the same to an insecure receiver (frames in the clear, header in door.hpp);
//   2  operations on a secure receiver, each starting with an opcode byte (modulo 4):
//      0 send:    [channel u8][length u16][payload][delivery u8][flip position u16][xor u8]: a
//                 DoorSender (sender 1, max_datagram_bytes 512, so a message over 395 bytes is
//                 cut into fragments) frames, fragments and seals it; delivery bit 0 reverses the
//                 datagrams, bit 1 drops the last, bit 2 replays the first at the end; datagram
//                 (position % count) gets the xor. An allowed, unlimited channel with nothing
//                 dropped or changed must be delivered exactly once, byte for byte; otherwise
//                 never during the operation;
//      1 frame:   [sender u8][channel u8][kind u8][id u8][index u16][count u16][total u32]
//                 [offset u32][length u8][bytes][flip position u16][xor u8]: a frame of the
//                 fuzzer's own (door.hpp layout: the door has no public frame encoder; the
//                 fragment header only when kind is 1, an empty frame when kind is 0xFF)
//                 sealed by a seal::Sealer (what DoorSender::emit calls) of sender 2..4. Intact:
//                 it opens; no kind or an unknown one is malformed, a channel not allowed
//                 not_allowed, a whole frame delivered as it is (unless rate-limited), an
//                 impossible fragment (index >= count, empty, outside its total) malformed, and a
//                 reassembled message has its fragments' channel and total, every index sent
//                 and the completing fragment's bytes at its offset;
//      2 time:    [u8]: the clock advances that many 50 ms (odd: expire() too);
//      3 replay:  [which u8][flip position u16][xor u8]: an earlier datagram of this input again.
//   3  the operator's commands: records as in 0, to a secure receiver of the other direction
//      (ground->air) whose operator's channels (kCommands) need the fixed test operator key's
//      signature for the fixed test session (common/seal/operator.hpp); the seeds hold signed
//      commands sealed with the test key, so mutations of valid envelopes are tried. A delivery
//      on an operator's channel must have verified exactly one signature; a refused one is
//      counted under one command refusal.
// In mode 2 a datagram opens only if one of the input's senders sealed it, and only once.
// Checked on every datagram: receive() never throws; counted exactly once (datagrams +1; at most
// one of delivered / not_allowed / rate_limited / malformed / insecure_peer / secure_peer /
// too_large / hellos / a command refusal / opener refusal, and none only for a fragment kept or dropped with its message; secure: opened
// + refused + insecure_peer +1); a refusal says why(); a delivery is counted with its bytes, on a
// channel the policy allows (its regex read here, not the door's matcher), at most
// max_message_bytes, and only from an opened datagram; at most max_pending_messages + 1
// messages dropped by one datagram. At the end of an
// input: expiring everything drops at most max_pending_messages (every prefix of an input is an
// input too, so this bounds every state reached), the counters add up, and the receiver still
// delivers a fresh sender's two interleaved fragmented messages that together just fit
// max_pending_bytes (so no pending byte is left counted). Anything else aborts.
//
// Seeds: AERIE_DOOR_RECEIVE_SEEDS=fuzz/corpus/door_receive build/default/fuzz/fuzz_replay_door_receive
// writes them (write_seeds below; the salts are random, so the bytes differ on every run) and exits.
#include <algorithm>
#include <cstdio>
#include <cstdlib>
#include <exception>
#include <fstream>
#include <map>
#include <optional>
#include <regex>
#include <set>
#include <span>
#include <string>
#include <vector>

#include "common/seal/operator.hpp"
#include "common/seal/seal.hpp"
#include "common/seal/testing.hpp"
#include "tools/link/door.hpp"

namespace {

using namespace aerie;

const seal::SecretKey& test_key() {
  static const seal::SecretKey key = seal::for_tests::counting_key(0);
  return key;
}

constexpr seal::Direction kDir = seal::Direction::AirToGround;
const char* const kCommands = "TRACK|FUZZ";  // mode 3: the operator's channels (inside kPolicy)

const seal::OperatorKey& test_operator() {
  static const seal::OperatorKey key = seal::OperatorKey::from_seed(seal::for_tests::counting_key(32));
  return key;
}
seal::Session test_session() {
  seal::Session s;
  for (size_t i = 0; i < s.size(); ++i) s[i] = static_cast<uint8_t>(0xC0 + i);
  return s;
}
const char* const kPolicy = "VO_POSE|TRACK|CAM_DOWN|FUZZ";
const char* const kLimited = "CAM_DOWN";
const char* const kChannels[] = {"VO_POSE", "TRACK", "CAM_DOWN", "FUZZ", "PILOT_CMD", "MAP_CMD", "X"};
constexpr size_t kChannelCount = sizeof(kChannels) / sizeof(kChannels[0]);
constexpr size_t kMaxSteps = 64;

link::ReassemblyLimits limits() {
  link::ReassemblyLimits l;
  l.max_message_bytes = 65536;  // >= seal::kMaxPayload: a whole frame is never over it
  l.max_pending_bytes = 131072;
  l.max_pending_messages = 4;
  l.timeout_s = 2.0;
  l.max_datagram_bytes = 512;
  return l;
}

link::DoorPolicy policy() {
  link::DoorPolicy p;
  p.channels = kPolicy;
  p.rates.push_back({.channels = kLimited, .messages_per_s = 2, .message_burst = 1});
  return p;
}

bool allowed(const std::string& channel) {
  static const std::regex re(kPolicy);
  return std::regex_match(channel, re);
}

[[noreturn]] void fail(const char* what, const link::DoorReceiver& rx) {
  std::fprintf(stderr, "door_receive: %s (why: \"%s\")\n", what, rx.why().c_str());
  std::abort();
}

// Reads the input front to back; past its end every read gives zeros.
struct Reader {
  std::span<const uint8_t> in;
  size_t pos = 0;
  bool done() const { return pos >= in.size(); }
  uint8_t u8() { return pos < in.size() ? in[pos++] : 0; }
  uint16_t u16() { return static_cast<uint16_t>(u8() | (u8() << 8)); }
  uint32_t u32() {
    uint32_t v = u16();
    return v | (uint32_t{u16()} << 16);
  }
  std::span<const uint8_t> bytes(size_t n) {
    n = std::min(n, in.size() - std::min(pos, in.size()));
    auto s = in.subspan(std::min(pos, in.size()), n);
    pos += n;
    return s;
  }
};

struct Outcome {
  std::optional<link::Delivered> delivered;
  bool opened = false;
};

uint64_t own_outcomes(const link::ReceiverCounters& c) {
  uint64_t commands = 0;  // the operator's signature (ground -> air only: never in this air -> ground target)
  for (const uint64_t n : c.commands_refused) commands += n;
  return c.delivered + c.not_allowed + c.rate_limited + c.malformed + c.insecure_peer + c.secure_peer + c.too_large +
         c.hellos + commands + c.opener.refused_total();
}

// One datagram through the receiver, with the checks every datagram gets.
Outcome feed(link::DoorReceiver& rx, std::span<const uint8_t> d, double now_s) {
  const link::ReceiverCounters before = rx.counters();
  Outcome out;
  try {
    out.delivered = rx.receive(d, now_s);
  } catch (const std::exception& e) {
    std::fprintf(stderr, "door_receive: receive() threw: %s\n", e.what());
    std::abort();
  } catch (...) {
    fail("receive() threw a non-exception", rx);
  }
  const link::ReceiverCounters& after = rx.counters();
  out.opened = after.opener.opened == before.opener.opened + 1;
  if (after.datagrams != before.datagrams + 1) fail("datagram not counted", rx);
  const uint64_t own = own_outcomes(after) - own_outcomes(before);
  if (own > 1) fail("one datagram counted under two outcomes", rx);
  if (own == 0 && after.fragments != before.fragments + 1) fail("a datagram that is no fragment left no count", rx);
  if (rx.secure()) {
    const uint64_t seen = (after.opener.opened - before.opener.opened) +
                          (after.opener.refused_total() - before.opener.refused_total()) +
                          (after.insecure_peer - before.insecure_peer);
    if (seen != 1) fail("secure: not exactly one of opened / refused / insecure_peer", rx);
    if (after.secure_peer != before.secure_peer) fail("secure half counted secure_peer", rx);
  } else {
    if (after.opener.opened != 0 || after.opener.refused_total() != 0) fail("insecure half counted openings", rx);
    if (after.insecure_peer != before.insecure_peer) fail("insecure half counted insecure_peer", rx);
  }
  if (after.reassembly_dropped - before.reassembly_dropped > limits().max_pending_messages + 1)
    fail("one datagram dropped more messages than can be pending", rx);
  if (out.delivered) {
    const link::Delivered& m = *out.delivered;
    if (after.delivered != before.delivered + 1) fail("delivery not counted", rx);
    if (after.bytes_delivered != before.bytes_delivered + m.payload.size()) fail("delivered bytes miscounted", rx);
    if (!seal::valid_channel(m.channel)) fail("delivered on an invalid channel name", rx);
    if (!allowed(m.channel)) fail("delivered on a channel the policy does not allow", rx);
    if (m.payload.size() > limits().max_message_bytes) fail("delivered a message over max_message_bytes", rx);
    if (rx.secure() && !out.opened) fail("delivered without opening a datagram", rx);
  } else {
    if (after.delivered != before.delivered) fail("delivery counted, nothing returned", rx);
    if (own == 1 && rx.why().empty() && after.hellos == before.hellos) fail("a refusal without why()", rx);
  }
  return out;
}

void finish(link::DoorReceiver& rx, double now_s) {
  const uint64_t dropped = rx.counters().reassembly_dropped;
  rx.expire(now_s + limits().timeout_s + 1);
  if (rx.counters().reassembly_dropped - dropped > limits().max_pending_messages)
    fail("more messages pending than max_pending_messages", rx);
  const uint64_t after_expiry = rx.counters().reassembly_dropped;
  rx.expire(now_s + 2 * limits().timeout_s + 2);
  if (rx.counters().reassembly_dropped != after_expiry) fail("expire() dropped a message twice", rx);
  const link::ReceiverCounters& c = rx.counters();
  if (rx.secure() && c.datagrams != c.insecure_peer + c.opener.opened + c.opener.refused_total())
    fail("datagrams != insecure_peer + opened + refused", rx);
  // Still serving, and the pending bytes went back to zero: a fresh sender's two messages of
  // 60000 bytes, their fragments interleaved, both fit max_pending_bytes only if nothing else
  // is still counted there (a leak over its remaining 11072 bytes evicts the first).
  const double t = now_s + 2 * limits().timeout_s + 3;
  link::ReassemblyLimits big = limits();
  big.max_datagram_bytes = 32768;
  link::DoorSender tx(rx.secure() ? &test_key() : nullptr, kDir, 5, 0, t, {}, big);
  std::vector<uint8_t> a(60000), b(60000);
  for (size_t i = 0; i < a.size(); ++i) a[i] = static_cast<uint8_t>(i * 7), b[i] = static_cast<uint8_t>(i * 5);
  std::vector<std::vector<uint8_t>> da, db;
  tx.send("FUZZ", a, t, da);
  tx.send("TRACK", b, t, db);
  if (da.size() != 2 || db.size() != 2) fail("the final messages are not two fragments each", rx);
  int got = 0;
  for (size_t i = 0; i < 2; ++i) {
    for (const auto* d : {&da[i], &db[i]}) {
      const Outcome o = feed(rx, *d, t);
      if (!o.delivered) continue;
      ++got;
      if (o.delivered->payload != (o.delivered->channel == "FUZZ" ? a : b)) fail("a final message changed", rx);
    }
  }
  if (got != 2) fail("the receiver no longer delivers two messages that fit its limits", rx);
}

void raw(std::span<const uint8_t> in, bool secure) {
  link::DoorReceiver rx(secure ? &test_key() : nullptr, kDir, policy(), {}, limits());
  Reader r{in};
  double now = 0;
  for (size_t step = 0; step < kMaxSteps && !r.done(); ++step) {
    std::span<const uint8_t> d;
    if (r.in.size() - r.pos < 2) {
      d = r.bytes(2);
    } else {
      const size_t n = r.u16();
      d = r.bytes(n);
    }
    feed(rx, d, now);
    now += 0.01;
  }
  finish(rx, now);
}

// Mode 3: the operator's commands through a ground->air receiver.
void commands(std::span<const uint8_t> in) {
  link::DoorPolicy p = policy();
  p.operator_channels = kCommands;
  link::DoorReceiver rx(&test_key(), seal::Direction::GroundToAir, p, {}, limits());
  rx.require_operator(seal::CommandVerifier({test_operator().public_key()}, test_session()));
  static const std::regex operator_channel(kCommands);
  Reader r{in};
  double now = 0;
  for (size_t step = 0; step < kMaxSteps && !r.done(); ++step) {
    const size_t n = r.in.size() - r.pos < 2 ? 2 : r.u16();
    const link::ReceiverCounters before = rx.counters();
    const Outcome o = feed(rx, r.bytes(n), now);
    const link::ReceiverCounters& after = rx.counters();
    uint64_t refused = 0;
    for (size_t i = 0; i < seal::kCommandRefusalCount; ++i) refused += after.commands_refused[i] - before.commands_refused[i];
    const uint64_t verified = after.commands_verified - before.commands_verified;
    if (refused + verified > 1) fail("one command counted twice", rx);
    if (o.delivered && std::regex_match(o.delivered->channel, operator_channel) && verified != 1)
      fail("an operator's command delivered without a verified signature", rx);
    if (o.delivered && !std::regex_match(o.delivered->channel, operator_channel) && verified != 0)
      fail("a signature verified for a channel that is not the operator's", rx);
    now += 0.01;
  }
}

void flip(std::vector<uint8_t>& d, uint16_t position, uint8_t x) {
  if (!d.empty()) d[position % d.size()] ^= x;
}

// Every datagram a sender of this input sealed, and those that opened: a datagram opens only if
// a sender sealed it, and only once (a changed one may open only by being changed back).
struct Ledger {
  std::set<std::vector<uint8_t>> sealed, opened;
  Outcome feed(link::DoorReceiver& rx, const std::vector<uint8_t>& d, double now_s) {
    Outcome o = ::feed(rx, d, now_s);
    if (o.opened && !sealed.count(d)) fail("opened a datagram no sender sealed", rx);
    if (o.opened && !opened.insert(d).second) fail("the same datagram opened twice", rx);
    return o;
  }
};

void ops(std::span<const uint8_t> in) {
  link::DoorReceiver rx(&test_key(), kDir, policy(), {}, limits());
  double now = 0;
  link::DoorSender tx(&test_key(), kDir, 1, 0, now, {}, limits());
  std::vector<seal::Sealer> crafted;
  crafted.reserve(3);
  for (uint32_t s = 2; s <= 4; ++s) crafted.emplace_back(test_key(), kDir, s, 0, now);
  Ledger ledger;
  std::vector<std::vector<uint8_t>> history;
  std::map<uint64_t, std::set<uint16_t>> indices;  // crafted fragments that opened, per (sender, id)
  Reader r{in};
  std::vector<std::vector<uint8_t>> ds;
  std::vector<uint8_t> frame, datagram;
  for (size_t step = 0; step < kMaxSteps && !r.done(); ++step) {
    switch (r.u8() % 4) {
      case 0: {  // a message through the door's own sender
        const std::string channel = kChannels[r.u8() % kChannelCount];
        const auto payload = r.bytes(r.u16());
        const uint8_t delivery = r.u8();
        const uint16_t position = r.u16();
        const uint8_t x = r.u8();
        if (!tx.send(channel, payload, now, ds)) fail("DoorSender refused a message under max_message_bytes", rx);
        ledger.sealed.insert(ds.begin(), ds.end());
        if (delivery & 1) std::reverse(ds.begin(), ds.end());
        const bool dropped = (delivery & 2) != 0;
        if (dropped) ds.pop_back();
        if (x != 0 && !ds.empty()) flip(ds[position % ds.size()], position, x);
        const bool changed = x != 0;
        std::vector<uint8_t> first = ds.empty() ? std::vector<uint8_t>{} : ds.front();
        int got = 0;
        for (size_t i = 0; i < ds.size(); ++i) {
          const Outcome o = ledger.feed(rx, ds[i], now);
          history.push_back(ds[i]);
          if (changed && i == position % ds.size() && o.opened) fail("a changed datagram opened", rx);
          if (o.delivered) {
            ++got;
            if (o.delivered->channel != channel ||
                !std::equal(o.delivered->payload.begin(), o.delivered->payload.end(), payload.begin(), payload.end()) ||
                o.delivered->payload.size() != payload.size())
              fail("delivered another message than the one sent", rx);
          }
        }
        if ((delivery & 4) && !ds.empty()) {
          if (ledger.feed(rx, first, now).opened) fail("a replayed datagram opened", rx);
        }
        const bool expect = allowed(channel) && channel != kLimited && !dropped && !changed;
        if (expect && got != 1) fail("an allowed message sent intact was not delivered exactly once", rx);
        if (!expect && channel != kLimited && got != 0) fail("a message delivered with a datagram lost or changed", rx);
        if (got > 1) fail("one message delivered twice", rx);
        break;
      }
      case 1: {  // a frame of the fuzzer's own, sealed
        seal::Sealer& sealer = crafted[r.u8() % crafted.size()];
        const std::string channel = kChannels[r.u8() % kChannelCount];
        const uint8_t kind = r.u8();
        const uint32_t id = r.u8();
        const uint16_t index = r.u16(), count = r.u16();
        const uint32_t total = r.u32(), offset = r.u32();
        const auto body = r.bytes(r.u8());
        const uint16_t position = r.u16();
        const uint8_t x = r.u8();
        frame.clear();
        if (kind != 0xFF) frame.push_back(kind);
        if (kind == 1) {
          for (int i = 0; i < 4; ++i) frame.push_back(static_cast<uint8_t>(id >> (8 * i)));
          for (int i = 0; i < 2; ++i) frame.push_back(static_cast<uint8_t>(index >> (8 * i)));
          for (int i = 0; i < 2; ++i) frame.push_back(static_cast<uint8_t>(count >> (8 * i)));
          for (int i = 0; i < 4; ++i) frame.push_back(static_cast<uint8_t>(total >> (8 * i)));
          for (int i = 0; i < 4; ++i) frame.push_back(static_cast<uint8_t>(offset >> (8 * i)));
        }
        if (kind != 0xFF) frame.insert(frame.end(), body.begin(), body.end());
        sealer.seal_into(channel, frame, now, datagram);
        ledger.sealed.insert(datagram);
        flip(datagram, position, x);
        const link::ReceiverCounters before = rx.counters();
        const Outcome o = ledger.feed(rx, datagram, now);
        history.push_back(datagram);
        const link::ReceiverCounters& after = rx.counters();
        if (x != 0) {
          if (o.opened) fail("a changed datagram opened", rx);
          break;
        }
        if (!o.opened) fail("an intact sealed frame did not open", rx);
        const size_t n = body.size();
        if (kind == 0xFF || kind > 1) {
          if (after.malformed != before.malformed + 1) fail("a frame of no kind was not refused as malformed", rx);
        } else if (!allowed(channel)) {
          if (after.not_allowed != before.not_allowed + 1) fail("a channel not allowed was not refused", rx);
        } else if (kind == 0) {
          if (channel != kLimited && !o.delivered) fail("an allowed whole frame was not delivered", rx);
          if (o.delivered && (o.delivered->channel != channel ||
                              !std::equal(o.delivered->payload.begin(), o.delivered->payload.end(), body.begin(),
                                          body.end()) ||
                              o.delivered->payload.size() != n))
            fail("a whole frame delivered changed", rx);
        } else {
          const bool impossible = count == 0 || index >= count || total == 0 || n == 0 ||
                                  uint64_t{offset} + n > total;
          if (impossible && (o.delivered || after.malformed != before.malformed + 1))
            fail("an impossible fragment was not refused as malformed", rx);
          if (total > limits().max_message_bytes && o.delivered) fail("a message over max_message_bytes delivered", rx);
          std::set<uint16_t>& seen = indices[(uint64_t{sealer.sender()} << 32) | id];
          seen.insert(index);
          if (o.delivered) {
            const auto& m = *o.delivered;
            if (m.channel != channel || m.payload.size() != total)
              fail("a reassembled message is not its fragments' channel and total", rx);
            if (seen.size() < count) fail("a message delivered with a fragment never sent", rx);
            if (!std::equal(body.begin(), body.end(), m.payload.begin() + offset))
              fail("a reassembled message lacks its last fragment's bytes", rx);
          }
        }
        break;
      }
      case 2: {
        const uint8_t v = r.u8();
        now += v * 0.05;
        if (v & 1) rx.expire(now);
        break;
      }
      default: {
        const uint8_t which = r.u8();
        const uint16_t position = r.u16();
        const uint8_t x = r.u8();
        if (history.empty()) break;
        std::vector<uint8_t> d = history[which % history.size()];
        flip(d, position, x);
        ledger.feed(rx, d, now);  // opens only if sealed and never opened (a change undone)
        break;
      }
    }
  }
  finish(rx, now);
}

// --- seeds ---------------------------------------------------------------------------------------
void put16(std::vector<uint8_t>& v, uint16_t x) {
  v.push_back(static_cast<uint8_t>(x));
  v.push_back(static_cast<uint8_t>(x >> 8));
}
void put32(std::vector<uint8_t>& v, uint32_t x) {
  put16(v, static_cast<uint16_t>(x));
  put16(v, static_cast<uint16_t>(x >> 16));
}
size_t channel_index(const std::string& c) {
  for (size_t i = 0; i < kChannelCount; ++i)
    if (c == kChannels[i]) return i;
  std::abort();
}
// Mode 0/1 records of a message sent by a (secure or insecure) DoorSender.
void records(std::vector<uint8_t>& v, bool secure, const std::string& channel, size_t size) {
  link::DoorSender tx(secure ? &test_key() : nullptr, kDir, 1, 0, 0, {}, limits());
  std::vector<uint8_t> payload(size);
  for (size_t i = 0; i < size; ++i) payload[i] = static_cast<uint8_t>(i);
  std::vector<std::vector<uint8_t>> ds;
  tx.send(channel, payload, 0, ds);
  for (const auto& d : ds) {
    put16(v, static_cast<uint16_t>(d.size()));
    v.insert(v.end(), d.begin(), d.end());
  }
}
void op_send(std::vector<uint8_t>& v, const std::string& channel, uint16_t size, uint8_t delivery = 0,
             uint16_t position = 0, uint8_t x = 0) {
  v.push_back(0);
  v.push_back(static_cast<uint8_t>(channel_index(channel)));
  put16(v, size);
  for (size_t i = 0; i < size; ++i) v.push_back(static_cast<uint8_t>(i * 3));
  v.push_back(delivery);
  put16(v, position);
  v.push_back(x);
}
void op_frame(std::vector<uint8_t>& v, uint8_t sender, const std::string& channel, uint8_t kind, uint8_t id,
              uint16_t index, uint16_t count, uint32_t total, uint32_t offset, uint8_t n) {
  v.insert(v.end(), {1, sender, static_cast<uint8_t>(channel_index(channel)), kind, id});
  put16(v, index);
  put16(v, count);
  put32(v, total);
  put32(v, offset);
  v.push_back(n);
  for (size_t i = 0; i < n; ++i) v.push_back(static_cast<uint8_t>('a' + i % 26));
  put16(v, 0);
  v.push_back(0);
}

void write_seeds(const std::string& dir) {
  const auto write = [&](const char* name, const std::vector<uint8_t>& v) {
    std::ofstream(dir + "/" + name, std::ios::binary).write(reinterpret_cast<const char*>(v.data()), v.size());
  };
  std::vector<uint8_t> v;
  v = {0}, records(v, true, "VO_POSE", 48), write("raw_vo_pose", v);
  v = {0}, records(v, true, "FUZZ", 1000), write("raw_fragments", v);
  v = {0}, records(v, true, "PILOT_CMD", 16), records(v, false, "TRACK", 8), write("raw_not_allowed_insecure_peer", v);
  v = {0, 4, 0, 0xAE, 1, 0, 0}, write("raw_short", v);
  v = {1}, records(v, false, "TRACK", 900), records(v, false, "VO_POSE", 20), write("insecure_fragments", v);
  v = {1}, records(v, true, "VO_POSE", 20), records(v, false, "X", 4), write("insecure_secure_peer", v);
  v = {2}, op_send(v, "VO_POSE", 40), op_send(v, "FUZZ", 1200, 1 | 4), write("ops_send", v);
  v = {2}, op_send(v, "TRACK", 900, 0, 1, 0x40), op_send(v, "FUZZ", 600, 2), write("ops_changed_dropped", v);
  v = {2}, op_frame(v, 0, "TRACK", 1, 7, 0, 2, 10, 0, 5), op_frame(v, 0, "TRACK", 1, 7, 1, 2, 10, 5, 5);
  op_frame(v, 1, "TRACK", 1, 7, 1, 2, 10, 5, 5), op_frame(v, 1, "TRACK", 1, 7, 1, 2, 10, 5, 5);
  write("ops_fragments", v);
  v = {2}, op_frame(v, 0, "FUZZ", 5, 0, 0, 0, 0, 0, 3), op_frame(v, 0, "FUZZ", 0xFF, 0, 0, 0, 0, 0, 0);
  op_frame(v, 0, "FUZZ", 1, 1, 2, 2, 10, 0, 5), op_frame(v, 0, "FUZZ", 1, 2, 0, 2, 100000, 0, 5);
  op_frame(v, 0, "FUZZ", 0, 0, 0, 0, 0, 0, 12), op_frame(v, 0, "MAP_CMD", 0, 0, 0, 0, 0, 0, 2);
  write("ops_bad_frames", v);
  v = {2}, op_frame(v, 2, "VO_POSE", 1, 3, 0, 2, 8, 0, 4), v.insert(v.end(), {2, 60});
  op_frame(v, 2, "VO_POSE", 1, 3, 1, 2, 8, 4, 4), write("ops_timeout", v);
  v = {2}, op_send(v, "VO_POSE", 30), op_send(v, "FUZZ", 500), v.insert(v.end(), {3, 0, 0, 0, 0, 3, 1, 5, 0, 0x10});
  write("ops_replay", v);
  v = {2};
  for (int i = 0; i < 3; ++i) op_send(v, "CAM_DOWN", 64);
  v.insert(v.end(), {2, 20}), op_send(v, "CAM_DOWN", 64), write("ops_rate_limit", v);
  v = {2};
  for (uint8_t id = 1; id <= 6; ++id) op_frame(v, id % 3, "FUZZ", 1, id, 0, 3, 40000, 0, 8);
  for (uint8_t id = 11; id <= 16; ++id) op_frame(v, id % 3, "TRACK", 1, id, 1, 2, 16, 8, 8);
  write("ops_evict", v);
  v = {2}, op_send(v, "PILOT_CMD", 900), op_send(v, "MAP_CMD", 10), write("ops_not_allowed", v);
  // Mode 3: signed commands (one whole, one fragmented), a bare one, one of another session.
  const auto command_records = [&](std::vector<uint8_t>& v, const std::string& channel, size_t size,
                                   const seal::Session& session) {
    link::DoorSender tx(&test_key(), seal::Direction::GroundToAir, 1, 0, 0, {}, limits());
    tx.sign_commands(kCommands, seal::CommandSigner(test_operator().clone()));
    tx.set_session(session);
    std::vector<uint8_t> payload(size);
    for (size_t i = 0; i < size; ++i) payload[i] = static_cast<uint8_t>(i * 11);
    std::vector<std::vector<uint8_t>> ds;
    tx.send(channel, payload, 0, ds);
    for (const auto& d : ds) {
      put16(v, static_cast<uint16_t>(d.size()));
      v.insert(v.end(), d.begin(), d.end());
    }
  };
  v = {3}, command_records(v, "TRACK", 40, test_session()), command_records(v, "FUZZ", 1000, test_session());
  command_records(v, "VO_POSE", 20, test_session()), write("commands_signed", v);
  v = {3}, command_records(v, "TRACK", 40, seal::new_session()), write("commands_other_session", v);
}

}  // namespace

extern "C" int LLVMFuzzerInitialize(int*, char***) {
  if (const char* dir = std::getenv("AERIE_DOOR_RECEIVE_SEEDS")) {
    write_seeds(dir);
    std::exit(0);
  }
  return 0;
}

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
  if (size == 0) return 0;
  const std::span<const uint8_t> rest(data + 1, size - 1);
  switch (data[0] % 4) {
    case 0: raw(rest, true); break;
    case 1: raw(rest, false); break;
    case 2: ops(rest); break;
    default: commands(rest); break;
  }
  return 0;
}
