#pragma once
// The main loop every node shares: handle LCM messages until SIGINT/SIGTERM, call
// `idle` between messages (at least every poll_ms), tick the status reporter.
#include <functional>

#include "common/bus/bus.hpp"
#include "common/bus/status.hpp"

namespace aerie::bus {

// Installs SIGINT/SIGTERM handlers that set the stop flag (idempotent).
void install_stop_handlers();
bool stop_requested();
void request_stop();

// Runs until stop is requested or `idle` returns false. Exceptions thrown by `idle`
// are counted in `status` ("loop_errors") and logged; the loop goes on.
void run(Bus& bus, StatusReporter& status, const std::function<bool()>& idle = {}, int poll_ms = 50);

}  // namespace aerie::bus
