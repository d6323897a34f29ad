#pragma once
// The sheriff: holds the wanted state of every command of a configuration, turns
// it into orders for each deputy, and derives each command's state from the
// deputies' reports (libbot2 semantics; transport-free, `aerie-sheriff` carries
// the messages over LCM). In observer mode it only watches: the commands are
// whatever the deputies report, and no orders are made.
#include <bot_procman/info2_t.hpp>
#include <bot_procman/orders2_t.hpp>

#include <cstdint>
#include <functional>
#include <map>
#include <optional>
#include <random>
#include <set>
#include <string>
#include <utility>
#include <vector>

#include "procman/pmd_config.hpp"

namespace aerie::procman {

enum class CommandStatus {
  Unknown,     // deputy not heard from (or lost), or command not yet in its report
  Starting,    // start ordered, not running yet
  Running,
  Restarting,  // running an older run id; will be stopped and started again
  Stopping,
  Respawning,  // ended by itself; the deputy will start it again (auto_respawn)
  Stopped,     // not running: never started, exited 0, or ended after a stop order
               // (its stop signal, SIGKILL after stop_time_allowed, or any exit then)
  Failed,      // ended by itself with a non-zero exit code or a signal, no respawn
};
const char* to_string(CommandStatus s);

// A command as the sheriff knows it. Key: (host, sheriff_id).
struct SheriffCommand {
  std::string host;
  int32_t sheriff_id = 0;
  bot_procman::command2_t cmd;
  int32_t desired_runid = 0;
  bool force_quit = false;
  // From the deputy's latest report.
  bool reported = false;
  bot_procman::deputy_cmd2_t last;
  int32_t restarts = 0;             // respawns seen (pid changed within one run id)
  int32_t last_seen_pid = 0;
  int32_t last_seen_runid = 0;
  // The last run ended after this sheriff (or, for an adopted command, its
  // predecessor) ordered it to stop: it reads "stopped" whatever its exit status.
  bool stopped_by_order = false;
};

struct DeputyView {
  std::string host;
  int64_t last_seen_ms = -1;        // monotonic, when the last report came
  int64_t reports = 0;
  bool synced = false;              // its commands were matched with ours
  bot_procman::info2_t info;

  // Memory in use on the deputy's host (MiB), as its last report gives it; subtracted in double,
  // since the figures come off the network (total INT64_MIN overflowed the int64 difference).
  double used_mib() const {
    return (static_cast<double>(info.phys_mem_total_bytes) - static_cast<double>(info.phys_mem_free_bytes)) / 1048576.0;
  }
};

class Sheriff {
 public:
  // seed: for the command ids; 0 = from std::random_device (a new sheriff session).
  Sheriff(std::string name, bool observer = false, double deputy_timeout_s = 3.0, uint64_t seed = 0);

  // Adds the commands of a configuration. Each gets a random 31-bit sheriff id
  // (never 0, unique within this sheriff), as libbot2's sheriff does, so ids of
  // different sheriff sessions do not collide on a deputy that still holds old
  // commands.
  void load(const PmdConfig& config);

  // Commands named by a script target; throws std::invalid_argument for an unknown name.
  std::vector<std::pair<std::string, int32_t>> select(TargetKind target, const std::string& ident) const;
  // libbot2's operations: start a stopped command (new run id), stop, restart
  // (new run id, stopping first if running).
  void start(const std::vector<std::pair<std::string, int32_t>>& keys);
  void stop(const std::vector<std::pair<std::string, int32_t>>& keys);
  void restart(const std::vector<std::pair<std::string, int32_t>>& keys);

  // Merges a deputy report. On the first report of a deputy, commands it already
  // runs under the same name are adopted (their ids and run ids), so a restarted
  // sheriff does not restart what is running.
  void on_info(const bot_procman::info2_t& info, int64_t now_ms);

  // Orders for every deputy heard from (none in observer mode).
  std::vector<bot_procman::orders2_t> orders(int64_t utime) const;
  // True once after something that should be sent at once (an operation, a sync).
  bool take_dirty();

  CommandStatus status(const SheriffCommand& c, int64_t now_ms) const;
  // True when every command in keys has reached `what` (Running or Stopped/Failed).
  bool reached(const std::vector<std::pair<std::string, int32_t>>& keys, WaitFor what, int64_t now_ms) const;
  bool deputy_alive(const std::string& host, int64_t now_ms) const;

  // The status table: deputies, then commands (host, command, group, state, pid,
  // CPU, memory, restarts).
  std::string table(int64_t now_ms) const;

  const std::string& name() const { return name_; }
  bool observer() const { return observer_; }
  const std::vector<SheriffCommand>& commands() const { return commands_; }
  const std::map<std::string, DeputyView>& deputies() const { return deputies_; }
  const SheriffCommand* find(const std::string& host, int32_t sheriff_id) const;
  const SheriffCommand* find_by_name(const std::string& name) const;

 private:
  SheriffCommand* find_mut(const std::string& host, int32_t sheriff_id);
  void adopt(const bot_procman::info2_t& info);
  int32_t fresh_id();
  bool id_in_use(int32_t id) const;

  std::string name_;
  bool observer_;
  int64_t deputy_timeout_ms_;
  std::vector<SheriffCommand> commands_;
  std::map<std::string, DeputyView> deputies_;
  bool dirty_ = false;
  std::mt19937 rng_;
  // Ids the deputies reported that belong to no command of ours: never handed out.
  std::set<std::pair<std::string, int32_t>> foreign_ids_;
};

// Runs a script of the configuration against a sheriff, one step at a time.
class ScriptRunner {
 public:
  enum class Status { Running, Done, Failed };
  using Log = std::function<void(const std::string&)>;

  // wait_timeout_s: a wait for a status fails after this long (0 = wait forever).
  ScriptRunner(Sheriff& sheriff, const PmdConfig& config, const std::string& script, Log log = {},
               double wait_timeout_s = 0);
  // Executes actions until one has to wait; call again on every report and timer.
  Status step(int64_t now_ms);
  Status status() const { return status_; }
  const std::string& error() const { return error_; }
  // Milliseconds until a timed wait ends (-1 = none).
  int next_timer_ms(int64_t now_ms) const;

 private:
  struct Frame {
    const PmdScript* script;
    size_t next;
  };
  Sheriff& sheriff_;
  const PmdConfig& config_;
  Log log_;
  int64_t wait_timeout_ms_;
  std::vector<Frame> stack_;
  Status status_ = Status::Running;
  std::string error_;
  // The wait in progress.
  int64_t wait_until_ms_ = -1;
  int64_t wait_since_ms_ = -1;
  WaitFor waiting_for_ = WaitFor::Nothing;
  std::vector<std::pair<std::string, int32_t>> waiting_on_;
  std::string waiting_what_;
};

}  // namespace aerie::procman
