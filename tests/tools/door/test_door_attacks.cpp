// The probe's attacks replayed against the secured chain (issue 46 section 4: "each attack of
// the probe above, replayed against the secured chain: refused, and the vehicle flies on").
// A lock-step landing through the door (link::SimDoor, the tracker on the ground) during which
// an attacker without the mission key puts datagrams on the air half's receiving side
// (SimLink::inject): forged operator commands, a forged target stream 1.2 m off the pad,
// CTRL_CMD at 200 Hz, a Ku = -50 controller, an 8 MB TRACK_CMD INIT, 400 MAP_CMD SAVEs,
// procman orders, frames in the clear; and, from the flight's own genuine ground->air
// datagrams (SimDoor::tap): duplicates, replays 4 s later, and tampered copies sent ahead of
// the genuine ones. Every injected datagram is refused and counted under its reason, none
// reaches the air bus, and the landing and every message on both buses are byte for byte
// those of the same landing without the attacker.
#include <aerie/control_cmd_t.hpp>
#include <aerie/flc_params_t.hpp>
#include <aerie/map_cmd_t.hpp>
#include <aerie/pilot_cmd_t.hpp>
#include <aerie/target_pose_t.hpp>
#include <aerie/track_cmd_t.hpp>
#include <aerie/track_t.hpp>
#include <bot_procman/orders2_t.hpp>
#include <gtest/gtest.h>

#include <map>
#include <set>

#include "tests/tools/door/split_landing.hpp"

using namespace aerie;
using seal::Refusal;
using door_test::Message;
using door_test::record;

namespace {

using Bytes = std::vector<uint8_t>;

template <typename T>
Bytes encode(const T& m) {
  Bytes b(static_cast<size_t>(m.getEncodedSize()));
  m.encode(b.data(), 0, static_cast<int>(b.size()));
  return b;
}

// The operator's key of both flights (a run's signatures differ, what is published does not).
std::shared_ptr<const seal::OperatorKey> operator_key() {
  static const auto key = std::make_shared<const seal::OperatorKey>(seal::OperatorKey::generate());
  return key;
}

// As test_door_landing's split, with the operator's commands also allowed up (as the secure
// config/link.yaml carries them): the policy would let them cross, the seal is what refuses.
loop::landing::RunConfig landing_split(std::shared_ptr<const seal::SecretKey> key) {
  loop::landing::RunConfig rc = door_test::landing_split(2, "TRACK|TARGET_POSE|PILOT_CMD|TRACK_CMD|FLC_PARAMS|MAP_CMD");
  link::SimDoor door;
  door.key = std::move(key);  // default rekeying: one epoch for the flight, so each refusal's reason is exact
  door.operator_channels = link::kDefaultOperatorChannels;  // the operator signs, as aerie-link's halves
  door.operator_key = operator_key();
  rc.split->door = door;
  return rc;
}

// The attacker: no mission key (its own random one, or none), and what it sees of the radio --
// and an insider who holds the mission key (a stolen ground station that only watched) but not
// the operator's key.
class Attacker {
 public:
  explicit Attacker(std::shared_ptr<const seal::SecretKey> mission)
      : insider_(mission.get(), seal::Direction::GroundToAir, 9, 0, 0.0) {}
  // What each injected datagram was refused as, per attack.
  std::map<std::string, std::map<Refusal, int>> refused;
  std::map<std::string, std::map<seal::CommandRefusal, int>> command_refused;  // the insider's
  std::map<std::string, int> insecure, published, other;
  std::map<std::string, int> sent;  // datagrams injected, per attack
  int injected = 0, frames = 0, seconds = 0;
  size_t init_bytes = 0;             // the 8 MB TRACK_CMD's encoded size
  std::set<Bytes> forged_payloads;  // what the forged datagrams carry
  link::ReceiverCounters last;      // the air half's receiver after the latest injection

  void attach(link::SimDoor& door) {
    door.on_deliver = [this](link::SimLink& l, double now_s) { on_deliver(l, now_s); };
    door.tap = [this](bool down, std::span<const uint8_t> d, double now_s) { on_tap(down, d, now_s); };
  }

