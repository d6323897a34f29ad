#include "tools/link/probe.hpp"

#include <aerie/image_t.hpp>

#include <chrono>
#include <thread>

#include "common/image/image_message.hpp"
#include "common/util/time.hpp"

namespace aerie::link {

Probe::Probe(bus::Bus& source, bus::Bus& sink, std::string channel)
    : source_(source), sink_(sink), channel_(std::move(channel)) {
  sink_.subscribe<aerie::image_t>(channel_, [this](const aerie::image_t& m, const bus::ReceiveInfo& info) {
    const int64_t seq = image::sequence_number(m);
    if (seq < 0) return;
    if (static_cast<size_t>(seq) >= seen_.size()) seen_.resize(static_cast<size_t>(seq) + 1, false);
    if (seen_[static_cast<size_t>(seq)]) {
      ++duplicates_;
      return;
    }
    seen_[static_cast<size_t>(seq)] = true;
    received_.push_back({seq, m.utime, info.recv_utime, info.bytes, image::pixel_format_name(m.pixelformat)});
  }, 100000);
}

void Probe::pump(int ms) {
  using Clock = std::chrono::steady_clock;
  const auto until = Clock::now() + std::chrono::milliseconds(ms);
  while (Clock::now() < until) {
    if (sink_.handle(1) == 0) source_.handle(0);
  }
}

void Probe::run(int n, double rate_hz, size_t payload, int drain_ms) {
  using Clock = std::chrono::steady_clock;
  aerie::image_t m;
  m.width = static_cast<int32_t>(payload);
  m.height = 1;
  m.row_stride = m.width;
  m.pixelformat = aerie::image_t::PIXEL_FORMAT_GRAY;
  m.size = m.width;
  m.data.assign(payload, 0);
  for (size_t i = 0; i < payload; ++i) m.data[i] = static_cast<uint8_t>(i * 31);
  const auto start = Clock::now();
  for (int i = 0; i < n; ++i) {
    if (rate_hz > 0) {
      const auto at = start + std::chrono::microseconds(static_cast<int64_t>(1e6 * i / rate_hz));
      while (Clock::now() < at) {
        // Receive meanwhile; never oversleep the next send.
        if (sink_.handle(0) == 0 && source_.handle(0) == 0) std::this_thread::sleep_for(std::chrono::microseconds(50));
      }
    } else {
      sink_.handle(0);
    }
    m.metadata.clear();
    m.nmetadata = 0;
    image::set_metadata(m, "seq", std::to_string(i));
    m.utime = util::wall_utime();
    source_.publish(channel_, m);
    ++sent_;
  }
  pump(drain_ms);
}

std::vector<double> Probe::delays_ms() const {
  std::vector<double> out;
  out.reserve(received_.size());
  for (const auto& s : received_) out.push_back(static_cast<double>(s.recv_utime - s.sent_utime) / 1000.0);
  return out;
}

std::vector<int64_t> Probe::lost() const {
  std::vector<int64_t> out;
  for (int64_t s = 0; s < sent_; ++s)
    if (static_cast<size_t>(s) >= seen_.size() || !seen_[static_cast<size_t>(s)]) out.push_back(s);
  return out;
}

}  // namespace aerie::link
