#include "common/bus/node.hpp"

#include <spdlog/spdlog.h>

#include <atomic>
#include <csignal>

namespace aerie::bus {
namespace {
std::atomic<bool> g_stop{false};
extern "C" void on_signal(int) { g_stop = true; }
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

void run(Bus& bus, StatusReporter& status, const std::function<bool()>& idle, int poll_ms) {
  install_stop_handlers();
  while (!g_stop) {
    bus.handle(poll_ms);
    if (idle) {
      try {
        if (!idle()) break;
      } catch (const std::exception& e) {
        status.count("loop_errors");
        status.error(e.what());
        spdlog::error("{}", e.what());
      }
    }
    status.tick();
  }
  status.publish_now();
}

}  // namespace aerie::bus