 private:
  void inject(const std::string& attack, std::span<const uint8_t> d) {
    const link::ReceiverCounters before = link_->door(false)->receiver.counters();
    if (link_->inject(false, d)) ++published[attack];
    last = link_->door(false)->receiver.counters();
    ++injected;
    ++sent[attack];
    if (last.insecure_peer == before.insecure_peer + 1) {
      ++insecure[attack];
      return;
    }
    for (size_t r = 1; r < seal::kRefusalCount; ++r)
      if (last.opener.refused[r] == before.opener.refused[r] + 1) {
        ++refused[attack][static_cast<Refusal>(r)];
        return;
      }
    for (size_t r = 1; r < seal::kCommandRefusalCount; ++r)
      if (last.commands_refused[r] == before.commands_refused[r] + 1) {
        ++command_refused[attack][static_cast<seal::CommandRefusal>(r)];
        return;
      }
    ++other[attack];
  }
  template <typename T>
  void forge(const std::string& attack, const std::string& channel, const T& m, double now_s,
             link::DoorSender* sender = nullptr) {
    const Bytes payload = encode(m);
    forged_payloads.insert(payload);
    ASSERT_TRUE((sender ? *sender : forger_).send(channel, payload, now_s, datagrams_));
    for (const auto& d : datagrams_) inject(attack, d);
  }

