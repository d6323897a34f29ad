#include "procman/sheriff.hpp"

#include <signal.h>
#include <sys/wait.h>

#include <algorithm>
#include <cstdio>
#include <limits>
#include <sstream>
#include <stdexcept>

namespace aerie::procman {

const char* to_string(CommandStatus s) {
  switch (s) {
    case CommandStatus::Starting: return "starting";
    case CommandStatus::Running: return "running";
    case CommandStatus::Restarting: return "restarting";
    case CommandStatus::Stopping: return "stopping";
    case CommandStatus::Respawning: return "respawning";
    case CommandStatus::Stopped: return "stopped";
    case CommandStatus::Failed: return "failed";
    default: return "unknown";
  }
}

Sheriff::Sheriff(std::string name, bool observer, double deputy_timeout_s, uint64_t seed)
    : name_(std::move(name)),
      observer_(observer),
      deputy_timeout_ms_(static_cast<int64_t>(deputy_timeout_s * 1000)),
      rng_([seed] {
        std::random_device rd;
        std::seed_seq seq = seed != 0 ? std::seed_seq{static_cast<uint32_t>(seed), static_cast<uint32_t>(seed >> 32)}
                                      : std::seed_seq{rd(), rd(), rd(), rd()};
        return std::mt19937(seq);
      }()) {}

void Sheriff::load(const PmdConfig& config) {
  for (const auto& pc : config.commands) {
    SheriffCommand c;
    c.host = pc.host;
    c.sheriff_id = fresh_id();
    c.cmd.exec_str = pc.exec;
    c.cmd.command_name = pc.name;
    c.cmd.group = pc.group;
    c.cmd.auto_respawn = pc.auto_respawn;
    c.cmd.stop_signal = static_cast<int8_t>(pc.stop_signal);
    c.cmd.stop_time_allowed = static_cast<float>(pc.stop_time_allowed_s);
    c.cmd.num_options = 0;
    commands_.push_back(std::move(c));
  }
}

bool Sheriff::id_in_use(int32_t id) const {
  if (std::any_of(commands_.begin(), commands_.end(), [&](const SheriffCommand& c) { return c.sheriff_id == id; }))
    return true;
  return std::any_of(foreign_ids_.begin(), foreign_ids_.end(), [&](const auto& f) { return f.second == id; });
}

// Random in [1, 2^31 - 1] (libbot2's sheriff draws random 31-bit ids too), unique
// among this sheriff's commands (on every host) and the ids deputies report.
int32_t Sheriff::fresh_id() {
  std::uniform_int_distribution<int32_t> dist(1, std::numeric_limits<int32_t>::max());
  while (true) {
    const int32_t id = dist(rng_);
    if (!id_in_use(id)) return id;
  }
}

SheriffCommand* Sheriff::find_mut(const std::string& host, int32_t sheriff_id) {
  for (auto& c : commands_)
    if (c.host == host && c.sheriff_id == sheriff_id) return &c;
  return nullptr;
}

const SheriffCommand* Sheriff::find(const std::string& host, int32_t sheriff_id) const {
  return const_cast<Sheriff*>(this)->find_mut(host, sheriff_id);
}

const SheriffCommand* Sheriff::find_by_name(const std::string& name) const {
  for (const auto& c : commands_)
    if (c.cmd.command_name == name) return &c;
  return nullptr;
}

std::vector<std::pair<std::string, int32_t>> Sheriff::select(TargetKind target, const std::string& ident) const {
  std::vector<std::pair<std::string, int32_t>> out;
  for (const auto& c : commands_) {
    const bool match = target == TargetKind::Everything ||
                       (target == TargetKind::Command && c.cmd.command_name == ident) ||
                       (target == TargetKind::Group && group_contains(ident, c.cmd.group));
    if (match) out.emplace_back(c.host, c.sheriff_id);
  }
  if (out.empty() && target != TargetKind::Everything)
    throw std::invalid_argument(std::string("no ") + (target == TargetKind::Group ? "group" : "command") + " named \"" +
                                ident + "\"");
  return out;
}

void Sheriff::start(const std::vector<std::pair<std::string, int32_t>>& keys) {
  for (const auto& [host, id] : keys) {
    SheriffCommand* c = find_mut(host, id);
    if (!c) continue;
    // Running, or a start already on its way: nothing to do. Otherwise a new run id.
    bool under_way = false;
    if (!c->force_quit)
      under_way = c->reported ? (c->last.pid != 0 || c->last.actual_runid != c->desired_runid) : c->desired_runid != 0;
    if (!under_way) ++c->desired_runid;
    c->force_quit = false;
    dirty_ = true;
  }
}

void Sheriff::stop(const std::vector<std::pair<std::string, int32_t>>& keys) {
  for (const auto& [host, id] : keys) {
    if (SheriffCommand* c = find_mut(host, id)) {
      c->force_quit = true;
      dirty_ = true;
    }
  }
}

void Sheriff::restart(const std::vector<std::pair<std::string, int32_t>>& keys) {
  for (const auto& [host, id] : keys) {
    if (SheriffCommand* c = find_mut(host, id)) {
      ++c->desired_runid;
      c->force_quit = false;
      dirty_ = true;
    }
  }
}

namespace {
// Without having sent the order itself (an adopted command, an observer), the
// sheriff takes a run that ended by the command's stop signal or by SIGKILL as
// stopped on order.
bool ended_like_a_stop(const bot_procman::deputy_cmd2_t& d) {
  if (d.pid != 0 || d.actual_runid == 0 || !WIFSIGNALED(d.exit_code)) return false;
  const int stop_signal = d.cmd.stop_signal > 0 ? d.cmd.stop_signal : SIGINT;
  return WTERMSIG(d.exit_code) == stop_signal || WTERMSIG(d.exit_code) == SIGKILL;
}
}  // namespace

void Sheriff::adopt(const bot_procman::info2_t& info) {
  for (const auto& d : info.cmds) {
    auto it = std::find_if(commands_.begin(), commands_.end(), [&](const SheriffCommand& c) {
      return c.host == info.host && c.cmd.command_name == d.cmd.command_name;
    });
    if (it == commands_.end()) {
      // Not ours: the deputy will stop and forget it (our orders omit it). Keep
      // its id away from our commands, so that no order of ours names it.
      foreign_ids_.insert({info.host, d.sheriff_id});
      continue;
    }
    if (it->sheriff_id != d.sheriff_id) {
      // Take the deputy's id; a command of ours already using it gets a fresh one.
      if (SheriffCommand* other = find_mut(info.host, d.sheriff_id)) other->sheriff_id = fresh_id();
      it->sheriff_id = d.sheriff_id;
    }
    it->desired_runid = d.actual_runid;
    it->force_quit = false;
    it->stopped_by_order = ended_like_a_stop(d);
  }
  // A command of ours whose id the deputy holds for another command gets a fresh id.
  for (auto& c : commands_) {
    if (c.host != info.host) continue;
    const bool clash = std::any_of(info.cmds.begin(), info.cmds.end(), [&](const auto& d) {
      return d.sheriff_id == c.sheriff_id && d.cmd.command_name != c.cmd.command_name;
    });
    if (clash) c.sheriff_id = fresh_id();
  }
}

void Sheriff::on_info(const bot_procman::info2_t& info, int64_t now_ms) {
  DeputyView& dv = deputies_[info.host];
  dv.host = info.host;
  dv.last_seen_ms = now_ms;
  ++dv.reports;
  dv.info = info;
  dv.info.cmds.clear();
  dv.info.ncmds = 0;
  if (!dv.synced) {
    if (!observer_) adopt(info);
    dv.synced = true;
    dirty_ = true;
  }
  if (observer_) {
    // The deputy's list is the truth: add new commands, drop vanished ones.
    for (const auto& d : info.cmds) {
      if (find_mut(info.host, d.sheriff_id)) continue;
      SheriffCommand c;
      c.host = info.host;
      c.sheriff_id = d.sheriff_id;
      c.cmd = d.cmd;
      c.desired_runid = d.actual_runid;
      commands_.push_back(std::move(c));
    }
    std::erase_if(commands_, [&](const SheriffCommand& c) {
      return c.host == info.host && std::none_of(info.cmds.begin(), info.cmds.end(),
                                                 [&](const auto& d) { return d.sheriff_id == c.sheriff_id; });
    });
  }
  for (auto& c : commands_) {
    if (c.host != info.host) continue;
    const auto d = std::find_if(info.cmds.begin(), info.cmds.end(),
                                [&](const auto& x) { return x.sheriff_id == c.sheriff_id; });
    if (d == info.cmds.end()) {
      c.reported = false;
      continue;
    }
    if (c.reported && d->actual_runid != c.last.actual_runid) c.stopped_by_order = false;  // a new run
    if (d->pid != 0) {
      if (c.last_seen_pid != 0 && d->pid != c.last_seen_pid && d->actual_runid == c.last_seen_runid) ++c.restarts;
      c.last_seen_pid = d->pid;
      c.last_seen_runid = d->actual_runid;
      c.stopped_by_order = false;
    } else if (observer_) {
      if (!c.reported || c.last.pid != 0) c.stopped_by_order = ended_like_a_stop(*d);
    } else if (c.reported && c.last.pid != 0 && c.force_quit) {
      c.stopped_by_order = true;  // it ended after our stop order
    }
    if (observer_) {
      c.cmd = d->cmd;
      c.desired_runid = d->actual_runid;
    }
    c.reported = true;
    c.last = *d;
  }
}

std::vector<bot_procman::orders2_t> Sheriff::orders(int64_t utime) const {
  std::vector<bot_procman::orders2_t> out;
  if (observer_) return out;
  for (const auto& [host, dv] : deputies_) {
    bot_procman::orders2_t o;
    o.utime = utime;
    o.host = host;
    o.sheriff_name = name_;
    for (const auto& c : commands_) {
      if (c.host != host) continue;
      bot_procman::sheriff_cmd2_t sc;
      sc.cmd = c.cmd;
      sc.desired_runid = c.desired_runid;
      sc.force_quit = c.force_quit ? 1 : 0;
      sc.sheriff_id = c.sheriff_id;
      o.cmds.push_back(std::move(sc));
    }
    o.ncmds = static_cast<int32_t>(o.cmds.size());
    o.num_options = 0;
    out.push_back(std::move(o));
  }
  return out;
}

bool Sheriff::take_dirty() {
  const bool d = dirty_;
  dirty_ = false;
  return d;
}

bool Sheriff::deputy_alive(const std::string& host, int64_t now_ms) const {
  const auto it = deputies_.find(host);
  return it != deputies_.end() && it->second.last_seen_ms >= 0 && now_ms - it->second.last_seen_ms <= deputy_timeout_ms_;
}

CommandStatus Sheriff::status(const SheriffCommand& c, int64_t now_ms) const {
  if (!deputy_alive(c.host, now_ms) || !c.reported) return CommandStatus::Unknown;
  const auto& d = c.last;
  if (d.pid != 0) {
    if (c.force_quit) return CommandStatus::Stopping;
    if (d.actual_runid != c.desired_runid) return CommandStatus::Restarting;
    return CommandStatus::Running;
  }
  if (!c.force_quit && d.actual_runid != c.desired_runid) return CommandStatus::Starting;
  if (c.stopped_by_order) return CommandStatus::Stopped;
  if (!c.force_quit && d.cmd.auto_respawn && d.actual_runid != 0) return CommandStatus::Respawning;
  const int st = d.exit_code;
  return (WIFSIGNALED(st) || (WIFEXITED(st) && WEXITSTATUS(st) != 0)) ? CommandStatus::Failed : CommandStatus::Stopped;
}

bool Sheriff::reached(const std::vector<std::pair<std::string, int32_t>>& keys, WaitFor what, int64_t now_ms) const {
  for (const auto& [host, id] : keys) {
    const SheriffCommand* c = find(host, id);
    if (!c) return false;
    const CommandStatus s = status(*c, now_ms);
    if (what == WaitFor::Running && s != CommandStatus::Running) return false;
    if (what == WaitFor::Stopped && s != CommandStatus::Stopped && s != CommandStatus::Failed) return false;
  }
  return true;
}

std::string Sheriff::table(int64_t now_ms) const {
  std::ostringstream os;
  char line[512];
  std::snprintf(line, sizeof line, "%-12s %-9s %7s %21s %10s\n", "DEPUTY", "STATE", "CPU", "MEM USED/TOTAL", "LAST SEEN");
  os << line;
  for (const auto& [host, dv] : deputies_) {
    std::snprintf(line, sizeof line, "%-12s %-9s %6.1f%% %9.0f/%6.0f MiB %8.1f s\n", host.c_str(),
                  deputy_alive(host, now_ms) ? "ok" : "LOST", 100.0 * dv.info.cpu_load, dv.used_mib(),
                  static_cast<double>(dv.info.phys_mem_total_bytes) / 1048576.0,
                  static_cast<double>(now_ms - dv.last_seen_ms) / 1000.0);
    os << line;
  }
  std::snprintf(line, sizeof line, "\n%-8s %-20s %-14s %-11s %8s %6s %9s %8s  %s\n", "HOST", "COMMAND", "GROUP", "STATE",
                "PID", "CPU", "RSS MiB", "RESTARTS", "LAST EXIT");
  os << line;
  for (const auto& c : commands_) {
    const CommandStatus s = status(c, now_ms);
    std::string exit_text = "-";
    if (c.reported && c.last.actual_runid != 0 && c.last.pid == 0) {
      const int st = c.last.exit_code;
      exit_text = WIFSIGNALED(st) ? "signal " + std::to_string(WTERMSIG(st)) : "code " + std::to_string(WEXITSTATUS(st));
    }
    // A running process always has resident pages: RSS 0 is a report the deputy sent before it
    // sampled the command (it samples once a second; the report of the start comes at once), shown
    // as "-", not as 0 % and 0 MiB (issue 49: a script's last table showed every command so).
    char cpu[16] = "-", rss[16] = "-";
    if (!c.reported || c.last.pid == 0 || c.last.mem_rss_bytes != 0) {
      std::snprintf(cpu, sizeof cpu, "%.1f%%", c.reported ? 100.0 * c.last.cpu_usage : 0.0);
      std::snprintf(rss, sizeof rss, "%.1f", c.reported ? static_cast<double>(c.last.mem_rss_bytes) / 1048576.0 : 0.0);
    }
    std::snprintf(line, sizeof line, "%-8s %-20s %-14s %-11s %8d %6s %9s %8d  %s\n", c.host.c_str(),
                  c.cmd.command_name.substr(0, 20).c_str(), c.cmd.group.substr(0, 14).c_str(), to_string(s),
                  c.reported ? c.last.pid : 0, cpu, rss, c.restarts, exit_text.c_str());
    os << line;
  }
  return os.str();
}

// ---------------------------------------------------------------------------

ScriptRunner::ScriptRunner(Sheriff& sheriff, const PmdConfig& config, const std::string& script, Log log,
                           double wait_timeout_s)
    : sheriff_(sheriff),
      config_(config),
      log_(std::move(log)),
      wait_timeout_ms_(static_cast<int64_t>(wait_timeout_s * 1000)) {
  const PmdScript* s = config_.find_script(script);
  if (!s) {
    std::string known;
    for (const auto& x : config_.scripts) known += (known.empty() ? "" : ", ") + x.name;
    throw std::invalid_argument("no script named \"" + script + "\" in " + config_.origin +
                                (known.empty() ? " (it has none)" : " (scripts: " + known + ")"));
  }
  stack_.push_back({s, 0});
}

int ScriptRunner::next_timer_ms(int64_t now_ms) const {
  if (status_ != Status::Running) return -1;
  if (wait_until_ms_ >= 0) return static_cast<int>(std::max<int64_t>(0, wait_until_ms_ - now_ms));
  if (waiting_for_ != WaitFor::Nothing && wait_timeout_ms_ > 0)
    return static_cast<int>(std::max<int64_t>(0, wait_since_ms_ + wait_timeout_ms_ - now_ms));
  return -1;
}

ScriptRunner::Status ScriptRunner::step(int64_t now_ms) {
  auto say = [&](const std::string& m) {
    if (log_) log_(m);
  };
  while (status_ == Status::Running) {
    // A wait in progress?
    if (wait_until_ms_ >= 0) {
      if (now_ms < wait_until_ms_) return status_;
      wait_until_ms_ = -1;
    }
    if (waiting_for_ != WaitFor::Nothing) {
      if (!sheriff_.reached(waiting_on_, waiting_for_, now_ms)) {
        if (wait_timeout_ms_ > 0 && now_ms - wait_since_ms_ > wait_timeout_ms_) {
          status_ = Status::Failed;
          error_ = "timed out after " + std::to_string(wait_timeout_ms_ / 1000.0).substr(0, 6) + " s waiting for " +
                   waiting_what_ + " to be " + to_string(waiting_for_);
          say(error_);
        }
        return status_;
      }
      say("  ... " + waiting_what_ + " " + to_string(waiting_for_));
      waiting_for_ = WaitFor::Nothing;
    }
    if (stack_.empty()) {
      status_ = Status::Done;
      return status_;
    }
    Frame& f = stack_.back();
    if (f.next >= f.script->actions.size()) {
      stack_.pop_back();
      continue;
    }
    const ScriptAction& a = f.script->actions[f.next++];
    const std::string what = a.target == TargetKind::Everything ? std::string("everything")
                             : (a.target == TargetKind::Group ? "group \"" : "cmd \"") + a.ident + "\"";
    try {
      switch (a.kind) {
        case ActionKind::Start:
        case ActionKind::Stop:
        case ActionKind::Restart: {
          const auto keys = sheriff_.select(a.target, a.ident);
          const char* verb = a.kind == ActionKind::Start ? "start" : a.kind == ActionKind::Stop ? "stop" : "restart";
          say(std::string(verb) + " " + what);
          if (a.kind == ActionKind::Start) sheriff_.start(keys);
          if (a.kind == ActionKind::Stop) sheriff_.stop(keys);
          if (a.kind == ActionKind::Restart) sheriff_.restart(keys);
          if (a.wait != WaitFor::Nothing) {
            waiting_for_ = a.wait;
            waiting_on_ = keys;
            waiting_what_ = what;
            wait_since_ms_ = now_ms;
            // A restart must first leave the old run: it is reached only once the
            // deputy reports the new run id, which status() checks.
          }
          break;
        }
        case ActionKind::WaitMs:
          say("wait " + std::to_string(a.wait_ms) + " ms");
          wait_until_ms_ = now_ms + a.wait_ms;
          break;
        case ActionKind::WaitStatus:
          say("wait for " + what + " to be " + to_string(a.wait));
          waiting_for_ = a.wait;
          waiting_on_ = sheriff_.select(a.target, a.ident);
          waiting_what_ = what;
          wait_since_ms_ = now_ms;
          break;
        case ActionKind::RunScript: {
          const PmdScript* s = config_.find_script(a.ident);
          if (!s) throw std::invalid_argument("no script named \"" + a.ident + "\"");
          say("run_script \"" + a.ident + "\"");
          stack_.push_back({s, 0});
          break;
        }
      }
    } catch (const std::exception& e) {
      status_ = Status::Failed;
      error_ = config_.origin + ":" + std::to_string(a.line) + ":" + std::to_string(a.column) + ": " + e.what();
      say(error_);
    }
  }
  return status_;
}

}  // namespace aerie::procman
