#include "procman/proc_stats.hpp"

#include <dirent.h>
#include <fcntl.h>
#include <unistd.h>

#include <algorithm>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <fstream>
#include <map>
#include <sstream>
#include <string>

namespace aerie::procman {

std::optional<ProcessSample> read_process(pid_t pid) {
  // Plain open/read: this runs for every process on every scan.
  char path[64];
  std::snprintf(path, sizeof path, "/proc/%d/stat", static_cast<int>(pid));
  const int fd = open(path, O_RDONLY | O_CLOEXEC);
  if (fd < 0) return std::nullopt;
  char buf[1024];
  const ssize_t n = read(fd, buf, sizeof buf - 1);
  close(fd);
  if (n <= 0) return std::nullopt;
  buf[n] = '\0';
  // The command name (field 2) is in parentheses and may contain spaces: parse after the last ')'.
  const char* p = std::strrchr(buf, ')');
  if (!p || p[1] != ' ') return std::nullopt;
  p += 2;
  while (*p && *p != ' ') ++p;  // field 3, the state
  long long f[21] = {0};        // fields 4..24 (ppid .. rss), see proc(5)
  for (long long& x : f) {
    char* end = nullptr;
    x = std::strtoll(p, &end, 10);
    if (end == p) return std::nullopt;
    p = end;
  }
  static const long page = sysconf(_SC_PAGESIZE);
  ProcessSample s;
  s.pid = pid;
  s.ppid = static_cast<pid_t>(f[0]);        // 4
  s.pgrp = static_cast<pid_t>(f[1]);        // 5
  s.session = static_cast<pid_t>(f[2]);     // 6
  s.cpu_jiffies = static_cast<uint64_t>(f[10] + f[11]);  // 14 utime, 15 stime
  s.vsize_bytes = f[19];                    // 23
  s.rss_bytes = f[20] * page;               // 24 (pages)
  return s;
}

std::vector<ProcessSample> read_all_processes() {
  std::vector<ProcessSample> out;
  DIR* d = opendir("/proc");
  if (!d) return out;
  while (const dirent* e = readdir(d)) {
    char* end = nullptr;
    const long pid = std::strtol(e->d_name, &end, 10);
    if (*end != '\0' || pid <= 0) continue;
    if (auto s = read_process(static_cast<pid_t>(pid))) out.push_back(*s);
  }
  closedir(d);
  return out;
}

HostSample read_host() {
  HostSample h;
  {
    std::ifstream in("/proc/stat");
    std::string cpu;
    uint64_t v[10] = {0};  // user nice system idle iowait irq softirq steal guest guest_nice
    in >> cpu;
    for (auto& x : v) in >> x;
    if (in && cpu == "cpu") {
      // guest time is already counted in user/nice.
      h.total_jiffies = v[0] + v[1] + v[2] + v[3] + v[4] + v[5] + v[6] + v[7];
      h.busy_jiffies = h.total_jiffies - v[3] - v[4];
    }
  }
  std::ifstream in("/proc/meminfo");
  std::string key;
  int64_t kb = 0;
  std::string unit;
  std::string line;
  while (std::getline(in, line)) {
    std::istringstream ss(line);
    if (!(ss >> key >> kb)) continue;
    const int64_t bytes = kb * 1024;
    if (key == "MemTotal:") h.mem_total_bytes = bytes;
    else if (key == "MemAvailable:") h.mem_available_bytes = bytes;
    else if (key == "SwapTotal:") h.swap_total_bytes = bytes;
    else if (key == "SwapFree:") h.swap_free_bytes = bytes;
  }
  return h;
}

std::vector<pid_t> command_processes(pid_t leader, const std::vector<ProcessSample>& all) {
  std::multimap<pid_t, pid_t> children;
  for (const auto& p : all) children.emplace(p.ppid, p.pid);
  std::vector<pid_t> out;
  auto add = [&](pid_t p) {
    if (p != getpid() && std::find(out.begin(), out.end(), p) == out.end()) out.push_back(p);
  };
  for (const auto& p : all)
    if (p.session == leader || p.pid == leader) add(p.pid);
  // Descendants by parent links (breadth first).
  std::vector<pid_t> frontier{leader};
  while (!frontier.empty()) {
    const pid_t p = frontier.back();
    frontier.pop_back();
    auto [b, e] = children.equal_range(p);
    for (auto it = b; it != e; ++it) {
      add(it->second);
      frontier.push_back(it->second);
    }
  }
  return out;
}

}  // namespace aerie::procman
