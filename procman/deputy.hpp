#pragma once
// The deputy: runs the commands a sheriff orders on one host, with libbot2's
// semantics (bot2-procman procman_deputy.c), transport-free so that it can be
// tested without LCM; `aerie-deputy` carries its messages over LCM.
//
// * Orders (bot_procman.orders2_t) are complete and stateless: each names every
//   command this host should have, with the run id the sheriff wants. A command
//   starts when desired_runid differs from the run id it last started with and
//   force_quit is 0, stops when force_quit is set, restarts when the run id changes
//   while running; commands absent from the orders are stopped and removed.
//   Orders older than max_order_age_s are refused ("check the clocks").
// * Safety against stale commands: an id the deputy does not know is a new command
//   (run id 0), started only when the orders ask for a run (desired_runid != 0 and
//   force_quit 0). An id the deputy knows under another command name (reused by a
//   different sheriff) is a different command: the old one is stopped, and the new
//   one inherits no run id, so it is not started until the sheriff changes
//   desired_runid. The newest orders are obeyed whatever the sheriff's name; a change
//   of sheriff is reported on the output (sheriff id 0).
// * A command runs in its own session on a pseudo-terminal (so its output is
//   line-buffered); everything it writes is passed to the output callback.
// * Stop: stop_signal to the command's session and descendants, SIGKILL after
//   stop_time_allowed. When a command ends, whatever it left behind is killed, and
//   the deputy is a child subreaper, so orphans never outlive it.
// * Auto-respawn with exponential back-off: respawn_min_ms after a crash, doubling
//   while the command keeps dying within stable_run_s, up to respawn_max_ms.
#include <bot_procman/info2_t.hpp>
#include <bot_procman/orders2_t.hpp>
#include <sys/types.h>

#include <cstdint>
#include <functional>
#include <map>
#include <memory>
#include <string>
#include <vector>

#include "procman/proc_stats.hpp"

namespace aerie::procman {

struct DeputyOptions {
  std::string name;                  // the host name the sheriff uses
  double max_order_age_s = 60.0;     // older orders are refused
  int respawn_min_ms = 100;
  int respawn_max_ms = 10000;
  double stable_run_s = 5.0;         // a run this long resets the back-off
  std::string extra_path;            // prepended to PATH for the commands ("" = none)
};

// Lifecycle of one command on the deputy (what the sheriff sees through pid/run id).
enum class ProcState { Stopped, Running, Stopping, RespawnPending };

class Deputy {
 public:
  // text written by command sheriff_id (0: the deputy's own messages).
  using OutputSink = std::function<void(int32_t sheriff_id, const std::string& text)>;

  struct Command {
    int32_t sheriff_id = 0;
    bot_procman::command2_t cmd;
    int32_t desired_runid = 0;
    int32_t actual_runid = 0;
    bool force_quit = false;
    bool remove_requested = false;
    pid_t pid = 0;
    int pty_fd = -1;
    int32_t exit_status = 0;         // last wait() status word (as libbot2 reports it)
    int64_t started_ms = 0;          // monotonic
    int64_t stop_sent_ms = -1;       // stop signal sent at; -1 = not stopping
    bool sigkill_sent = false;
    int64_t respawn_at_ms = -1;      // -1 = none scheduled
    int backoff_ms = 0;
    int32_t restarts = 0;            // automatic respawns
    std::vector<pid_t> stop_targets;  // processes signalled when stopping
    std::string superseded_name;     // the running process is an earlier command of this id, being stopped
    // usage over the last sampling period: the command's CPU time and the host's total at the
    // last sample, or at the start (a new process has used none), so the first sample has a CPU figure
    uint64_t last_jiffies = 0;
    uint64_t last_host_jiffies = 0;
    float cpu_usage = 0;
    int64_t vsize_bytes = 0, rss_bytes = 0;

    ProcState state() const;
  };

  Deputy(DeputyOptions options, OutputSink output);
  ~Deputy();  // shutdown()
  Deputy(const Deputy&) = delete;
  Deputy& operator=(const Deputy&) = delete;

  enum class OrdersResult { Applied, OtherHost, Stale, Exiting };
  // now_utime: wall clock, compared with orders.utime. `changed` is set when
  // something was started, stopped, added or removed (report at once).
  OrdersResult handle_orders(const bot_procman::orders2_t& orders, int64_t now_utime, bool* changed = nullptr);

  // Reaps exited children, forwards their output, sends due SIGKILLs and respawns.
  // Returns true when a command changed state (report at once).
  bool step();
  // Samples CPU and memory (call about once a second).
  void sample_usage();
  bot_procman::info2_t report(int64_t utime) const;

  // File descriptors to wait on (readable = call step()): the commands' terminals
  // and a pipe written on SIGCHLD.
  std::vector<int> wait_fds() const;
  // Milliseconds until step() has a timer to serve (-1 = none).
  int next_timer_ms() const;

  // Stops every command (stop signal, then SIGKILL after the longest
  // stop_time_allowed, at most max_wait_s) and kills all that is left, orphans
  // included. Blocks until done. Orders are refused afterwards.
  void shutdown(double max_wait_s = 30.0);

  const std::map<int32_t, Command>& commands() const { return commands_; }
  const std::string& name() const { return options_.name; }
  float host_cpu_load() const { return cpu_load_; }

 private:
  void apply(Command& c, int64_t now);
  bool start(Command& c, int64_t now);
  void stop(Command& c, int64_t now);
  void signal_command(Command& c, int sig);
  bool drain_output(Command& c);
  void on_exit(Command& c, int status, int64_t now);
  void say(int32_t sheriff_id, const std::string& text);
  void kill_leftovers(pid_t session);

  DeputyOptions options_;
  OutputSink output_;
  std::map<int32_t, Command> commands_;
  bool exiting_ = false;
  int64_t last_stale_warning_ms_ = -1000000;
  std::string last_sheriff_name_;  // who sent the last orders applied
  HostSample host_;  // the last sample: memory, and the jiffies the CPU load is measured from
  float cpu_load_ = 0;
};

const char* to_string(ProcState s);

}  // namespace aerie::procman
