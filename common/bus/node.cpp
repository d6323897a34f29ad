#include "common/bus/node.hpp"

#include <spdlog/spdlog.h>

#include <algorithm>
#include <atomic>
#include <csignal>

#include "common/util/time.hpp"

namespace aerie::bus {
namespace {
std::atomic<bool> g_stop{false};
extern "C" void on_signal(int) { g_stop = true; }

// One step of a loop's idle work, its exception counted and logged instead of ending the node.
template <typename F>
void guarded(StatusReporter& status, F&& step) {
  try {
    step();
  } catch (const std::exception& e) {
    status.count("loop_errors");
    status.error(e.what());
    spdlog::error("{}", e.what());
  }
}
}  // namespace

void install_stop_handlers() {
  struct sigaction sa {};
  sa.sa_handler = on_signal;
  sigemptyset(&sa.sa_mask);
  sigaction(SIGINT, &sa, nullptr);
  sigaction(SIGTERM, &sa, nullptr);
}

bool stop_requested() { return g_stop; }
void request_stop() { g_stop = true; }

Node::Node(Bus& bus, std::string name, double status_period_s)
    : bus_(bus), name_(std::move(name)), status_(bus, name_, status_period_s) {}

Node::~Node() {
  for (const Subscription* s : subs_) bus_.unsubscribe(*s);
}

void Node::unsubscribe(const Subscription& sub) {
  const auto it = std::find(subs_.begin(), subs_.end(), &sub);
  if (it == subs_.end()) throw std::invalid_argument(name_ + ": " + sub.channel() + " is not a subscription of this node");
  bus_.unsubscribe(sub);
  subs_.erase(it);
}

void run(Node& node, int poll_ms) {
  install_stop_handlers();
  while (!g_stop && node.running()) {
    node.bus().handle(poll_ms);
    guarded(node.status(), [&] { node.tick(util::wall_utime()); });
    node.status().tick();
  }
  node.status().publish_now();
}

void run(Bus& bus, StatusReporter& status, const std::function<bool()>& idle, int poll_ms) {
  install_stop_handlers();
  bool go_on = true;
  while (!g_stop && go_on) {
    bus.handle(poll_ms);
    if (idle) guarded(status, [&] { go_on = idle(); });
    status.tick();
  }
  status.publish_now();
}

}  // namespace aerie::bus
