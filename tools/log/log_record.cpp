#include "tools/log/log_record.hpp"

#include <filesystem>
#include <stdexcept>

namespace aerie::logtools {

namespace {

// Checked before the writer truncates anything.
const RecordOptions& checked(const RecordOptions& o) {
  if (o.queue < 0) throw std::invalid_argument("record: --queue must be >= 0 (0 = no limit), got " + std::to_string(o.queue));
  if (!(o.flush_period_s >= 0)) throw std::invalid_argument("record: the flush period must be >= 0 s");
  std::error_code ec;
  if (!o.force && std::filesystem::exists(std::filesystem::symlink_status(o.path, ec)))
    throw std::invalid_argument("record: " + o.path + " exists; pass --force to overwrite it");
  return o;
}

}  // namespace

Recorder::Recorder(bus::Bus& bus, RecordOptions options) : opt_(checked(options)), writer_(opt_.path) {
  bus.subscribe_raw(
      opt_.channels,
      [this](const uint8_t* data, size_t size, const bus::ReceiveInfo& info) {
        writer_.write(info.recv_utime, info.channel, data, size);  // lcm-logger's event time: the receive time
        bytes_ += static_cast<int64_t>(size);
      },
      opt_.queue);
}

void Recorder::tick(int64_t now_us) {
  if (now_us - last_flush_us_ < static_cast<int64_t>(opt_.flush_period_s * 1e6)) return;
  writer_.flush();
  last_flush_us_ = now_us;
}

void Recorder::close() { writer_.close(); }

}  // namespace aerie::logtools
