#pragma once
// A test bed for multi-host runs on one machine: network namespaces standing for
// hosts (multicast on their own loopback), veth pairs joining them, and child
// processes run inside them. Used by the procman/link/split tests and benchmarks.
// Needs root (CAP_SYS_ADMIN + CAP_NET_ADMIN) and iproute2; nothing here sends
// traffic outside the namespaces it creates.
#include <sys/types.h>

#include <chrono>
#include <optional>
#include <string>
#include <vector>

namespace aerie::procman::testbed {

// Empty when namespaces can be created here; otherwise why not (for GTEST_SKIP).
std::string namespaces_unavailable();

// Runs a command to completion; throws std::runtime_error with its output when it fails.
std::string run(const std::vector<std::string>& argv);

// "aerie-test-<pid>-<role>" (unique per test process). Namespaces of that form whose
// process is gone (a crashed or killed test) are removed by remove_stale_namespaces(),
// which every NetNamespace constructor calls.
std::string unique_name(const std::string& role);
void remove_stale_namespaces();

// `ip netns add NAME`, loopback up, multicast routed to loopback. Removed (with
// everything still running in it killed) on destruction.
class NetNamespace {
 public:
  explicit NetNamespace(std::string name);
  ~NetNamespace();
  NetNamespace(const NetNamespace&) = delete;
  NetNamespace& operator=(const NetNamespace&) = delete;
  const std::string& name() const { return name_; }
  // argv prefix that runs a command inside: {"ip", "netns", "exec", name}.
  std::vector<std::string> exec_prefix() const;

 private:
  std::string name_;
};

// A veth pair between two namespaces with addresses 10.<subnet>.0.1/24 (a) and
// 10.<subnet>.0.2/24 (b); multicast is routed over it in both (instead of loopback),
// so LCM with ttl=1 reaches the other namespace.
void join_with_veth(const NetNamespace& a, const NetNamespace& b, int subnet = 213);

// Moves the calling thread into a namespace for its lifetime (sockets created
// meanwhile belong to it), then back.
class EnterNamespace {
 public:
  explicit EnterNamespace(const NetNamespace& ns);
  ~EnterNamespace();
  EnterNamespace(const EnterNamespace&) = delete;
  EnterNamespace& operator=(const EnterNamespace&) = delete;

 private:
  int original_ = -1;
};

// Runs the calling thread under SCHED_FIFO for its lifetime (threads it creates
// meanwhile inherit it), so that timing measurements on a loaded machine do not
// measure the scheduler. No effect (and ok() false) without the privilege.
class RealtimePriority {
 public:
  explicit RealtimePriority(int priority = 10);
  ~RealtimePriority();
  RealtimePriority(const RealtimePriority&) = delete;
  RealtimePriority& operator=(const RealtimePriority&) = delete;
  bool ok() const { return ok_; }

 private:
  bool ok_ = false;
  int old_policy_ = 0;
  int old_priority_ = 0;
};

// A child process with stdout+stderr to a file; SIGTERM (then SIGKILL) on destruction.
class Process {
 public:
  Process(const std::vector<std::string>& argv, const std::string& log_path);
  ~Process();
  Process(const Process&) = delete;
  Process& operator=(const Process&) = delete;
  pid_t pid() const { return pid_; }
  bool running();
  // Waits for the exit; the exit status (WEXITSTATUS, or 128+signal), nullopt on timeout.
  std::optional<int> wait(std::chrono::milliseconds timeout);
  // Sends sig and waits up to grace; SIGKILL after. Returns the exit status.
  int stop(int sig = 15, std::chrono::milliseconds grace = std::chrono::milliseconds(5000));
  const std::string& log_path() const { return log_; }
  std::string log() const;

 private:
  pid_t pid_ = -1;
  std::optional<int> status_;
  std::string log_;
};

}  // namespace aerie::procman::testbed
