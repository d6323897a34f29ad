#pragma once
// Drives an in-process Deputy for tests: builds orders, runs its loop until a
// condition holds, and keeps everything the commands printed.
#include <poll.h>
#include <signal.h>

#include <chrono>
#include <functional>
#include <string>
#include <utility>
#include <vector>

#include "common/util/time.hpp"
#include "procman/deputy.hpp"

namespace aerie::procman::test {

struct CmdSpec {
  int32_t id = 1;
  std::string name = "cmd";
  std::string exec;
  int32_t runid = 1;
  bool force_quit = false;
  bool auto_respawn = false;
  int stop_signal = SIGTERM;
  double stop_time_allowed = 2.0;
  std::string group;
};

inline bot_procman::sheriff_cmd2_t sheriff_cmd(const CmdSpec& s) {
  bot_procman::sheriff_cmd2_t c;
  c.cmd.exec_str = s.exec;
  c.cmd.command_name = s.name;
  c.cmd.group = s.group;
  c.cmd.auto_respawn = s.auto_respawn;
  c.cmd.stop_signal = static_cast<int8_t>(s.stop_signal);
  c.cmd.stop_time_allowed = static_cast<float>(s.stop_time_allowed);
  c.cmd.num_options = 0;
  c.desired_runid = s.runid;
  c.force_quit = s.force_quit ? 1 : 0;
  c.sheriff_id = s.id;
  return c;
}

inline bot_procman::orders2_t make_orders(const std::string& host, const std::vector<CmdSpec>& cmds,
                                          int64_t age_us = 0) {
  bot_procman::orders2_t o;
  o.utime = aerie::util::wall_utime() - age_us;
  o.host = host;
  o.sheriff_name = "test-sheriff";
  for (const auto& c : cmds) o.cmds.push_back(sheriff_cmd(c));
  o.ncmds = static_cast<int32_t>(o.cmds.size());
  o.num_options = 0;
  return o;
}

class DeputyHarness {
 public:
  explicit DeputyHarness(DeputyOptions opts = default_options())
      : deputy(std::move(opts), [this](int32_t id, const std::string& t) {
          output.push_back({id, t, std::chrono::steady_clock::now()});
        }) {}

  static DeputyOptions default_options() {
    DeputyOptions o;
    o.name = "testhost";
    o.respawn_min_ms = 50;
    o.respawn_max_ms = 400;
    return o;
  }

  Deputy::OrdersResult order(const std::vector<CmdSpec>& cmds, int64_t age_us = 0) {
    return deputy.handle_orders(make_orders(deputy.name(), cmds, age_us), aerie::util::wall_utime());
  }

  // Runs the deputy's loop until pred() or the timeout; returns pred().
  bool run_until(const std::function<bool()>& pred, int timeout_ms = 5000) {
    const auto until = std::chrono::steady_clock::now() + std::chrono::milliseconds(timeout_ms);
    while (!pred()) {
      if (std::chrono::steady_clock::now() >= until) return false;
      std::vector<pollfd> fds;
      for (int fd : deputy.wait_fds()) fds.push_back({fd, POLLIN, 0});
      int t = deputy.next_timer_ms();
      t = t < 0 ? 20 : std::min(t, 20);
      poll(fds.data(), fds.size(), t);
      deputy.step();
    }
    return true;
  }
  void run_for(int ms) {
    run_until([] { return false; }, ms);
  }

  const Deputy::Command* cmd(int32_t id) const {
    const auto it = deputy.commands().find(id);
    return it == deputy.commands().end() ? nullptr : &it->second;
  }
  std::string text(int32_t id) const {
    std::string s;
    for (const auto& o : output)
      if (o.id == id) s += o.text;
    return s;
  }

  struct Output {
    int32_t id;
    std::string text;
    std::chrono::steady_clock::time_point at;
  };
  std::vector<Output> output;
  Deputy deputy;
};

}  // namespace aerie::procman::test