  void on_deliver(link::SimLink& l, double now_s) {
    link_ = &l;
    if (t0_ < 0) t0_ = now_s;
    const double t = now_s - t0_;
    // Duplicates of what crossed in the last delivery, at once.
    for (const auto& d : duplicate_) inject("duplicate", d);
    duplicate_.clear();
    // Replays of genuine datagrams, 4 s after they crossed.
    while (!recorded_.empty() && recorded_.front().first + 4.0 <= t) {
      inject("replay_4s", recorded_.front().second);
      recorded_.erase(recorded_.begin());
    }
    const int frame = static_cast<int>(std::lround(t * 20));  // 20 Hz cameras
    if (frame == last_frame_ || t < 1.0 || t > 16.0) return;  // once per frame, 1..16 s
    last_frame_ = frame;
    ++frames;
    const int64_t ut = static_cast<int64_t>(now_s * 1e6);

    aerie::target_pose_t pose{};  // a fitted pose at x = 1.2 m, as the probe's stream 1.2 m off the pad
    pose.utime = ut;
    pose.seq = frame;
    pose.target = "pad";
    pose.position[0] = 1.2;
    pose.position[2] = -1.0;
    pose.confidence = 1;
    pose.source = aerie::target_pose_t::SOURCE_FIT;
    forge("target_pose", "TARGET_POSE", pose, now_s);
    aerie::track_t track{};
    track.utime = ut;
    forge("track", "TRACK", track, now_s);
    for (int i = 0; i < 10; ++i) {  // 200 Hz
      aerie::control_cmd_t c{};
      c.utime = ut + i * 5000;
      c.seq = frame * 10 + i;
      c.mode = aerie::control_cmd_t::ACTIVE;
      c.controller_id = "attacker";
      c.velocity_body[0] = 5;  // into the wall
      forge("ctrl_cmd_200hz", "CTRL_CMD", c, now_s);
    }
    for (int i = 0; i < 4 && saves_ < 400; ++i, ++saves_) {
      aerie::map_cmd_t m{};
      m.utime = ut;
      m.seq = saves_;
      m.command = aerie::map_cmd_t::SAVE;
      m.path = "/tmp/fill_" + std::to_string(saves_) + ".bt";
      forge("map_save", "MAP_CMD", m, now_s);
    }
    if (frame % 20 == 0) {  // each second: procman orders, and an ABORT in the clear
      ++seconds;
      bot_procman::orders2_t o{};
      o.utime = ut + 10LL * 365 * 86400 * 1000000;  // ten years ahead
      o.host = "air";
      o.sheriff_name = "aerie-sheriff";
      o.ncmds = 1;
      o.cmds.resize(1);
      o.cmds[0].cmd.exec_str = "touch /tmp/owned";
      o.cmds[0].cmd.command_name = "owned";
      o.cmds[0].desired_runid = frame;
      forge("pmd_orders2", "PMD_ORDERS2", o, now_s);
      aerie::pilot_cmd_t a{};
      a.utime = ut;
      a.command = aerie::pilot_cmd_t::ABORT;
      a.source = "operator";
      const Bytes p = encode(a);
      forged_payloads.insert(p);
      ASSERT_TRUE(keyless_.send("PILOT_CMD", p, now_s, datagrams_));
      for (const auto& d : datagrams_) inject("pilot_abort_in_the_clear", d);
    }
    auto pilot = [&](int8_t command, const char* attack, link::DoorSender* sender = nullptr) {
      aerie::pilot_cmd_t c{};
      c.utime = ut;
      c.seq = frame;
      c.command = command;
      c.source = "operator";
      forge(attack, "PILOT_CMD", c, now_s, sender);
    };
    if (frame == 40) pilot(aerie::pilot_cmd_t::ABORT, "pilot_abort");
    // The insider: sealed with the mission key, so the datagrams open; the commands do not pass.
    if (frame == 70) pilot(aerie::pilot_cmd_t::LAND, "insider_pilot_land", &insider_);
    if (frame == 110) {
      // Signed with a key of its own, for the session it learnt by opening the air half's hello.
      insider_.sign_commands("PILOT_CMD", seal::CommandSigner(seal::OperatorKey::generate()));
      insider_.set_session(*link_->door(true)->receiver.peer_session());
      pilot(aerie::pilot_cmd_t::ABORT, "insider_signed_abort", &insider_);
      insider_.sign_commands("", std::nullopt);
    }
    if (frame == 60) pilot(aerie::pilot_cmd_t::LAND, "pilot_land");
    if (frame == 80) {
      aerie::track_cmd_t c{};
      c.utime = ut;
      c.command = aerie::track_cmd_t::STOP;
      forge("track_stop", "TRACK_CMD", c, now_s);
    }
    if (frame == 100) {
      aerie::flc_params_t f{};
      f.utime = ut;
      f.controller_id = "yaw";
      f.nparams = 1;
      f.names = {"Ku"};
      f.values = {-50.0};
      forge("flc_ku_minus_50", "FLC_PARAMS", f, now_s);
    }
    if (frame == 140)  // the ground's own sender id: its counters 1.. were used already, refused before the tag
      for (int i = 0; i < 10; ++i) {
        aerie::pilot_cmd_t c{};
        c.utime = ut;
        c.seq = i;
        c.command = aerie::pilot_cmd_t::ABORT;
        c.source = "operator";
        forge("pilot_abort_as_ground_sender", "PILOT_CMD", c, now_s, &spoofer_);
      }
    if (frame == 120) {
      aerie::track_cmd_t c{};
      c.utime = ut;
      c.command = aerie::track_cmd_t::INIT;
      c.tracker = "ct";
      c.width = c.height = 10;
      c.nparams = 1;
      c.param_names = {"x"};
      c.param_values = {std::string(8'000'000, 'A')};  // 8 MB: fragments
      init_bytes = static_cast<size_t>(c.getEncodedSize());
      forge("track_init_8mb", "TRACK_CMD", c, now_s);
    }
  }

  // The genuine ground->air datagrams, seen on the radio before the air half opens them.
  void on_tap(bool down, std::span<const uint8_t> d, double now_s) {
    if (down || t0_ < 0) return;
    const double t = now_s - t0_;
    const Bytes g(d.begin(), d.end());
    if (t >= 3.0 && t < 4.0) recorded_.emplace_back(t, g);  // replayed 4 s later
    if (t >= 5.0 && t < 6.0) duplicate_.push_back(g);
    if (t >= 9.0 && t < 10.0) {  // tampered copies, raced ahead of the genuine one
      Bytes body = g;
      body[seal::kHeaderSize + (tampered_++ % (body.size() - seal::kHeaderSize))] ^= 0x40;
      inject("flipped_body", body);
      Bytes header = g;
      header[19] ^= 0x01;  // the counter's top byte: a fresh counter, so the tag is what refuses
      inject("flipped_counter", header);
    }
  }

