#pragma once
// CPU and memory figures from /proc (Linux), for the deputy's reports.
#include <sys/types.h>

#include <cstdint>
#include <optional>
#include <vector>

namespace aerie::procman {

// One process from /proc/<pid>/stat.
struct ProcessSample {
  pid_t pid = 0;
  pid_t ppid = 0;
  pid_t pgrp = 0;
  pid_t session = 0;
  uint64_t cpu_jiffies = 0;   // utime + stime
  int64_t vsize_bytes = 0;
  int64_t rss_bytes = 0;
};

// Whole-host figures from /proc/stat and /proc/meminfo.
struct HostSample {
  uint64_t total_jiffies = 0;  // all CPUs, all states
  uint64_t busy_jiffies = 0;   // total minus idle and iowait
  int64_t mem_total_bytes = 0;
  int64_t mem_available_bytes = 0;  // MemAvailable: what new processes can use
  int64_t swap_total_bytes = 0;
  int64_t swap_free_bytes = 0;
};

std::optional<ProcessSample> read_process(pid_t pid);
// Every process visible in /proc (those that vanish while reading are skipped).
std::vector<ProcessSample> read_all_processes();
HostSample read_host();

// Processes to signal when stopping a command whose leader is `leader`: members of
// its session (the deputy makes each command a session leader) and all descendants
// by parent links (even those that left the session). Excludes the caller.
std::vector<pid_t> command_processes(pid_t leader, const std::vector<ProcessSample>& all);

}  // namespace aerie::procman
