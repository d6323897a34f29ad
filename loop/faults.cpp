#include "loop/faults.hpp"

#include <aerie/pose_t.hpp>
#include <aerie/target_pose_t.hpp>

#include <algorithm>
#include <cmath>
#include <limits>
#include <sstream>
#include <stdexcept>

#include "common/bus/wire.hpp"

namespace aerie::loop::faults {

namespace {

const std::map<std::string, Kind>& kinds() {
  static const std::map<std::string, Kind> k{{"kill", Kind::Kill},         {"camera_stall", Kind::CameraStall},
                                             {"link_drop", Kind::LinkDrop}, {"link_degrade", Kind::LinkDegrade},
                                             {"burst", Kind::Burst},        {"nan_pose", Kind::NanPose}};
  return k;
}

std::vector<std::string> split(const std::string& s, char sep) {
  std::vector<std::string> out;
  std::stringstream ss(s);
  std::string part;
  while (std::getline(ss, part, sep)) out.push_back(part);
  if (!s.empty() && s.back() == sep) out.emplace_back();
  return out;
}

double number(const std::string& spec, const std::string& what, const std::string& text) {
  size_t used = 0;
  double v = std::nan("");
  try {
    v = std::stod(text, &used);
  } catch (const std::exception&) {
    used = 0;
  }
  if (used != text.size() || text.empty() || !std::isfinite(v) || v < 0)
    throw std::invalid_argument("fault '" + spec + "': " + what + " must be a number >= 0, got '" + text + "'");
  return v;
}

}  // namespace

Fault parse(const std::string& spec) {
  const auto at = spec.find('@');
  if (at == std::string::npos)
    throw std::invalid_argument("fault '" + spec + "': expected KIND[:TARGET]@TIME..., e.g. kill:track@8+1 (docs/faults.md)");
  const std::string head = spec.substr(0, at), tail = spec.substr(at + 1);
  const auto colon = head.find(':');
  const std::string name = head.substr(0, colon);
  const auto k = kinds().find(name);
  if (k == kinds().end())
    throw std::invalid_argument("fault '" + spec + "': unknown kind '" + name +
                                "' (kill, camera_stall, link_drop, link_degrade, burst, nan_pose)");
  Fault f;
  f.kind = k->second;
  if (colon != std::string::npos) f.target = head.substr(colon + 1);
  const bool needs_target = f.kind == Kind::Kill || f.kind == Kind::NanPose;
  if (needs_target && f.target.empty())
    throw std::invalid_argument("fault '" + spec + "': " + name + " needs a " + (f.kind == Kind::Kill ? "node" : "channel") +
                                " (" + name + ":NAME@...)");
  if (!needs_target && !f.target.empty()) throw std::invalid_argument("fault '" + spec + "': " + name + " takes no target");

  const std::vector<std::string> fields = split(tail, ':');
  const auto plus = fields[0].find('+');
  const std::string when = fields[0].substr(0, plus);
  const auto tilde = when.find('~');
  f.at_s = number(spec, "the start time", when.substr(0, tilde));
  f.at_max_s = tilde == std::string::npos ? f.at_s : number(spec, "the latest start time", when.substr(tilde + 1));
  if (f.at_max_s < f.at_s) throw std::invalid_argument("fault '" + spec + "': the time range " + when + " ends before it starts");
  const bool has_duration = f.kind == Kind::Kill || f.kind == Kind::CameraStall || f.kind == Kind::LinkDrop ||
                            f.kind == Kind::LinkDegrade;
  if (has_duration != (plus != std::string::npos))
    throw std::invalid_argument("fault '" + spec + "': " + name + (has_duration ? " needs a duration (+D)" : " takes no duration (+D)"));
  if (has_duration) {
    f.duration_s = number(spec, "the duration", fields[0].substr(plus + 1));
    if (f.duration_s <= 0) throw std::invalid_argument("fault '" + spec + "': the duration must be > 0");
  }
  const size_t extra = f.kind == Kind::LinkDegrade ? 2 : f.kind == Kind::Burst ? 1 : 0;
  if (fields.size() != 1 + extra)
    throw std::invalid_argument("fault '" + spec + "': " + name +
                                (extra == 2   ? " is link_degrade@T+D:DELAY_MS:LOSS"
                                 : extra == 1 ? " is burst@T:COUNT"
                                              : " takes nothing after its time"));
  if (f.kind == Kind::LinkDegrade) {
    f.delay_ms = number(spec, "the delay (ms)", fields[1]);
    f.loss = number(spec, "the loss", fields[2]);
    if (f.loss > 1) throw std::invalid_argument("fault '" + spec + "': the loss must be in [0, 1]");
  }
  if (f.kind == Kind::Burst) {
    const double n = number(spec, "the count", fields[1]);
    if (n < 1 || n > 1e7 || n != std::floor(n)) throw std::invalid_argument("fault '" + spec + "': the count must be an integer in [1, 1e7]");
    f.count = static_cast<int>(n);
  }
  return f;
}

std::string to_string(const Fault& f) {
  std::string name;
  for (const auto& [n, k] : kinds())
    if (k == f.kind) name = n;
  std::ostringstream s;
  s << name << (f.target.empty() ? "" : ":" + f.target) << '@' << f.at_s;
  if (f.at_max_s > f.at_s) s << '~' << f.at_max_s;
  if (f.duration_s > 0) s << '+' << f.duration_s;
  if (f.kind == Kind::LinkDegrade) s << ':' << f.delay_ms << ':' << f.loss;
  if (f.kind == Kind::Burst) s << ':' << f.count;
  return s.str();
}

std::vector<Fault> parse_list(const std::string& specs) {
  std::vector<Fault> out;
  std::stringstream ss(specs);
  for (std::string s; ss >> s;)
    if (s != "none") out.push_back(parse(s));
  return out;
}

Report Injector::report(link::SplitBus& buses, int64_t stalled_frames, int64_t command_timeouts) const {
  Report r{counters_, applied(), stalled_frames, command_timeouts, 0};
  for (const link::Side side : {link::Side::kAir, link::Side::kGround})
    if (side == link::Side::kAir || buses.link())
      for (const auto& s : buses.on(side).subscriptions()) r.malformed += s->counters().malformed;
  return r;
}

std::string Injector::applied() const {
  std::string s;
  for (const Fault& f : faults_) s += (s.empty() ? "" : " ") + to_string(f);
  return s.empty() ? "none" : s;
}

Injector::Injector(std::vector<Fault> faults, uint64_t seed) : faults_(std::move(faults)), rng_(seed ^ 0xfa017) {
  phase_.assign(faults_.size(), 0);
  for (Fault& f : faults_)
    if (f.at_max_s > f.at_s) f.at_s = f.at_max_s = std::uniform_real_distribution<double>(f.at_s, f.at_max_s)(rng_);
  for (size_t i = 0; i < faults_.size(); ++i)
    for (size_t j = 0; j < i; ++j) {
      const Fault &a = faults_[i], &b = faults_[j];
      const bool overlap = a.at_s < b.at_s + b.duration_s && b.at_s < a.at_s + a.duration_s;
      if (a.kind == Kind::Kill && b.kind == Kind::Kill && a.target == b.target && overlap)
        throw std::invalid_argument("faults '" + to_string(b) + "' and '" + to_string(a) + "' kill " + a.target +
                                    " while it is already dead");
    }
}

void Injector::observe(link::Side side, const std::string& channel, const uint8_t* data, size_t size) {
  if (publishing_) return;
  last_[{side, channel}].assign(data, data + size);
}

link::SplitBus::Tap Injector::tap(link::SplitBus::Tap next) {
  return [this, next = std::move(next)](link::Side side, const std::string& channel, const uint8_t* data, size_t size,
                                        int64_t now_us) {
    observe(side, channel, data, size);
    if (next) next(side, channel, data, size, now_us);
  };
}

std::vector<link::LinkDirection*> Injector::directions(Flight& flight) {
  link::SimLink* l = flight.buses->link();
  if (!l) throw std::invalid_argument("link faults need a split deployment (a link between air and ground)");
  return {&l->down().model(), &l->up().model()};
}

void Injector::step(double t_s, Flight& flight) {
  publishing_ = false;
  for (size_t i = 0; i < faults_.size(); ++i) {
    const Fault& f = faults_[i];
    if (phase_[i] == 0 && t_s + 1e-9 >= f.at_s) {
      phase_[i] = f.duration_s > 0 ? 1 : 2;
      set(f, flight, true);
    }
    if (phase_[i] == 1 && t_s + 1e-9 >= f.at_s + f.duration_s) {
      phase_[i] = 2;
      set(f, flight, false);
    }
  }
}

void Injector::set(const Fault& f, Flight& flight, bool on) {
  switch (f.kind) {
    case Kind::Kill: {
      const auto node = flight.nodes.find(f.target);
      if (node == flight.nodes.end()) {
        std::string names;
        for (const auto& [n, _] : flight.nodes) names += (names.empty() ? "" : ", ") + n;
        throw std::invalid_argument("fault '" + to_string(f) + "': this flight has no node '" + f.target + "' (" + names + ")");
      }
      node->second(!on);  // killed while the fault lasts, respawned when it ends
      ++(on ? counters_.kills : counters_.respawns);
      break;
    }
    case Kind::CameraStall: flight.stall_cameras(on); break;
    case Kind::LinkDrop:
      for (auto* d : directions(flight)) d->set_down(on);
      break;
    case Kind::LinkDegrade:  // ends back at the link's configured figures
      for (auto* d : directions(flight)) {
        if (on)
          d->impair(f.delay_ms, f.loss);
        else
          d->restore();
      }
      break;
    case Kind::Burst:  // instantaneous: only started
      burst(link::Side::kAir, f.count, flight.buses->on(link::Side::kAir));
      if (flight.buses->link()) burst(link::Side::kGround, f.count, flight.buses->on(link::Side::kGround));
      break;
    case Kind::NanPose: nan_pose(f.target, flight); break;
  }
}

void Injector::burst(link::Side side, int count, bus::Bus& bus) {
  std::vector<const std::pair<const std::pair<link::Side, std::string>, std::vector<uint8_t>>*> seen;
  for (const auto& e : last_)
    if (e.first.first == side) seen.push_back(&e);
  if (seen.empty()) return;
  static constexpr uint32_t kHostile[] = {0x80000000u, 0x20000001u, 0x7fffffffu, 0xffffffffu, 0x00ffffffu};
  std::uniform_int_distribution<int> byte(0, 255);
  publishing_ = true;
  for (int i = 0; i < count; ++i) {
    const auto& [key, sample] = *seen[static_cast<size_t>(i) % seen.size()];
    std::vector<uint8_t> m = sample;
    switch (i / static_cast<int>(seen.size()) % 4) {
      case 0:
        m.resize(std::uniform_int_distribution<size_t>(0, std::min<size_t>(2 * sample.size() + 8, 65536))(rng_));
        for (auto& b : m) b = static_cast<uint8_t>(byte(rng_));
        break;
      case 1: m.resize(std::uniform_int_distribution<size_t>(0, sample.size() ? sample.size() - 1 : 0)(rng_)); break;
      case 2:
        if (!m.empty())
          for (int k = std::uniform_int_distribution<int>(1, 8)(rng_); k > 0; --k)
            m[std::uniform_int_distribution<size_t>(0, m.size() - 1)(rng_)] ^= static_cast<uint8_t>(1u << (byte(rng_) % 8));
        break;
      default:
        if (m.size() >= 12) {
          const size_t at = 8 + 4 * std::uniform_int_distribution<size_t>(0, (m.size() - 12) / 4)(rng_);
          const uint32_t v = kHostile[std::uniform_int_distribution<size_t>(0, std::size(kHostile) - 1)(rng_)];
          for (int b = 0; b < 4; ++b) m[at + static_cast<size_t>(b)] = static_cast<uint8_t>(v >> (24 - 8 * b));  // big-endian, as LCM
        }
        break;
    }
    bus.publish_raw(key.second, m.data(), static_cast<unsigned>(m.size()));
    ++counters_.burst_messages;
  }
}

// The newest pose on the channel again, its position NaN: a diverged estimator.
void Injector::nan_pose(const std::string& channel, Flight& flight) {
  for (const link::Side side : {link::Side::kAir, link::Side::kGround}) {
    const auto it = last_.find({side, channel});
    if (it == last_.end()) continue;
    std::vector<uint8_t> out;
    const double nan = std::numeric_limits<double>::quiet_NaN();
    auto bump = [&](auto msg) {
      msg.seq += 1;
      for (double& p : msg.position) p = nan;
      out.resize(static_cast<size_t>(msg.getEncodedSize()));
      msg.encode(out.data(), 0, static_cast<int>(out.size()));
    };
    if (channel == "TARGET_POSE")
      bump(bus::decode_bounded<aerie::target_pose_t>(it->second.data(), it->second.size()));
    else if (channel == "VO_POSE")
      bump(bus::decode_bounded<aerie::pose_t>(it->second.data(), it->second.size()));
    else
      throw std::invalid_argument("nan_pose: channel " + channel + " is not TARGET_POSE or VO_POSE");
    publishing_ = true;
    flight.buses->on(side).publish_raw(channel, out.data(), static_cast<unsigned>(out.size()));
    ++counters_.nan_messages;
    return;
  }
  throw std::invalid_argument("nan_pose: nothing was published on " + channel + " before the fault");
}

}  // namespace aerie::loop::faults
