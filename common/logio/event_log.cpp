#include "common/logio/event_log.hpp"

#include <algorithm>
#include <array>
#include <cctype>
#include <cstdio>
#include <filesystem>
#include <stdexcept>

namespace aerie::logio {
namespace {

uint32_t get_u32(const uint8_t* p) {
  return (uint32_t{p[0]} << 24) | (uint32_t{p[1]} << 16) | (uint32_t{p[2]} << 8) | uint32_t{p[3]};
}
uint64_t get_u64(const uint8_t* p) { return (uint64_t{get_u32(p)} << 32) | get_u32(p + 4); }
void put_u32(uint8_t* p, uint32_t v) {
  for (int i = 3; i >= 0; --i, v >>= 8) p[i] = static_cast<uint8_t>(v & 0xff);
}
void put_u64(uint8_t* p, uint64_t v) {
  put_u32(p, static_cast<uint32_t>(v >> 32));
  put_u32(p + 4, static_cast<uint32_t>(v));
}
// LCM's event counter is a u64 on disk: the number after INT64_MAX (read as int64) wraps to
// INT64_MIN rather than overflowing.
int64_t next_event_number(int64_t n) { return static_cast<int64_t>(static_cast<uint64_t>(n) + 1); }
std::string hex32(uint32_t v) {
  char buf[16];
  std::snprintf(buf, sizeof buf, "0x%08X", v);
  return buf;
}

}  // namespace

std::string to_string(Damage::Kind k) {
  switch (k) {
    case Damage::Kind::Truncated: return "truncated";
    case Damage::Kind::BadSync: return "bad sync word";
    case Damage::Kind::BadHeader: return "bad event header";
  }
  return "?";
}

Reader::Reader(const std::string& path, Options options) : path_(path), options_(options) {
  std::error_code ec;
  if (!std::filesystem::is_regular_file(path, ec)) throw std::runtime_error(path + ": no such log file");
  in_.open(path, std::ios::binary);
  if (!in_) throw std::runtime_error(path + ": cannot open log file");
  size_ = std::filesystem::file_size(path);
}

// Reads and validates the header at `at`. Truncated: the file ends inside the event.
Reader::HeaderCheck Reader::read_header(uint64_t at, Event& ev, uint32_t& channel_len, uint32_t& data_len,
                                        std::string& why) {
  const uint64_t remain = size_ - at;
  std::array<uint8_t, kHeaderSize> h{};
  const size_t n = static_cast<size_t>(std::min<uint64_t>(remain, kHeaderSize));
  in_.clear();
  in_.seekg(static_cast<std::streamoff>(at));
  in_.read(reinterpret_cast<char*>(h.data()), static_cast<std::streamsize>(n));
  if (n >= 4 && get_u32(h.data()) != kSyncWord) {
    why = "sync word " + hex32(get_u32(h.data())) + ", expected " + hex32(kSyncWord);
    return HeaderCheck::BadSync;
  }
  if (n < kHeaderSize) {
    why = "the file ends inside the 28-byte event header (" + std::to_string(remain) + " bytes left)";
    return HeaderCheck::Truncated;
  }
  ev.event_number = static_cast<int64_t>(get_u64(h.data() + 4));
  ev.utime = static_cast<int64_t>(get_u64(h.data() + 12));
  channel_len = get_u32(h.data() + 20);
  data_len = get_u32(h.data() + 24);
  if (channel_len == 0 || channel_len > kMaxChannelLength) {
    why = "channel length " + std::to_string(channel_len) + " outside 1.." + std::to_string(kMaxChannelLength);
    return HeaderCheck::BadHeader;
  }
  if (data_len > kMaxDataLength) {
    why = "data length " + std::to_string(data_len) + " above the 256 MB limit";
    return HeaderCheck::BadHeader;
  }
  const uint64_t need = kHeaderSize + uint64_t{channel_len} + data_len;
  if (need > remain) {
    why = "event needs " + std::to_string(need) + " bytes (channel " + std::to_string(channel_len) + ", data " +
          std::to_string(data_len) + ") but only " + std::to_string(remain) + " remain";
    return HeaderCheck::Truncated;
  }
  ev.channel.resize(channel_len);
  in_.read(ev.channel.data(), channel_len);
  // LCM channel names are printable ASCII; anything else is a corrupt header.
  if (!std::all_of(ev.channel.begin(), ev.channel.end(), [](unsigned char c) { return std::isprint(c); })) {
    why = "channel name is not printable text";
    return HeaderCheck::BadHeader;
  }
  return HeaderCheck::Ok;
}

void Reader::report(Damage::Kind kind, uint64_t at, const std::string& what) {
  Damage d{kind, at, expected_event_, 0, ""};
  d.message = path_ + ": " + to_string(kind) + " at byte " + std::to_string(at) + " (event " +
              std::to_string(expected_event_) + "): " + what;
  damage_.push_back(std::move(d));
}

// Scans from `from` for the next sync word followed by a plausible header. On success
// moves offset_ there and notes the skipped bytes in `d`.
bool Reader::resync_from(uint64_t from, Damage& d) {
  constexpr size_t kChunk = 1 << 16;
  std::vector<uint8_t> buf(kChunk + 3);
  for (uint64_t pos = from; pos + 4 <= size_;) {
    const size_t n = static_cast<size_t>(std::min<uint64_t>(size_ - pos, buf.size()));
    in_.clear();
    in_.seekg(static_cast<std::streamoff>(pos));
    in_.read(reinterpret_cast<char*>(buf.data()), static_cast<std::streamsize>(n));
    for (size_t i = 0; i + 4 <= n; ++i) {
      if (get_u32(buf.data() + i) != kSyncWord) continue;
      Event probe;
      uint32_t cl = 0, dl = 0;
      std::string why;
      if (read_header(pos + i, probe, cl, dl, why) == HeaderCheck::Ok) {
        d.skipped = pos + i - d.offset;
        d.message += "; skipped " + std::to_string(d.skipped) + " bytes to the next event at byte " +
                     std::to_string(pos + i);
        offset_ = pos + i;
        return true;
      }
    }
    if (n < buf.size()) break;
    pos += n - 3;  // overlap so that a sync word across the chunk border is found
  }
  d.message += "; no further event found";
  return false;
}

bool Reader::next(Event& ev) {
  while (!done_) {
    if (offset_ >= size_) {
      done_ = true;
      break;
    }
    uint32_t cl = 0, dl = 0;
    std::string why;
    const auto check = read_header(offset_, ev, cl, dl, why);
    if (check == HeaderCheck::Ok) {
      ev.data.resize(dl);
      in_.read(reinterpret_cast<char*>(ev.data.data()), dl);
      if (!in_) throw std::runtime_error(path_ + ": read error at byte " + std::to_string(offset_));
      ev.offset = offset_;
      offset_ += kHeaderSize + cl + dl;
      expected_event_ = next_event_number(ev.event_number);
      return true;
    }
    const auto kind = check == HeaderCheck::Truncated ? Damage::Kind::Truncated
                      : check == HeaderCheck::BadSync ? Damage::Kind::BadSync
                                                      : Damage::Kind::BadHeader;
    report(kind, offset_, why);
    if (!options_.resync || !resync_from(offset_ + 1, damage_.back())) done_ = true;
  }
  return false;
}

ReadResult read_all(const std::string& path, Reader::Options options) {
  Reader r(path, options);
  ReadResult out;
  Event ev;
  while (r.next(ev)) out.events.push_back(std::move(ev));
  out.damage = r.damage();
  return out;
}

Writer::Writer(const std::string& path) : path_(path), out_(path, std::ios::binary | std::ios::trunc) {
  if (!out_) throw std::runtime_error(path + ": cannot create log file");
}

void Writer::write(int64_t utime, const std::string& channel, const void* data, size_t size) {
  if (channel.empty() || channel.size() > kMaxChannelLength)
    throw std::invalid_argument(path_ + ": channel name '" + channel + "' must have 1.." +
                                std::to_string(kMaxChannelLength) + " characters");
  if (size > kMaxDataLength) throw std::invalid_argument(path_ + ": payload on " + channel + " above 256 MB");
  std::array<uint8_t, kHeaderSize> h{};
  put_u32(h.data(), kSyncWord);
  put_u64(h.data() + 4, static_cast<uint64_t>(next_number_));
  put_u64(h.data() + 12, static_cast<uint64_t>(utime));
  put_u32(h.data() + 20, static_cast<uint32_t>(channel.size()));
  put_u32(h.data() + 24, static_cast<uint32_t>(size));
  out_.write(reinterpret_cast<const char*>(h.data()), kHeaderSize);
  out_.write(channel.data(), static_cast<std::streamsize>(channel.size()));
  out_.write(static_cast<const char*>(data), static_cast<std::streamsize>(size));
  if (!out_) throw std::runtime_error(path_ + ": write failed (disk full?)");
  next_number_ = next_event_number(next_number_);
}

void Writer::write(const Event& ev, bool keep_numbers) {
  if (keep_numbers) next_number_ = ev.event_number;
  write(ev.utime, ev.channel, ev.data.data(), ev.data.size());
}

void Writer::flush() {
  out_.flush();
  if (!out_) throw std::runtime_error(path_ + ": write failed (disk full?)");
}

void Writer::close() {
  if (out_.is_open()) {
    flush();
    out_.close();
  }
}

}  // namespace aerie::logio
