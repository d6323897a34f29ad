#pragma once
// The air-ground link in simulation time, for split deployments flown in lock-step.
//
// Two in-process buses (memq://) stand for the air and the ground networks; a Relay per
// direction joins them on the simulation's clock. What a side publishes on a direction's
// channels is offered to the link at the current simulation time (set_time) and published
// on the other side once the link model delivers it. Nothing waits on a wall clock, so a
// run delivers the same messages at the same simulation times on a loaded machine as on a
// quiet one. Nodes see a delivery when the driver settles the buses: in a frame-stepped
// simulation, at the first frame at or after its delivery time.
#include <cstdint>
#include <functional>
#include <map>
#include <memory>
#include <optional>
#include <span>
#include <stdexcept>
#include <string>

#include "common/bus/bus.hpp"
#include "common/seal/keys.hpp"
#include "tools/link/door.hpp"
#include "tools/link/relay.hpp"

namespace aerie::link {

enum class Side { kAir, kGround };
Side side_from_name(const std::string& name);  // air | ground; throws std::invalid_argument naming it
const char* side_name(Side side);

// The door in simulation time (docs/link.md "The door in lock-step"): every message the link
// delivers is first sealed by the sending half's DoorSender and opened by the receiving
// half's DoorReceiver (policy: the direction's channels and `rates`), in process, with the
// simulation's clock for rekeying -- what aerie-link --half does between the impairments and
// the far network, without sockets.
class SimLink;

struct SimDoor {
  std::shared_ptr<const seal::SecretKey> key;  // null: insecure frames (still framed and checked)
  seal::RekeyPolicy rekey;                     // seconds of simulation time
  double overlap_s = 5.0;
  ReassemblyLimits limits;
  std::vector<RateRule> down_rates, up_rates;
  // The operator's role (common/seal/operator.hpp): ground -> air messages on operator_channels
  // are signed with operator_key by the ground half, for the session the air half announced in
  // its hello, and checked by the air half. "" = no operator's channels; with channels but no
  // key the air half refuses those commands, as aerie-link's ground half without --operator-key.
  std::string operator_channels;
  std::shared_ptr<const seal::OperatorKey> operator_key;
  // Test hooks (tests/tools/door/test_door_attacks.cpp): `tap` sees each datagram a sending
  // half sealed (down: air->ground), before the far half opens it; `on_deliver` is called at
  // the start of each SimLink::deliver(), where a test may SimLink::inject() what a third
  // party puts on a receiving side.
  std::function<void(bool down, std::span<const uint8_t> datagram, double now_s)> tap;
  std::function<void(SimLink& link, double now_s)> on_deliver;
};

// Where each node runs, and the link between the two sides.
struct Split {
  std::map<std::string, Side> nodes;  // nodes not named run on the air side
  DirectionConfig down, up;           // air->ground and ground->air; `channels` says what crosses ("" = nothing)
  std::optional<SimDoor> door = std::nullopt;  // the sealed door on the link's path
  Side side(const std::string& node) const;
};

class SimLink {
 public:
  SimLink(bus::Bus& air, bus::Bus& ground, const DirectionConfig& down, const DirectionConfig& up,
          const std::optional<SimDoor>& door = std::nullopt);
  SimLink(const SimLink&) = delete;
  SimLink& operator=(const SimLink&) = delete;

  // The simulation time (µs) at which what is published from now on is offered.
  void set_time(int64_t now_us) { now_us_ = now_us; }
  int64_t time() const { return now_us_; }
  // Publishes on the far side what the link delivers by now; returns how many messages.
  int deliver();
  // When the link next delivers (or sends) something; -1 when it is empty.
  int64_t next_event_us() const;
  // A datagram from a third party on a direction's receiving side (down: the ground half's),
  // opened now by that half's DoorReceiver like any other; published on its bus only if it
  // opens and passes the policy. Returns whether it was published. Throws std::logic_error
  // without a door.
  bool inject(bool down, std::span<const uint8_t> datagram);

  Relay& down() { return down_; }
  Relay& up() { return up_; }
  // The door's ends per direction (null without a door).
  struct DoorEnds {
    DoorSender sender;
    DoorReceiver receiver;
  };
  const DoorEnds* door(bool down) const { return down ? door_down_.get() : door_up_.get(); }

 private:
  bus::Bus &air_, &ground_;
  Relay down_, up_;
  std::optional<SimDoor> hooks_;  // the door's tap and on_deliver
  int injected_ = 0;              // injected datagrams published (deliver() counts them)
  std::unique_ptr<DoorEnds> door_down_, door_up_;
  std::vector<std::vector<uint8_t>> datagrams_;
  int64_t now_us_ = 0;
};

// The buses of a lock-step run: one (every node on it) or, with a split, the air and the
// ground buses joined by a SimLink.
class SplitBus {
 public:
  explicit SplitBus(const std::optional<Split>& split);
  bus::Bus& on(Side side) { return side == Side::kGround && ground_ ? *ground_ : air_; }
  bus::Bus& of(const std::string& node) { return on(split_ ? split_->side(node) : Side::kAir); }
  SimLink* link() { return link_.get(); }
  // What each direction received, delivered and dropped (zeros without a split).
  DirectionCounters down_counters() const;
  DirectionCounters up_counters() const;

  // A message on a side's bus, with the simulation time (µs) it is handled at.
  using Tap = std::function<void(Side side, const std::string& channel, const uint8_t* data, size_t size, int64_t now_us)>;
  // `tap` sees every message on each bus (one side only without a split), e.g. to log it.
  void tap(Tap tap);

  // Handles every message pending on the buses and delivers what the link has due at
  // now_us, round after round, until nothing is left. wait_workers (may be empty) waits
  // for the nodes' own threads (e.g. the tracker's) at each round.
  void settle(int64_t now_us, const std::function<void()>& wait_workers = {});

 private:
  std::optional<Split> split_;
  int64_t now_us_ = 0;
  bus::Bus air_;
  std::unique_ptr<bus::Bus> ground_;
  std::unique_ptr<SimLink> link_;
};

}  // namespace aerie::link
