#include "tools/link/sim_link.hpp"

#include <algorithm>
#include <stdexcept>

namespace aerie::link {

Side side_from_name(const std::string& name) {
  if (name == "air") return Side::kAir;
  if (name == "ground") return Side::kGround;
  throw std::invalid_argument("side must be air or ground, not '" + name + "'");
}

const char* side_name(Side side) { return side == Side::kAir ? "air" : "ground"; }

Side Split::side(const std::string& node) const {
  const auto it = nodes.find(node);
  return it == nodes.end() ? Side::kAir : it->second;
}

namespace {
// "" = nothing crosses this way: allowed here (aerie-link's configuration refuses it).
DirectionConfig none_allowed(DirectionConfig d) {
  if (d.channels.empty()) d.channels = "$^";
  return d;
}
}  // namespace

SimLink::SimLink(bus::Bus& air, bus::Bus& ground, const DirectionConfig& down, const DirectionConfig& up,
                 const std::optional<SimDoor>& door)
    : air_(air), ground_(ground), down_(none_allowed(down)), up_(none_allowed(up)) {
  if (door) {
    hooks_ = door;
    seal::OpenerConfig o;
    o.overlap_s = door->overlap_s;
    const seal::SecretKey* k = door->key.get();
    door_down_ = std::make_unique<DoorEnds>(DoorEnds{
        DoorSender(k, seal::Direction::AirToGround, 1, 0, 0.0, door->rekey, door->limits),
        DoorReceiver(k, seal::Direction::AirToGround, DoorPolicy{down.channels, door->down_rates, ""}, o, door->limits)});
    door_up_ = std::make_unique<DoorEnds>(DoorEnds{
        DoorSender(k, seal::Direction::GroundToAir, 2, 0, 0.0, door->rekey, door->limits),
        DoorReceiver(k, seal::Direction::GroundToAir, DoorPolicy{up.channels, door->up_rates, door->operator_channels},
                     o, door->limits)});
    if (k && !door->operator_channels.empty()) {
      // The air half's session, announced down through the door as aerie-link --half air does.
      const seal::Session session = seal::new_session();
      if (door->operator_key)
        door_up_->receiver.require_operator(seal::CommandVerifier({door->operator_key->public_key()}, session));
      std::optional<seal::CommandSigner> signer;
      if (door->operator_key) signer.emplace(door->operator_key->clone());
      door_up_->sender.sign_commands(door->operator_channels, std::move(signer));
      std::vector<uint8_t> hello;
      door_down_->sender.hello(session, 0.0, hello);
      door_down_->receiver.receive(hello, 0.0);
      if (door_down_->receiver.peer_session()) door_up_->sender.set_session(*door_down_->receiver.peer_session());
    }
  }
  // Deep queues: in lock-step nothing may be dropped before the link model decides.
  if (!down.channels.empty())
    air_.subscribe_raw(down.channels, [this](const uint8_t* data, size_t size, const bus::ReceiveInfo& info) {
      down_.take(info.channel, data, size, info.recv_utime, now_us_);
    }, 100000);
  if (!up.channels.empty())
    ground_.subscribe_raw(up.channels, [this](const uint8_t* data, size_t size, const bus::ReceiveInfo& info) {
      up_.take(info.channel, data, size, info.recv_utime, now_us_);
    }, 100000);
}

bool SimLink::inject(bool down, std::span<const uint8_t> datagram) {
  DoorEnds* d = down ? door_down_.get() : door_up_.get();
  if (!d) throw std::logic_error("SimLink::inject: the link has no door");
  const auto m = d->receiver.receive(datagram, static_cast<double>(now_us_) * 1e-6);
  if (!m) return false;
  bus::Bus& b = down ? ground_ : air_;
  b.publish_raw(m->channel, m->payload.data(), static_cast<unsigned>(m->payload.size()));
  ++injected_;
  return true;
}

int SimLink::deliver() {
  int n = 0;
  if (hooks_ && hooks_->on_deliver) {
    const int before = injected_;
    hooks_->on_deliver(*this, static_cast<double>(now_us_) * 1e-6);
    n += injected_ - before;  // so that settle() handles them in this round
  }
  for (Relay* r : {&down_, &up_}) {
    const Side to = r == &down_ ? Side::kGround : Side::kAir;
    bus::Bus& b = to == Side::kGround ? ground_ : air_;
    DoorEnds* d = r == &down_ ? door_down_.get() : door_up_.get();
    const double t = static_cast<double>(now_us_) * 1e-6;
    for (const Packet& p : r->due(now_us_)) {
      if (!d) {
        b.publish_raw(p.channel, p.data.data(), static_cast<unsigned>(p.data.size()));
        ++n;
        continue;
      }
      // Sealed by the sending half, opened by the receiving one (refusals counted there).
      if (!d->sender.send(p.channel, p.data, t, datagrams_)) continue;
      for (const auto& dg : datagrams_) {
        if (hooks_->tap) hooks_->tap(r == &down_, dg, t);
        if (auto m = d->receiver.receive(dg, t)) {
          b.publish_raw(m->channel, m->payload.data(), static_cast<unsigned>(m->payload.size()));
          ++n;
        }
      }
    }
  }
  return n;
}

int64_t SimLink::next_event_us() const {
  const int64_t d = down_.model().next_event_us(), u = up_.model().next_event_us();
  return d < 0 ? u : u < 0 ? d : std::min(d, u);
}

SplitBus::SplitBus(const std::optional<Split>& split) : split_(split), air_("memq://") {
  if (!split_) return;
  ground_ = std::make_unique<bus::Bus>("memq://");
  link_ = std::make_unique<SimLink>(air_, *ground_, split_->down, split_->up, split_->door);
}

DirectionCounters SplitBus::down_counters() const { return link_ ? link_->down().model().counters() : DirectionCounters{}; }
DirectionCounters SplitBus::up_counters() const { return link_ ? link_->up().model().counters() : DirectionCounters{}; }

void SplitBus::tap(Tap tap) {
  if (!tap) return;
  for (Side side : {Side::kAir, Side::kGround}) {
    if (side == Side::kGround && !ground_) break;
    on(side).subscribe_raw(".*", [this, tap, side](const uint8_t* data, size_t size, const bus::ReceiveInfo& info) {
      tap(side, info.channel, data, size, now_us_);
    }, 100000);
  }
}

void SplitBus::settle(int64_t now_us, const std::function<void()>& wait_workers) {
  now_us_ = now_us;
  if (link_) link_->set_time(now_us);
  while (true) {
    int n = 0;
    for (int round = 0; round < 2; ++round) {  // before and after the workers' outputs
      while (air_.handle(0) > 0) ++n;
      if (ground_)
        while (ground_->handle(0) > 0) ++n;
      if (round == 0 && wait_workers) wait_workers();
    }
    if (link_) n += link_->deliver();
    if (n == 0) return;
  }
}

}  // namespace aerie::link
