#include "procman/testbed.hpp"

#include <dirent.h>
#include <fcntl.h>
#include <sched.h>
#include <signal.h>
#include <sys/prctl.h>
#include <sys/wait.h>
#include <unistd.h>

#include <cerrno>
#include <cstring>
#include <fstream>
#include <sstream>
#include <stdexcept>
#include <thread>

namespace aerie::procman::testbed {
namespace {

std::vector<char*> c_argv(std::vector<std::string>& args) {
  std::vector<char*> out;
  for (auto& a : args) out.push_back(a.data());
  out.push_back(nullptr);
  return out;
}

std::string joined(const std::vector<std::string>& argv) {
  std::string s;
  for (const auto& a : argv) s += (s.empty() ? "" : " ") + a;
  return s;
}

int exit_code(int status) { return WIFEXITED(status) ? WEXITSTATUS(status) : 128 + WTERMSIG(status); }

}  // namespace

std::string run(const std::vector<std::string>& argv) {
  int fds[2];
  if (pipe2(fds, O_CLOEXEC) != 0) throw std::runtime_error("pipe2 failed");
  std::vector<std::string> args = argv;
  auto cargs = c_argv(args);
  const pid_t pid = fork();
  if (pid == 0) {
    dup2(fds[1], 1);
    dup2(fds[1], 2);
    execvp(cargs[0], cargs.data());
    _exit(127);
  }
  close(fds[1]);
  std::string out;
  char buf[4096];
  ssize_t n;
  while ((n = read(fds[0], buf, sizeof buf)) > 0) out.append(buf, static_cast<size_t>(n));
  close(fds[0]);
  int status = 0;
  waitpid(pid, &status, 0);
  if (exit_code(status) != 0)
    throw std::runtime_error("'" + joined(argv) + "' failed (exit " + std::to_string(exit_code(status)) + "): " + out);
  return out;
}

std::string namespaces_unavailable() {
  if (geteuid() != 0) return "network namespaces need root (run the test as root)";
  try {
    run({"ip", "netns", "list"});
  } catch (const std::exception& e) {
    return std::string("iproute2 'ip netns' does not work here: ") + e.what();
  }
  return "";
}

std::string unique_name(const std::string& role) { return "aerie-test-" + std::to_string(getpid()) + "-" + role; }

void remove_stale_namespaces() {
  DIR* d = opendir("/var/run/netns");
  if (!d) return;
  std::vector<std::string> stale;
  while (const dirent* e = readdir(d)) {
    const std::string n = e->d_name;
    const std::string prefix = "aerie-test-";
    if (n.rfind(prefix, 0) != 0) continue;
    const pid_t owner = static_cast<pid_t>(std::atol(n.c_str() + prefix.size()));
    if (owner > 0 && kill(owner, 0) != 0 && errno == ESRCH) stale.push_back(n);
  }
  closedir(d);
  for (const auto& n : stale) {
    try {
      run({"ip", "netns", "del", n});
    } catch (...) {
    }
  }
}

NetNamespace::NetNamespace(std::string name) : name_(std::move(name)) {
  remove_stale_namespaces();
  run({"ip", "netns", "add", name_});
  try {
    run({"ip", "-n", name_, "link", "set", "lo", "up"});
    run({"ip", "-n", name_, "route", "add", "224.0.0.0/4", "dev", "lo"});
  } catch (...) {
    run({"ip", "netns", "del", name_});
    throw;
  }
}

NetNamespace::~NetNamespace() {
  try {
    // Whatever still runs inside would keep the namespace alive: kill it.
    std::istringstream pids(run({"ip", "netns", "pids", name_}));
    for (pid_t p; pids >> p;) kill(p, SIGKILL);
    run({"ip", "netns", "del", name_});
  } catch (...) {
  }
}

std::vector<std::string> NetNamespace::exec_prefix() const { return {"ip", "netns", "exec", name_}; }

void join_with_veth(const NetNamespace& a, const NetNamespace& b, int subnet) {
  // Interface names are at most 15 characters.
  const std::string tag = std::to_string(getpid() % 100000) + "-" + std::to_string(subnet % 1000);
  const std::string va = "va" + tag, vb = "vb" + tag;
  run({"ip", "-n", a.name(), "link", "add", va, "type", "veth", "peer", "name", vb, "netns", b.name()});
  const std::string net = "10." + std::to_string(subnet) + ".0.";
  run({"ip", "-n", a.name(), "addr", "add", net + "1/24", "dev", va});
  run({"ip", "-n", b.name(), "addr", "add", net + "2/24", "dev", vb});
  run({"ip", "-n", a.name(), "link", "set", va, "up"});
  run({"ip", "-n", b.name(), "link", "set", vb, "up"});
  run({"ip", "-n", a.name(), "route", "replace", "224.0.0.0/4", "dev", va});
  run({"ip", "-n", b.name(), "route", "replace", "224.0.0.0/4", "dev", vb});
}

EnterNamespace::EnterNamespace(const NetNamespace& ns) {
  original_ = open("/proc/thread-self/ns/net", O_RDONLY | O_CLOEXEC);
  const int target = open(("/var/run/netns/" + ns.name()).c_str(), O_RDONLY | O_CLOEXEC);
  if (original_ < 0 || target < 0 || setns(target, CLONE_NEWNET) != 0) {
    const std::string err = std::strerror(errno);
    if (target >= 0) close(target);
    if (original_ >= 0) close(original_);
    throw std::runtime_error("cannot enter network namespace " + ns.name() + ": " + err);
  }
  close(target);
}

EnterNamespace::~EnterNamespace() {
  setns(original_, CLONE_NEWNET);
  close(original_);
}

RealtimePriority::RealtimePriority(int priority) {
  sched_param old{};
  old_policy_ = sched_getscheduler(0);
  sched_getparam(0, &old);
  old_priority_ = old.sched_priority;
  sched_param sp{};
  sp.sched_priority = priority;
  ok_ = sched_setscheduler(0, SCHED_FIFO, &sp) == 0;
}

RealtimePriority::~RealtimePriority() {
  if (!ok_) return;
  sched_param sp{};
  sp.sched_priority = old_priority_;
  sched_setscheduler(0, old_policy_, &sp);
}

Process::Process(const std::vector<std::string>& argv, const std::string& log_path) : log_(log_path) {
  std::vector<std::string> args = argv;
  auto cargs = c_argv(args);
  const pid_t parent = getpid();
  pid_ = fork();
  if (pid_ == 0) {
    prctl(PR_SET_PDEATHSIG, SIGKILL);  // never outlive the test
    if (getppid() != parent) _exit(127);
    const int fd = open(log_path.c_str(), O_WRONLY | O_CREAT | O_TRUNC, 0644);
    if (fd >= 0) {
      dup2(fd, 1);
      dup2(fd, 2);
    }
    const int devnull = open("/dev/null", O_RDONLY);
    if (devnull >= 0) dup2(devnull, 0);
    sigset_t none;
    sigemptyset(&none);
    sigprocmask(SIG_SETMASK, &none, nullptr);
    execvp(cargs[0], cargs.data());
    _exit(127);
  }
  if (pid_ < 0) throw std::runtime_error("fork failed for " + joined(argv));
}

Process::~Process() {
  if (pid_ > 0 && !status_) stop(SIGTERM, std::chrono::milliseconds(5000));
}

bool Process::running() { return !wait(std::chrono::milliseconds(0)).has_value(); }

std::optional<int> Process::wait(std::chrono::milliseconds timeout) {
  if (status_) return status_;
  const auto until = std::chrono::steady_clock::now() + timeout;
  while (true) {
    int st = 0;
    const pid_t r = waitpid(pid_, &st, WNOHANG);
    if (r == pid_) {
      status_ = exit_code(st);
      return status_;
    }
    if (r < 0) {
      status_ = -1;
      return status_;
    }
    if (std::chrono::steady_clock::now() >= until) return std::nullopt;
    std::this_thread::sleep_for(std::chrono::milliseconds(5));
  }
}

int Process::stop(int sig, std::chrono::milliseconds grace) {
  if (status_) return *status_;
  kill(pid_, sig);
  if (auto s = wait(grace)) return *s;
  kill(pid_, SIGKILL);
  return wait(std::chrono::milliseconds(10000)).value_or(-1);
}

std::string Process::log() const {
  std::ifstream in(log_);
  std::stringstream ss;
  ss << in.rdbuf();
  return ss.str();
}

}  // namespace aerie::procman::testbed
