#pragma once
// Faults injected into closed-loop flights in lock-step (docs/faults.md): a node killed and
// respawned as procman would, the cameras stalling, the air-ground link dropping or
// degrading, a burst of malformed messages on every channel, a NaN pose. A fault starts at
// a simulation time, so a faulted flight is as reproducible as a clean one.
//
// A run (loop::Harness, which owns the injector) describes its Flight and calls Injector::step once
// per frame before its buses settle; the injector sees every message through the buses' tap.
#include <cstdint>
#include <functional>
#include <map>
#include <memory>
#include <random>
#include <set>
#include <string>
#include <vector>

#include "common/bus/bus.hpp"
#include "tools/link/sim_link.hpp"

namespace aerie::loop::faults {

enum class Kind { Kill, CameraStall, LinkDrop, LinkDegrade, Burst, NanPose };

struct Fault {
  Kind kind = Kind::Kill;
  std::string target;     // kill: the node; nan_pose: the channel (TARGET_POSE, VO_POSE)
  double at_s = 0;        // simulation time it starts ...
  double at_max_s = 0;    // ... or, when later than at_s, a time drawn from the seed in [at_s, at_max_s]
  double duration_s = 0;  // kill: until the respawn; camera_stall, link_drop, link_degrade: how long
  int count = 0;          // burst: messages on each side's bus
  double delay_ms = 0, loss = 0;  // link_degrade, both directions
};

// One fault from its spec (docs/faults.md):
//   kill:NODE@T+D  camera_stall@T+D  link_drop@T+D  link_degrade@T+D:DELAY_MS:LOSS
//   burst@T:COUNT  nan_pose:CHANNEL@T
// T is seconds of simulation time, or A~B: drawn from the flight's seed in [A, B].
// Throws std::invalid_argument naming the spec and what is wrong in it.
Fault parse(const std::string& spec);
// Several, separated by spaces ("" or "none": no fault).
std::vector<Fault> parse_list(const std::string& specs);
std::string to_string(const Fault& fault);  // the spec parse() reads back

// A node the run can kill — its subscriptions leave the bus with it, messages queued for it
// are lost — and start again, fresh, as procman respawns a process.
template <typename Node>
class Respawnable {
 public:
  using Make = std::function<std::unique_ptr<Node>()>;
  Respawnable(bus::Bus& bus, Make make) : bus_(bus), make_(std::move(make)) { start(); }
  ~Respawnable() { kill(); }
  Respawnable(const Respawnable&) = delete;
  Respawnable& operator=(const Respawnable&) = delete;

  void kill() {
    if (!node_) return;
    for (const bus::Subscription* s : subs_) bus_.unsubscribe(*s);
    subs_.clear();
    node_.reset();
  }
  void start() {
    if (node_) return;
    std::set<const bus::Subscription*> before;
    for (const auto& s : bus_.subscriptions()) before.insert(s.get());
    node_ = make_();
    for (const auto& s : bus_.subscriptions())
      if (!before.count(s.get())) subs_.push_back(s.get());
  }
  Node* get() const { return node_.get(); }  // nullptr while dead

 private:
  bus::Bus& bus_;
  Make make_;
  std::unique_ptr<Node> node_;
  std::vector<const bus::Subscription*> subs_;
};

// What a flight lets faults act on.
struct Flight {
  link::SplitBus* buses = nullptr;
  std::function<void(bool stalled)> stall_cameras;
  std::map<std::string, std::function<void(bool alive)>> nodes;  // by name: kill (false), respawn (true)

  template <typename Node>
  void add(const std::string& name, Respawnable<Node>& node) {
    nodes[name] = [&node](bool alive) { alive ? node.start() : node.kill(); };
  }
};


struct Counters {
  int64_t kills = 0, respawns = 0;
  int64_t burst_messages = 0;  // published, every side
  int64_t nan_messages = 0;
};

// What a flight saw of its faults (the runs' results, the study's CSV).
struct Report {
  Counters counters;
  std::string applied = "none";    // the faults with their drawn times
  int64_t stalled_frames = 0;      // frames the cameras published nothing (camera_stall)
  int64_t command_timeouts = 0;    // the autopilot's offboard-loss holds
  int64_t malformed = 0;           // refusals by the decoders, per subscription (of the nodes alive at the end)
};

class Injector {
 public:
  // Draws the times given as ranges from the seed. Throws std::invalid_argument when faults
  // overlap in a way that has no meaning (the same node killed twice at once).
  Injector(std::vector<Fault> faults, uint64_t seed);

  // A SplitBus tap: the channels a burst covers and the newest message of each, per side
  // (not the injector's own, which are handled in the frame they are published in).
  void observe(link::Side side, const std::string& channel, const uint8_t* data, size_t size);
  // A tap for SplitBus::tap that observes, then hands the message on to `next` (may be empty).
  link::SplitBus::Tap tap(link::SplitBus::Tap next);
  // Starts and ends what is due at t_s (once per frame, before the buses settle). Throws
  // std::invalid_argument when a fault names a node the flight does not have, a link fault
  // has no link, or a NaN pose has no message to copy.
  void step(double t_s, Flight& flight);

  const Counters& counters() const { return counters_; }
  // At the end of a flight, with what the simulator counted.
  Report report(link::SplitBus& buses, int64_t stalled_frames, int64_t command_timeouts) const;
  const std::vector<Fault>& faults() const { return faults_; }  // with their times drawn
  std::string applied() const;  // the faults with their times drawn, as specs

 private:
  // Starts (on) or ends a fault; instantaneous ones (burst, NaN pose) only start.
  void set(const Fault& f, Flight& flight, bool on);
  void burst(link::Side side, int count, bus::Bus& bus);
  void nan_pose(const std::string& channel, Flight& flight);
  static std::vector<link::LinkDirection*> directions(Flight& flight);

  std::vector<Fault> faults_;
  std::vector<int> phase_;  // per fault: 0 pending, 1 active, 2 over
  std::mt19937_64 rng_;
  bool publishing_ = false;  // its own messages are on the buses: not observed until the next step
  std::map<std::pair<link::Side, std::string>, std::vector<uint8_t>> last_;  // newest message per side and channel
  Counters counters_;
};

}  // namespace aerie::loop::faults
