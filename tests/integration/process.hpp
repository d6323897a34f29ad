#pragma once
// Child processes and network namespaces for the end-to-end tests.
#include <fcntl.h>
#include <signal.h>
#include <sys/wait.h>
#include <unistd.h>

#include <chrono>
#include <cstdlib>
#include <filesystem>
#include <optional>
#include <stdexcept>
#include <string>
#include <thread>
#include <vector>

namespace aerie::test {

// A child process with stdout+stderr to a file; killed (SIGKILL) if still running
// when destroyed, so that a failing test leaves nothing behind.
class Process {
 public:
  Process(const std::vector<std::string>& argv, const std::filesystem::path& output) {
    pid_ = fork();
    if (pid_ < 0) throw std::runtime_error("fork failed");
    if (pid_ == 0) {
      const int fd = open(output.c_str(), O_WRONLY | O_CREAT | O_TRUNC, 0644);
      if (fd >= 0) {
        dup2(fd, 1);
        dup2(fd, 2);
      }
      std::vector<char*> args;
      for (const auto& a : argv) args.push_back(const_cast<char*>(a.c_str()));
      args.push_back(nullptr);
      execvp(args[0], args.data());
      _exit(127);
    }
  }
  Process(const Process&) = delete;
  Process& operator=(const Process&) = delete;
  ~Process() {
    if (running()) {
      kill(pid_, SIGKILL);
      waitpid(pid_, nullptr, 0);
    }
  }
  void signal(int sig) const {
    if (running()) kill(pid_, sig);
  }
  // Exit status, or nullopt if it did not end within timeout_s (then it is killed).
  std::optional<int> wait(double timeout_s) {
    const auto end = std::chrono::steady_clock::now() + std::chrono::duration<double>(timeout_s);
    while (std::chrono::steady_clock::now() < end) {
      int status = 0;
      const pid_t r = waitpid(pid_, &status, WNOHANG);
      if (r == pid_) {
        done_ = true;
        return WIFEXITED(status) ? WEXITSTATUS(status) : 128 + WTERMSIG(status);
      }
      std::this_thread::sleep_for(std::chrono::milliseconds(20));
    }
    return std::nullopt;
  }
  bool running() const { return !done_ && pid_ > 0; }

 private:
  pid_t pid_ = -1;
  bool done_ = false;
};

inline int run_quiet(const std::string& cmd) { return std::system((cmd + " >/dev/null 2>&1").c_str()); }

// A network namespace with loopback up and a multicast route on it; deleted on
// destruction (also when the test fails).
class NetNamespace {
 public:
  explicit NetNamespace(const std::string& name) : name_(name) {
    run_quiet("ip netns del " + name_);
    if (run_quiet("ip netns add " + name_) != 0) throw std::runtime_error("ip netns add " + name_ + " failed");
    created_ = true;
    if (run_quiet("ip netns exec " + name_ + " ip link set lo up") != 0 ||
        run_quiet("ip netns exec " + name_ + " ip route add 224.0.0.0/4 dev lo") != 0)
      throw std::runtime_error("cannot set up loopback multicast in namespace " + name_);
  }
  NetNamespace(const NetNamespace&) = delete;
  NetNamespace& operator=(const NetNamespace&) = delete;
  ~NetNamespace() {
    if (created_) run_quiet("ip netns del " + name_);
  }
  // argv prefixed to run inside the namespace.
  std::vector<std::string> exec(std::vector<std::string> argv) const {
    argv.insert(argv.begin(), {"ip", "netns", "exec", name_});
    return argv;
  }
  const std::string& name() const { return name_; }

  // Why namespaces cannot be used here, or "" when they can.
  static std::string unavailable() {
    if (geteuid() != 0) return "network namespaces need root (ip netns add); run the tests as root";
    if (run_quiet("command -v ip") != 0) return "the 'ip' tool (iproute2) is not installed";
    return "";
  }

 private:
  std::string name_;
  bool created_ = false;
};

}  // namespace aerie::test
