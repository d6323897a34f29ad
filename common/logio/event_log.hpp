#pragma once
// Reader and writer of the standard LCM event-log format (the files lcm-logger
// writes and lcm-logplayer reads). Each event is a 28-byte big-endian header
//   uint32 sync (0xEDA1DA01), int64 event number, int64 utime (µs),
//   uint32 channel length, uint32 data length
// followed by the channel name and the payload. The reader never gives up silently:
// a truncated or corrupt log is reported with the byte offset and the event number
// where the damage starts, every event before it is still returned, and on request
// it resynchronises on the next sync word and reads on.
#include <cstdint>
#include <fstream>
#include <optional>
#include <string>
#include <vector>

namespace aerie::logio {

inline constexpr uint32_t kSyncWord = 0xEDA1DA01;
inline constexpr size_t kHeaderSize = 28;
// Limits LCM itself enforces when reading logs: longer names or payloads mean corruption.
inline constexpr uint32_t kMaxChannelLength = 1000;
inline constexpr uint32_t kMaxDataLength = 256u * 1024 * 1024;

struct Event {
  int64_t event_number = 0;
  int64_t utime = 0;  // when the logger received it (µs)
  std::string channel;
  std::vector<uint8_t> data;
  uint64_t offset = 0;  // byte offset of the event header in the file (reader only)
};

// Where and how a log is damaged. `event_number` is the number the damaged event
// should have had: one past the last good event (0 when none was read).
struct Damage {
  enum class Kind { Truncated, BadSync, BadHeader };
  Kind kind;
  uint64_t offset;       // byte offset where the damaged event starts
  int64_t event_number;  // expected number of the damaged event
  uint64_t skipped = 0;  // bytes skipped to the next sync word (when resynchronising)
  std::string message;   // names the file, offset and event
};
std::string to_string(Damage::Kind k);

class Reader {
 public:
  struct Options {
    // Skip damaged bytes up to the next plausible event header instead of stopping.
    bool resync = false;
  };
  // Throws std::runtime_error naming the file if it cannot be opened.
  explicit Reader(const std::string& path, Options options);
  explicit Reader(const std::string& path) : Reader(path, Options{}) {}

  // Reads the next event; false at the end of the file or at damage (without resync).
  bool next(Event& ev);

  const std::vector<Damage>& damage() const { return damage_; }
  bool damaged() const { return !damage_.empty(); }
  uint64_t file_size() const { return size_; }
  uint64_t offset() const { return offset_; }
  const std::string& path() const { return path_; }

 private:
  enum class HeaderCheck { Ok, Truncated, BadSync, BadHeader };
  HeaderCheck read_header(uint64_t at, Event& ev, uint32_t& channel_len, uint32_t& data_len, std::string& why);
  bool resync_from(uint64_t from, Damage& d);
  void report(Damage::Kind kind, uint64_t at, const std::string& what);

  std::string path_;
  Options options_;
  std::ifstream in_;
  uint64_t size_ = 0;
  uint64_t offset_ = 0;
  int64_t expected_event_ = 0;
  bool done_ = false;
  std::vector<Damage> damage_;
};

// Reads a whole log into memory (convenient for small logs and tests).
struct ReadResult {
  std::vector<Event> events;
  std::vector<Damage> damage;
};
ReadResult read_all(const std::string& path, Reader::Options options = {});

class Writer {
 public:
  // Creates (truncates) the file; throws std::runtime_error naming it on failure.
  explicit Writer(const std::string& path);
  // Appends an event; the event number is taken from `ev` when `keep_numbers`,
  // otherwise numbered 0, 1, 2, ... as lcm-logger does.
  void write(const Event& ev, bool keep_numbers = false);
  void write(int64_t utime, const std::string& channel, const void* data, size_t size);
  void flush();
  void close();
  int64_t events_written() const { return next_number_; }
  const std::string& path() const { return path_; }

 private:
  std::string path_;
  std::ofstream out_;
  int64_t next_number_ = 0;
};

}  // namespace aerie::logio
