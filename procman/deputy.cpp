#include "procman/deputy.hpp"

#include <fcntl.h>
#include <poll.h>
#include <pty.h>
#include <signal.h>
#include <sys/prctl.h>
#include <sys/wait.h>
#include <termios.h>
#include <unistd.h>

#include <algorithm>
#include <cerrno>
#include <chrono>
#include <cmath>
#include <cstring>
#include <stdexcept>

#include "procman/command_line.hpp"
#include "procman/proc_stats.hpp"

extern char** environ;

namespace aerie::procman {
namespace {

int64_t mono_ms() {
  return std::chrono::duration_cast<std::chrono::milliseconds>(std::chrono::steady_clock::now().time_since_epoch())
      .count();
}

// SIGCHLD -> a byte in a non-blocking pipe, so the deputy's poll() wakes up at once.
int g_sigchld_pipe[2] = {-1, -1};
extern "C" void on_sigchld(int) {
  const int saved = errno;
  const char b = 1;
  [[maybe_unused]] const auto n = write(g_sigchld_pipe[1], &b, 1);
  errno = saved;
}
void install_sigchld_pipe() {
  if (g_sigchld_pipe[0] >= 0) return;
  if (pipe2(g_sigchld_pipe, O_NONBLOCK | O_CLOEXEC) != 0)
    throw std::runtime_error(std::string("deputy: pipe2: ") + std::strerror(errno));
  struct sigaction sa {};
  sa.sa_handler = on_sigchld;
  sigemptyset(&sa.sa_mask);
  sa.sa_flags = SA_RESTART | SA_NOCLDSTOP;
  sigaction(SIGCHLD, &sa, nullptr);
}
void drain_sigchld_pipe() {
  char buf[64];
  while (read(g_sigchld_pipe[0], buf, sizeof buf) > 0) {
  }
}

std::string describe_status(int status) {
  if (WIFSIGNALED(status)) {
    std::string s = std::string("terminated by signal ") + std::to_string(WTERMSIG(status)) + " (" +
                    strsignal(WTERMSIG(status)) + ")";
    if (WCOREDUMP(status)) s += ", core dumped";
    return s;
  }
  return "exited with code " + std::to_string(WEXITSTATUS(status));
}

}  // namespace

ProcState Deputy::Command::state() const {
  if (pid != 0) return stop_sent_ms >= 0 ? ProcState::Stopping : ProcState::Running;
  return respawn_at_ms >= 0 ? ProcState::RespawnPending : ProcState::Stopped;
}

const char* to_string(ProcState s) {
  switch (s) {
    case ProcState::Running: return "running";
    case ProcState::Stopping: return "stopping";
    case ProcState::RespawnPending: return "respawn-pending";
    default: return "stopped";
  }
}

Deputy::Deputy(DeputyOptions options, OutputSink output) : options_(std::move(options)), output_(std::move(output)) {
  if (options_.name.empty()) throw std::invalid_argument("deputy: empty name");
  if (options_.respawn_min_ms <= 0 || options_.respawn_max_ms < options_.respawn_min_ms)
    throw std::invalid_argument("deputy: need 0 < respawn_min_ms <= respawn_max_ms");
  install_sigchld_pipe();
  // Orphaned descendants of our commands are re-parented to us, not to init.
  prctl(PR_SET_CHILD_SUBREAPER, 1);
  host_ = read_host();
}

Deputy::~Deputy() {
  try {
    shutdown();
  } catch (...) {
  }
}

void Deputy::say(int32_t sheriff_id, const std::string& text) {
  if (output_) output_(sheriff_id, text + "\n");
}

Deputy::OrdersResult Deputy::handle_orders(const bot_procman::orders2_t& orders, int64_t now_utime, bool* changed) {
  bool any = false;
  if (changed) *changed = false;
  if (exiting_) return OrdersResult::Exiting;
  if (orders.host != options_.name) return OrdersResult::OtherHost;
  // In double: the stamp comes off the network (INT64_MIN overflowed the int64 difference).
  const double age_s = (static_cast<double>(now_utime) - static_cast<double>(orders.utime)) * 1e-6;
  const int64_t now = mono_ms();
  if (age_s > options_.max_order_age_s) {
    if (now - last_stale_warning_ms_ >= 5000) {  // at most every 5 s
      last_stale_warning_ms_ = now;
      char buf[320];
      std::snprintf(buf, sizeof buf,
                    "refusing orders from sheriff '%s': they are %.1f s old (limit %.1f s). "
                    "Check that the clocks of the sheriff's and this deputy's hosts agree (NTP/chrony).",
                    orders.sheriff_name.c_str(), age_s, options_.max_order_age_s);
      say(0, buf);
    }
    return OrdersResult::Stale;
  }

  // The newest orders are obeyed (libbot2), whoever sent them; a change of sheriff
  // is said on PMD_PRINTF so that the operator sees who took over.
  if (orders.sheriff_name != last_sheriff_name_) {
    if (!last_sheriff_name_.empty())
      say(0, "taking orders from sheriff '" + orders.sheriff_name + "' (previous orders came from '" +
                 last_sheriff_name_ + "')");
    last_sheriff_name_ = orders.sheriff_name;
  }

  for (const auto& sc : orders.cmds) {
    if (sc.sheriff_id == 0) continue;  // 0 is the deputy's own id (printf_t), never a command's
    auto [it, fresh] = commands_.try_emplace(sc.sheriff_id);
    Command& c = it->second;
    if (fresh) {
      // An id this deputy does not know: a new command. Its run id is 0, so it
      // starts only when the orders ask for a run (desired_runid != 0, force_quit 0).
      c.sheriff_id = sc.sheriff_id;
      c.cmd = sc.cmd;
      c.backoff_ms = options_.respawn_min_ms;
      any = true;
    } else if (c.cmd.command_name != sc.cmd.command_name) {
      // The id now names another command (ids reused by a different sheriff, or an
      // old sheriff numbering 1..N). What we hold under it is not what the orders
      // name: it is stopped, and its run history is not inherited by the new
      // command, which these orders do not start (run id taken as current); the
      // sheriff starts it by changing desired_runid.
      say(0, "sheriff '" + orders.sheriff_name + "' names id " + std::to_string(sc.sheriff_id) + " [" +
                 sc.cmd.command_name + "], which here was [" + c.cmd.command_name + "]" +
                 (c.pid != 0 ? ": stopping [" + c.cmd.command_name + "]" : "") + "; [" + sc.cmd.command_name +
                 "] starts when the sheriff asks for a new run");
      if (c.pid != 0) {
        if (c.superseded_name.empty()) c.superseded_name = c.cmd.command_name;
        stop(c, now);
      }
      c.cmd = sc.cmd;
      c.actual_runid = sc.desired_runid;
      c.respawn_at_ms = -1;
      c.restarts = 0;
      c.backoff_ms = options_.respawn_min_ms;
      if (c.pid == 0) c.exit_status = 0;
      any = true;
    } else {
      // A changed exec string takes effect at the next start (as in libbot2).
      if (c.cmd.exec_str != sc.cmd.exec_str || c.cmd.group != sc.cmd.group) any = true;
      c.cmd = sc.cmd;
    }
    c.desired_runid = sc.desired_runid;
    c.force_quit = sc.force_quit != 0;
    c.remove_requested = false;
    const ProcState before = c.state();
    const int32_t pid_before = c.pid;
    apply(c, now);
    if (c.state() != before || c.pid != pid_before) any = true;
  }
  // Commands the sheriff no longer lists are stopped and forgotten.
  for (auto it = commands_.begin(); it != commands_.end();) {
    const bool listed = std::any_of(orders.cmds.begin(), orders.cmds.end(),
                                    [&](const auto& sc) { return sc.sheriff_id == it->first; });
    if (listed) {
      ++it;
      continue;
    }
    any = true;
    if (it->second.pid != 0) {
      it->second.remove_requested = true;
      stop(it->second, now);
      ++it;
    } else {
      it = commands_.erase(it);
    }
  }
  if (changed) *changed = any;
  return OrdersResult::Applied;
}

// libbot2's reconciliation of one command with its orders.
void Deputy::apply(Command& c, int64_t now) {
  if (c.pid == 0) {
    if (!c.force_quit && c.desired_runid != c.actual_runid) {
      start(c, now);
    } else {
      c.actual_runid = c.desired_runid;
      if (c.force_quit) c.respawn_at_ms = -1;
    }
  } else if (c.force_quit || c.desired_runid != c.actual_runid) {
    stop(c, now);
  }
}

bool Deputy::start(Command& c, int64_t now) {
  c.respawn_at_ms = -1;
  c.actual_runid = c.desired_runid;
  CommandLine line;
  try {
    line = split_command_line(c.cmd.exec_str);
  } catch (const std::exception& e) {
    c.exit_status = W_EXITCODE(127, 0);
    say(c.sheriff_id, std::string("cannot start [") + c.cmd.command_name + "]: " + e.what());
    return false;
  }

  // Everything the child needs is prepared before fork(): after it only
  // async-signal-safe calls are made (the node has LCM threads).
  std::vector<std::string> env_strings;
  std::string path = options_.extra_path;
  if (const char* p = std::getenv("PATH")) path = path.empty() ? p : path + ":" + p;
  for (char** e = environ; *e; ++e) {
    const std::string kv = *e;
    const std::string key = kv.substr(0, kv.find('='));
    if (key == "PATH") continue;
    if (std::any_of(line.env.begin(), line.env.end(), [&](const auto& p) { return p.first == key; })) continue;
    env_strings.push_back(kv);
  }
  env_strings.push_back("PATH=" + path);
  for (const auto& [k, v] : line.env) env_strings.push_back(k + "=" + v);
  std::vector<char*> envp, argv;
  for (auto& s : env_strings) envp.push_back(s.data());
  envp.push_back(nullptr);
  for (auto& s : line.argv) argv.push_back(s.data());
  argv.push_back(nullptr);

  struct termios tio {};
  cfmakeraw(&tio);  // exact bytes: no echo, no "\n" -> "\r\n"
  const pid_t parent = getpid();
  int master = -1;
  const pid_t pid = forkpty(&master, nullptr, &tio, nullptr);
  if (pid == 0) {
    // Child: forkpty made it a session leader with the terminal as stdin/out/err.
    prctl(PR_SET_PDEATHSIG, SIGKILL);  // dies with the deputy
    if (getppid() != parent) _exit(127);
    sigset_t none;
    sigemptyset(&none);
    sigprocmask(SIG_SETMASK, &none, nullptr);
    for (int s : {SIGPIPE, SIGCHLD, SIGINT, SIGTERM, SIGHUP, SIGQUIT}) signal(s, SIG_DFL);
    close_range(3, ~0U, 0);
    environ = envp.data();
    execvp(argv[0], argv.data());
    const char* err = strerror(errno);
    const char* msg = "aerie-deputy: cannot run '";
    [[maybe_unused]] auto n = write(2, msg, std::strlen(msg));
    n = write(2, argv[0], std::strlen(argv[0]));
    n = write(2, "': ", 3);
    n = write(2, err, std::strlen(err));
    n = write(2, "\n", 1);
    _exit(127);
  }
  if (pid < 0) {
    c.exit_status = W_EXITCODE(127, 0);
    say(c.sheriff_id, std::string("cannot start [") + c.cmd.command_name + "]: forkpty: " + std::strerror(errno));
    return false;
  }
  fcntl(master, F_SETFL, fcntl(master, F_GETFL) | O_NONBLOCK);
  fcntl(master, F_SETFD, FD_CLOEXEC);
  c.pid = pid;
  c.pty_fd = master;
  c.exit_status = 0;
  c.started_ms = now;
  c.stop_sent_ms = -1;
  c.sigkill_sent = false;
  c.stop_targets.clear();
  c.last_jiffies = 0;
  c.last_host_jiffies = read_host().total_jiffies;
  c.cpu_usage = 0;
  return true;
}

void Deputy::signal_command(Command& c, int sig) {
  kill(c.pid, sig);  // the command first, then what it started (found by a /proc scan)
  for (pid_t p : command_processes(c.pid, read_all_processes()))
    if (std::find(c.stop_targets.begin(), c.stop_targets.end(), p) == c.stop_targets.end())
      c.stop_targets.push_back(p);
  for (pid_t p : c.stop_targets)
    if (p != c.pid) kill(p, sig);
}

void Deputy::stop(Command& c, int64_t now) {
  c.respawn_at_ms = -1;
  if (c.pid == 0 || c.stop_sent_ms >= 0) return;
  c.stop_sent_ms = now;
  signal_command(c, c.cmd.stop_signal > 0 ? c.cmd.stop_signal : SIGINT);
}

bool Deputy::drain_output(Command& c) {
  if (c.pty_fd < 0) return false;
  char buf[4096];
  bool any = false;
  while (true) {
    const ssize_t n = read(c.pty_fd, buf, sizeof buf);
    if (n > 0) {
      if (output_) output_(c.sheriff_id, std::string(buf, static_cast<size_t>(n)));
      any = true;
      continue;
    }
    if (n < 0 && (errno == EAGAIN || errno == EINTR)) break;
    // EOF or EIO: nobody holds the terminal any more.
    close(c.pty_fd);
    c.pty_fd = -1;
    break;
  }
  return any;
}

void Deputy::kill_leftovers(pid_t session) {
  // Whatever is left of the command: its session, and orphans re-parented to us.
  const pid_t self = getpid();
  for (const auto& p : read_all_processes()) {
    const bool ours = std::any_of(commands_.begin(), commands_.end(), [&](const auto& kv) { return kv.second.pid == p.pid; });
    if (ours || p.pid == self) continue;
    if (p.session == session || p.ppid == self) kill(p.pid, SIGKILL);
  }
}

void Deputy::on_exit(Command& c, int status, int64_t now) {
  drain_output(c);
  if (c.pty_fd >= 0) {
    close(c.pty_fd);
    c.pty_fd = -1;
  }
  const pid_t leader = c.pid;
  c.pid = 0;
  c.exit_status = status;
  kill_leftovers(leader);
  const bool was_stopping = c.stop_sent_ms >= 0;
  c.stop_sent_ms = -1;
  c.cpu_usage = 0;
  c.vsize_bytes = c.rss_bytes = 0;
  if (!c.superseded_name.empty()) {
    // What ended was the command that held this id before: not the current one's exit.
    say(0, "[" + c.superseded_name + "] (id " + std::to_string(c.sheriff_id) + ") " + describe_status(status));
    c.superseded_name.clear();
    c.exit_status = 0;
  } else if (!was_stopping || status != 0) {
    say(c.sheriff_id, "[" + c.cmd.command_name + "] " + describe_status(status));
  }
  if (c.remove_requested || exiting_) return;

  if (!c.force_quit && c.desired_runid != c.actual_runid) {
    start(c, now);  // a restart: the stop is done, start the new run at once
  } else if (c.cmd.auto_respawn && !c.force_quit && !was_stopping) {
    if (static_cast<double>(now - c.started_ms) >= options_.stable_run_s * 1000.0) c.backoff_ms = options_.respawn_min_ms;
    c.respawn_at_ms = now + c.backoff_ms;
    say(c.sheriff_id, "[" + c.cmd.command_name + "] respawning in " + std::to_string(c.backoff_ms) + " ms");
    c.backoff_ms = std::min(options_.respawn_max_ms, c.backoff_ms * 2);
  }
}

bool Deputy::step() {
  drain_sigchld_pipe();
  bool changed = false;
  for (auto& [id, c] : commands_) drain_output(c);
  const int64_t now = mono_ms();
  while (true) {
    int status = 0;
    const pid_t pid = waitpid(-1, &status, WNOHANG);
    if (pid <= 0) break;
    auto it = std::find_if(commands_.begin(), commands_.end(), [&](const auto& kv) { return kv.second.pid == pid; });
    if (it == commands_.end()) continue;  // an orphan we killed
    on_exit(it->second, status, now);
    changed = true;
    if (it->second.remove_requested && it->second.pid == 0) commands_.erase(it);
  }
  for (auto& [id, c] : commands_) {
    if (c.pid != 0 && c.stop_sent_ms >= 0 && !c.sigkill_sent &&
        now - c.stop_sent_ms >= static_cast<int64_t>(std::lround(c.cmd.stop_time_allowed * 1000.0))) {
      say(c.sheriff_id, "[" + c.cmd.command_name + "] still running " + std::to_string(c.cmd.stop_time_allowed) +
                            " s after signal " + std::to_string(c.cmd.stop_signal) + ": sending SIGKILL");
      c.sigkill_sent = true;
      signal_command(c, SIGKILL);
    }
    if (c.pid == 0 && c.respawn_at_ms >= 0 && now >= c.respawn_at_ms) {
      c.respawn_at_ms = -1;
      if (c.cmd.auto_respawn && !c.force_quit && !exiting_ && start(c, now)) {
        ++c.restarts;
        changed = true;
      }
    }
  }
  return changed;
}

int Deputy::next_timer_ms() const {
  const int64_t now = mono_ms();
  int64_t best = -1;
  auto consider = [&](int64_t at) {
    const int64_t dt = std::max<int64_t>(0, at - now);
    if (best < 0 || dt < best) best = dt;
  };
  for (const auto& [id, c] : commands_) {
    if (c.pid != 0 && c.stop_sent_ms >= 0 && !c.sigkill_sent)
      consider(c.stop_sent_ms + static_cast<int64_t>(std::lround(c.cmd.stop_time_allowed * 1000.0)));
    if (c.pid == 0 && c.respawn_at_ms >= 0) consider(c.respawn_at_ms);
  }
  return static_cast<int>(std::min<int64_t>(best, 1 << 30));
}

std::vector<int> Deputy::wait_fds() const {
  std::vector<int> fds{g_sigchld_pipe[0]};
  for (const auto& [id, c] : commands_)
    if (c.pty_fd >= 0) fds.push_back(c.pty_fd);
  return fds;
}

void Deputy::sample_usage() {
  const HostSample h = read_host();
  const uint64_t dtotal = h.total_jiffies - host_.total_jiffies;
  const uint64_t dbusy = h.busy_jiffies - host_.busy_jiffies;
  if (dtotal > 0 && dbusy <= dtotal) cpu_load_ = static_cast<float>(static_cast<double>(dbusy) / static_cast<double>(dtotal));
  host_ = h;

  const auto all = read_all_processes();
  const pid_t self = getpid();
  for (auto& [id, c] : commands_) {
    if (c.pid == 0) continue;
    uint64_t jiffies = 0;
    int64_t vsize = 0, rss = 0;
    for (const auto& p : all) {
      if (p.session != c.pid) continue;  // the command and what it started
      jiffies += p.cpu_jiffies;
      vsize += p.vsize_bytes;
      rss += p.rss_bytes;
    }
    // cpu_usage: fraction of the whole host's CPU time (libbot2's convention), since the last
    // sample or the start. (Waiting for a previous sample with jiffies > 0 left a new command at
    // 0 % for its first two or three reports, issue 49.)
    const uint64_t dhost = h.total_jiffies - c.last_host_jiffies;
    if (c.last_host_jiffies > 0 && jiffies >= c.last_jiffies && dhost > 0 && h.total_jiffies >= c.last_host_jiffies)
      c.cpu_usage = static_cast<float>(static_cast<double>(jiffies - c.last_jiffies) / static_cast<double>(dhost));
    c.last_jiffies = jiffies;
    c.last_host_jiffies = h.total_jiffies;
    c.vsize_bytes = vsize;
    c.rss_bytes = rss;
  }
  // Orphans re-parented to us (subreaper) whose command is gone.
  for (const auto& p : all) {
    if (p.ppid != self) continue;
    const bool ours = std::any_of(commands_.begin(), commands_.end(), [&](const auto& kv) { return kv.second.pid == p.pid; });
    if (!ours) kill(p.pid, SIGKILL);
  }
}

bot_procman::info2_t Deputy::report(int64_t utime) const {
  bot_procman::info2_t m;
  m.utime = utime;
  m.host = options_.name;
  m.cpu_load = cpu_load_;
  m.phys_mem_total_bytes = host_.mem_total_bytes;
  m.phys_mem_free_bytes = host_.mem_available_bytes;
  m.swap_total_bytes = host_.swap_total_bytes;
  m.swap_free_bytes = host_.swap_free_bytes;
  for (const auto& [id, c] : commands_) {
    bot_procman::deputy_cmd2_t d;
    d.cmd = c.cmd;
    d.pid = c.pid;
    d.actual_runid = c.actual_runid;
    d.exit_code = c.exit_status;
    d.cpu_usage = c.cpu_usage;
    d.mem_vsize_bytes = c.vsize_bytes;
    d.mem_rss_bytes = c.rss_bytes;
    d.sheriff_id = c.sheriff_id;
    m.cmds.push_back(std::move(d));
  }
  m.ncmds = static_cast<int32_t>(m.cmds.size());
  m.num_options = 0;
  return m;
}

void Deputy::shutdown(double max_wait_s) {
  exiting_ = true;
  int64_t now = mono_ms();
  double grace_s = 0;
  for (auto& [id, c] : commands_) {
    c.force_quit = true;
    c.respawn_at_ms = -1;
    if (c.pid != 0) {
      stop(c, now);
      grace_s = std::max(grace_s, static_cast<double>(c.cmd.stop_time_allowed));
    }
  }
  const int64_t deadline = now + static_cast<int64_t>(std::min(max_wait_s, grace_s + 1.0) * 1000.0);
  auto running = [&] {
    return std::any_of(commands_.begin(), commands_.end(), [](const auto& kv) { return kv.second.pid != 0; });
  };
  while (running() && mono_ms() < deadline) {
    pollfd pfd{g_sigchld_pipe[0], POLLIN, 0};
    poll(&pfd, 1, 20);
    step();  // reaps, forwards output, sends SIGKILL after each command's grace time
  }
  for (auto& [id, c] : commands_) {
    if (c.pid == 0) continue;
    signal_command(c, SIGKILL);
    int status = 0;
    if (waitpid(c.pid, &status, 0) == c.pid) on_exit(c, status, mono_ms());
  }
  // Orphans: SIGKILL and reap everything still parented to us.
  const pid_t self = getpid();
  for (int round = 0; round < 50; ++round) {
    bool any = false;
    for (const auto& p : read_all_processes())
      if (p.ppid == self) {
        kill(p.pid, SIGKILL);
        any = true;
      }
    while (waitpid(-1, nullptr, WNOHANG) > 0) {
    }
    if (!any) break;
    usleep(10000);
  }
  commands_.clear();
}

}  // namespace aerie::procman
