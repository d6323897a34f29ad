#include "fuzz/fuzz_support.hpp"

#include <spdlog/spdlog.h>
#include <unistd.h>

#include <cstdlib>
#include <filesystem>
#include <fstream>

namespace aerie::fuzz {

void quiet() {
  static const bool done = [] {
    spdlog::set_level(spdlog::level::off);
    return true;
  }();
  (void)done;
}

namespace {

std::filesystem::path make_temp_dir() {
  std::string pattern = (std::filesystem::temp_directory_path() / "aerie-fuzz-XXXXXX").string();
  if (!mkdtemp(pattern.data())) throw std::logic_error("fuzz: cannot create a temporary folder");
  return pattern;
}

const std::filesystem::path& temp_dir() {
  static const std::filesystem::path dir = make_temp_dir();
  static const int cleanup = std::atexit([] {
    std::error_code ignored;
    std::filesystem::remove_all(temp_dir(), ignored);
  });
  (void)cleanup;
  return dir;
}

}  // namespace

std::string temp_file(const std::string& name, const uint8_t* data, size_t size) {
  const std::string path = (temp_dir() / name).string();
  std::ofstream out(path, std::ios::binary | std::ios::trunc);
  out.write(reinterpret_cast<const char*>(data), static_cast<std::streamsize>(size));
  if (!out) throw std::logic_error("fuzz: cannot write " + path);
  return path;
}

std::string empty_temp_folder(const std::string& name) {
  const std::filesystem::path dir = temp_dir() / name;
  std::filesystem::remove_all(dir);
  std::filesystem::create_directories(dir);
  return dir.string();
}

std::string source_path(const std::string& relative) { return std::string(AERIE_SOURCE_DIR) + "/" + relative; }

std::vector<Record> split_records(const uint8_t* data, size_t size, size_t channels) {
  std::vector<Record> records;
  size_t at = 0;
  while (at + 4 <= size) {
    const size_t channel = data[at] % channels;
    const size_t declared = size_t{data[at + 1]} << 16 | size_t{data[at + 2]} << 8 | data[at + 3];
    at += 4;
    const size_t n = std::min(declared, size - at);
    records.push_back({channel, {data + at, n}});
    at += n;
  }
  return records;
}

void append_record(std::vector<uint8_t>& out, uint8_t channel, std::span<const uint8_t> payload) {
  if (payload.size() > 0xFFFFFF) throw std::invalid_argument("fuzz: a record holds at most 16 MiB");
  out.push_back(channel);
  out.push_back(static_cast<uint8_t>(payload.size() >> 16));
  out.push_back(static_cast<uint8_t>((payload.size() >> 8) & 0xFF));
  out.push_back(static_cast<uint8_t>(payload.size() & 0xFF));
  out.insert(out.end(), payload.begin(), payload.end());
}

void publish_records(bus::Bus& bus, const std::vector<std::string>& channels, const uint8_t* data, size_t size,
                     const std::function<void()>& after_each) {
  for (const Record& r : split_records(data, size, channels.size())) {
    bus.publish_raw(channels[r.channel], r.payload.data(), static_cast<unsigned>(r.payload.size()));
    while (bus.handle(0) > 0) {
    }
    if (after_each) after_each();
  }
}

}  // namespace aerie::fuzz
