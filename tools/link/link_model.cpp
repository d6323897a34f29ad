#include "tools/link/link_model.hpp"

#include <algorithm>
#include <cmath>
#include <stdexcept>

namespace aerie::link {

double GilbertElliott::mean_loss() const {
  const double p = p_good_to_bad, r = p_bad_to_good;
  if (p + r <= 0) return loss_good;  // never leaves Good
  return (r * loss_good + p * loss_bad) / (p + r);
}

void DirectionConfig::validate() const {
  auto bad = [&](const std::string& field, const std::string& why) {
    throw std::invalid_argument("link direction '" + name + "': " + field + " " + why);
  };
  auto probability = [&](const std::string& field, double v) {
    if (!(v >= 0.0 && v <= 1.0)) bad(field, "must be a probability in [0, 1], got " + std::to_string(v));
  };
  if (!(delay_ms >= 0)) bad("delay_ms", "must be >= 0");
  if (!(jitter_ms >= 0)) bad("jitter_ms", "must be >= 0");
  probability("loss", loss);
  probability("gilbert_elliott.p_good_to_bad", gilbert_elliott.p_good_to_bad);
  probability("gilbert_elliott.p_bad_to_good", gilbert_elliott.p_bad_to_good);
  probability("gilbert_elliott.loss_good", gilbert_elliott.loss_good);
  probability("gilbert_elliott.loss_bad", gilbert_elliott.loss_bad);
  if (!(bandwidth_bps >= 0)) bad("bandwidth", "must be >= 0 (0 = unlimited)");
  if (queue_bytes <= 0) bad("queue_bytes", "must be > 0");
  if (jpeg_quality < 1 || jpeg_quality > 100) bad("jpeg.quality", "must be in 1..100");
  if (channels.empty()) bad("channels", "is empty (use \".*\" for every channel)");
}

int64_t wire_bytes(const std::string& channel, size_t payload_size) {
  constexpr size_t kShortMax = 65499;  // LCM's largest unfragmented message (udpm)
  constexpr size_t kFragment = 65423;  // LCM fragment payload
  const size_t body = payload_size + channel.size() + 1;
  if (body <= kShortMax) return static_cast<int64_t>(body + 8 + 28);
  const size_t fragments = (payload_size + kFragment - 1) / kFragment;
  return static_cast<int64_t>(body + fragments * (20 + 28));
}

LinkDirection::LinkDirection(DirectionConfig config) : config_(std::move(config)) {
  config_.validate();
  configured_ = config_;
  std::seed_seq loss_seed{config_.seed, uint64_t{1}}, delay_seed{config_.seed, uint64_t{2}};
  loss_rng_.seed(loss_seed);
  delay_rng_.seed(delay_seed);
}

bool LinkDirection::draw_loss() {
  std::uniform_real_distribution<double> u(0.0, 1.0);
  if (config_.loss_model == LossModel::Bernoulli) return config_.loss > 0 && u(loss_rng_) < config_.loss;
  // Gilbert-Elliott: move the chain, then lose with the state's probability.
  const auto& ge = config_.gilbert_elliott;
  bad_state_ = bad_state_ ? !(u(loss_rng_) < ge.p_bad_to_good) : (u(loss_rng_) < ge.p_good_to_bad);
  return u(loss_rng_) < (bad_state_ ? ge.loss_bad : ge.loss_good);
}

int64_t LinkDirection::draw_delay_us() {
  double d = config_.delay_ms;
  const double j = config_.jitter_ms;
  if (j > 0) {
    switch (config_.jitter) {
      case JitterDistribution::Normal: d += j * std::normal_distribution<double>(0.0, 1.0)(delay_rng_); break;
      case JitterDistribution::Uniform: {
        const double half = j * std::sqrt(3.0);  // standard deviation j
        d += std::uniform_real_distribution<double>(-half, half)(delay_rng_);
        break;
      }
      case JitterDistribution::Exponential: d += std::exponential_distribution<double>(1.0 / j)(delay_rng_); break;
    }
  }
  return static_cast<int64_t>(std::llround(std::max(0.0, d) * 1000.0));
}

void LinkDirection::transmit(int64_t now_us) {
  while (!waiting_.empty()) {
    Packet& p = waiting_.front();
    const int64_t start = std::max(transmitter_free_us_, p.arrival_us);
    if (start > now_us) return;  // the transmitter is still busy
    const int64_t bytes = wire_bytes(p.channel, p.data.size());
    int64_t end = start;
    if (config_.bandwidth_bps > 0)
      end += static_cast<int64_t>(std::llround(static_cast<double>(bytes) * 8.0 * 1e6 / config_.bandwidth_bps));
    transmitter_free_us_ = end;
    Packet sent = std::move(p);
    waiting_.pop_front();
    waiting_bytes_ -= bytes;
    if (down_) {
      ++counters_.dropped_outage;
      continue;
    }
    if (draw_loss()) {
      ++counters_.dropped_loss;
      continue;
    }
    sent.release_us = end + draw_delay_us();
    if (!config_.reorder) sent.release_us = std::max(sent.release_us, last_release_us_);
    last_release_us_ = std::max(last_release_us_, sent.release_us);
    in_flight_.push_back(std::move(sent));
    std::push_heap(in_flight_.begin(), in_flight_.end(), Later{});
  }
}

void LinkDirection::offer(Packet packet, int64_t now_us) {
  transmit(now_us);
  ++counters_.received;
  packet.arrival_us = now_us;
  packet.serial = next_serial_++;
  const int64_t bytes = wire_bytes(packet.channel, packet.data.size());
  if (bytes > config_.queue_bytes) {
    ++counters_.dropped_other;  // could never fit
    return;
  }
  if (waiting_bytes_ + bytes > config_.queue_bytes) {
    if (config_.queue_policy == QueuePolicy::DropNewest) {
      ++counters_.dropped_queue;
      return;
    }
    while (!waiting_.empty() && waiting_bytes_ + bytes > config_.queue_bytes) {
      waiting_bytes_ -= wire_bytes(waiting_.front().channel, waiting_.front().data.size());
      waiting_.pop_front();
      ++counters_.dropped_queue;
    }
  }
  waiting_bytes_ += bytes;
  waiting_.push_back(std::move(packet));
  transmit(now_us);
}

void LinkDirection::set_down(bool down) {
  down_ = down;
  if (!down_) return;
  counters_.dropped_outage += static_cast<int64_t>(in_flight_.size());
  in_flight_.clear();
}

void LinkDirection::impair(double delay_ms, double loss) {
  DirectionConfig c = config_;
  c.delay_ms = delay_ms;
  c.loss_model = LossModel::Bernoulli;
  c.loss = loss;
  c.validate();
  config_ = c;
}

std::vector<Packet> LinkDirection::due(int64_t now_us) {
  transmit(now_us);
  std::vector<Packet> out;
  while (!in_flight_.empty() && in_flight_.front().release_us <= now_us) {
    std::pop_heap(in_flight_.begin(), in_flight_.end(), Later{});
    out.push_back(std::move(in_flight_.back()));
    in_flight_.pop_back();
    ++counters_.delivered;
    counters_.bytes_delivered += wire_bytes(out.back().channel, out.back().data.size());
  }
  return out;
}

int64_t LinkDirection::next_event_us() const {
  int64_t t = -1;
  if (!in_flight_.empty()) t = in_flight_.front().release_us;
  if (!waiting_.empty()) {
    const int64_t start = std::max(transmitter_free_us_, waiting_.front().arrival_us);
    t = t < 0 ? start : std::min(t, start);
  }
  return t;
}

const char* to_string(JitterDistribution d) {
  switch (d) {
    case JitterDistribution::Uniform: return "uniform";
    case JitterDistribution::Exponential: return "exponential";
    default: return "normal";
  }
}

JitterDistribution jitter_from_string(const std::string& s) {
  if (s == "normal") return JitterDistribution::Normal;
  if (s == "uniform") return JitterDistribution::Uniform;
  if (s == "exponential") return JitterDistribution::Exponential;
  throw std::invalid_argument("jitter_distribution must be normal, uniform or exponential, got '" + s + "'");
}

QueuePolicy queue_policy_from_string(const std::string& s) {
  if (s == "drop_oldest") return QueuePolicy::DropOldest;
  if (s == "drop_newest") return QueuePolicy::DropNewest;
  throw std::invalid_argument("queue_policy must be drop_oldest or drop_newest, got '" + s + "'");
}

LossModel loss_model_from_string(const std::string& s) {
  if (s == "bernoulli") return LossModel::Bernoulli;
  if (s == "gilbert_elliott") return LossModel::GilbertElliott;
  throw std::invalid_argument("loss.model must be bernoulli or gilbert_elliott, got '" + s + "'");
}

}  // namespace aerie::link