  link::DoorSender insider_;
  seal::SecretKey wrong_ = seal::SecretKey::generate();
  link::DoorSender forger_{&wrong_, seal::Direction::GroundToAir, 7, 0, 0.0};   // a sender id of its own
  link::DoorSender spoofer_{&wrong_, seal::Direction::GroundToAir, 2, 0, 0.0};  // the ground's sender id
  link::DoorSender keyless_{nullptr, seal::Direction::GroundToAir, 2, 0, 0.0};  // --insecure
  std::vector<Bytes> datagrams_;
  link::SimLink* link_ = nullptr;  // valid during the flight's deliveries
  double t0_ = -1;
  int last_frame_ = -1, saves_ = 0;
  size_t tampered_ = 0;
  std::vector<std::pair<double, Bytes>> recorded_;
  std::vector<Bytes> duplicate_;
};


}  // namespace

TEST(DoorAttacks, EveryAttackOfTheProbeIsRefusedAndCountedAndTheVehicleLandsAsWithout) {
  const auto key = std::make_shared<const seal::SecretKey>(seal::SecretKey::generate());
  loop::landing::RunResult plain, attacked;
  const auto a = record(landing_split(key), plain);
  Attacker attacker(key);
  loop::landing::RunConfig rc = landing_split(key);
  attacker.attach(*rc.split->door);
  const auto b = record(rc, attacked);

  // Every attack made, each datagram refused under the one reason expected for it.
  const int frames = attacker.frames;
  EXPECT_GE(frames, 300);  // 1..16 s at 20 Hz
  const size_t chunk = seal::kMaxPayload - link::kFragmentHeader;
  const std::map<std::string, std::pair<Refusal, int>> expected = {
      {"target_pose", {Refusal::AuthFailed, frames}},
      {"track", {Refusal::AuthFailed, frames}},
      {"ctrl_cmd_200hz", {Refusal::AuthFailed, 10 * frames}},
      {"map_save", {Refusal::AuthFailed, 400}},
      {"pmd_orders2", {Refusal::AuthFailed, attacker.seconds}},
      {"pilot_abort", {Refusal::AuthFailed, 1}},
      {"pilot_land", {Refusal::AuthFailed, 1}},
      {"track_stop", {Refusal::AuthFailed, 1}},
      {"flc_ku_minus_50", {Refusal::AuthFailed, 1}},
      {"track_init_8mb", {Refusal::AuthFailed, static_cast<int>((attacker.init_bytes + chunk - 1) / chunk)}},
      {"pilot_abort_as_ground_sender", {Refusal::Replayed, 10}},
      {"replay_4s", {Refusal::Replayed, attacker.sent["replay_4s"]}},
      {"duplicate", {Refusal::Replayed, attacker.sent["duplicate"]}},
      {"flipped_body", {Refusal::AuthFailed, attacker.sent["flipped_body"]}},
      {"flipped_counter", {Refusal::AuthFailed, attacker.sent["flipped_counter"]}},
  };
  EXPECT_GT(attacker.init_bytes, 8'000'000u);
  EXPECT_EQ(expected.at("track_init_8mb").second, 123);
  for (const char* genuine : {"replay_4s", "duplicate", "flipped_body", "flipped_counter"})
    EXPECT_GE(attacker.sent[genuine], 15) << genuine << ": a second of the tracker's results";
  int total = 0;
  for (const auto& [attack, want] : expected) {
    EXPECT_EQ(attacker.sent[attack], want.second) << attack;
    EXPECT_EQ(attacker.refused[attack], (std::map<Refusal, int>{{want.first, want.second}}))
        << attack << " refused as " << seal::to_string(want.first);
    total += want.second;
  }
  // The insider's commands: authentic datagrams, refused for their signature.
  const std::map<std::string, std::pair<seal::CommandRefusal, int>> insider = {
      {"insider_pilot_land", {seal::CommandRefusal::Unsigned, 1}},
      {"insider_signed_abort", {seal::CommandRefusal::BadSignature, 1}},
  };
  for (const auto& [attack, want] : insider) {
    EXPECT_EQ(attacker.sent[attack], want.second) << attack;
    EXPECT_EQ(attacker.command_refused[attack], (std::map<seal::CommandRefusal, int>{{want.first, want.second}}))
        << attack << " refused as " << seal::to_string(want.first);
    total += want.second;
  }
  EXPECT_EQ(attacker.sent["pilot_abort_in_the_clear"], attacker.seconds);
  EXPECT_EQ(attacker.insecure["pilot_abort_in_the_clear"], attacker.seconds);
  total += attacker.seconds;
  EXPECT_EQ(attacker.injected, total);
  EXPECT_TRUE(attacker.published.empty()) << "an injected datagram was published on the air bus";
  EXPECT_TRUE(attacker.other.empty()) << "an injected datagram refused for another reason";

  // The air half's counters: exactly the injected datagrams refused, by reason; nothing else.
  const link::ReceiverCounters& c = attacker.last;
  int auth = 0, replayed = 0;
  for (const auto& [attack, want] : expected) (want.first == Refusal::AuthFailed ? auth : replayed) += want.second;
  EXPECT_EQ(c.opener[Refusal::AuthFailed], static_cast<uint64_t>(auth));
  EXPECT_EQ(c.opener[Refusal::Replayed], static_cast<uint64_t>(replayed));
  EXPECT_EQ(c.opener.refused_total(), static_cast<uint64_t>(auth + replayed));
  EXPECT_EQ(c.insecure_peer, static_cast<uint64_t>(attacker.seconds));
  EXPECT_EQ(c.not_allowed, 0u);
  EXPECT_EQ(c.rate_limited, 0u);
  EXPECT_EQ(c.malformed, 0u);
  EXPECT_EQ(c.reassembly_dropped, 0u);
  EXPECT_EQ(c.fragments, 0u) << "no forged fragment authenticated, so none was buffered";

  // None reaches the air bus.
  int commands = 0, forged = 0;
  for (const Message& m : b) {
    if (m.side != link::Side::kAir) continue;
    commands += m.channel == "PILOT_CMD" || m.channel == "TRACK_CMD" || m.channel == "FLC_PARAMS" ||
                m.channel == "MAP_CMD" || m.channel == "PMD_ORDERS2";
    forged += attacker.forged_payloads.count(m.bytes) > 0;
  }
  EXPECT_EQ(commands, 0);
  EXPECT_EQ(forged, 0);

  // And the vehicle flies on: the same landing, the same messages on both buses, byte for byte.
  ASSERT_TRUE(plain.outcome.landed) << plain.final_state;
  EXPECT_GT(plain.sim_s, 17.0) << "the attacks end before the landing";
  EXPECT_TRUE(attacked.outcome.landed) << attacked.final_state;
  EXPECT_EQ(attacked.final_state, plain.final_state);
  EXPECT_EQ(attacked.score.success, plain.score.success);
  EXPECT_EQ(attacked.score.touchdown_error_m, plain.score.touchdown_error_m);
  EXPECT_EQ(attacked.score.yaw_error_deg, plain.score.yaw_error_deg);
  EXPECT_EQ(attacked.sim_s, plain.sim_s);
  EXPECT_EQ(attacked.target_poses, plain.target_poses);
  EXPECT_EQ(attacked.pilot_refused, plain.pilot_refused);
  EXPECT_EQ(attacked.commands_refused, plain.commands_refused);
  EXPECT_EQ(attacked.link_up.delivered, plain.link_up.delivered);
  EXPECT_EQ(attacked.link_down.delivered, plain.link_down.delivered);
  ASSERT_EQ(a.size(), b.size());
  size_t first_diff = a.size();
  for (size_t i = 0; i < a.size() && first_diff == a.size(); ++i)
    if (!(a[i] == b[i])) first_diff = i;
  EXPECT_EQ(first_diff, a.size()) << "first difference at message " << first_diff << " on "
                                  << (first_diff < a.size() ? a[first_diff].channel : "");
}
