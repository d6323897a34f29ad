#pragma once
// The shape of a node (docs/architecture.md, "Nodes"): a name, a status reporter on
// STATUS_<NAME>, subscriptions that end with the node, and one periodic step, run by one
// main loop that stops on SIGINT/SIGTERM.
//
//   class Bridge final : public bus::Node {
//    public:
//     explicit Bridge(bus::Bus& bus) : Node(bus, "mavlink") {
//       subscribe<aerie::control_cmd_t>(channels::kCtrlCmd, [this](const auto& m, const auto&) { ... });
//     }
//     void tick(int64_t now_us) override { ... }   // between messages, at least every poll period
//   };
//   bus::run(bridge);
//
// A handler captures `this`, so a node's subscriptions must not outlive it: the Node removes
// every subscription it made when it is destroyed (as LCM's own subscribe/unsubscribe pair).
#include <cstdint>
#include <functional>
#include <string>
#include <utility>
#include <vector>

#include "common/bus/bus.hpp"
#include "common/bus/status.hpp"

namespace aerie::bus {

// Installs SIGINT/SIGTERM handlers that set the stop flag (idempotent).
void install_stop_handlers();
bool stop_requested();
void request_stop();

class Node {
 public:
  Node(Bus& bus, std::string name, double status_period_s = 1.0);
  Node(const Node&) = delete;
  Node& operator=(const Node&) = delete;
  virtual ~Node();

  // The periodic step: called by run() between messages (at least every poll period) with the
  // node's time in microseconds (the wall clock live; the caller's clock in lock-step tests).
  // An exception is counted in status ("loop_errors") and logged; the loop goes on.
  virtual void tick(int64_t now_us) { (void)now_us; }
  // Whether run() should go on (a node that has finished its work returns false).
  virtual bool running() const { return true; }

  const std::string& name() const { return name_; }
  Bus& bus() { return bus_; }
  StatusReporter& status() { return status_; }
  const StatusReporter& status() const { return status_; }

 protected:
  template <typename Msg>
  Subscription& subscribe(const std::string& channel, typename TypedSubscription<Msg>::Handler handler,
                          int queue_capacity = 30) {
    return own(bus_.subscribe<Msg>(channel, std::move(handler), queue_capacity));
  }
  template <typename Msg>
  Subscription& subscribe_queued(const std::string& channel, typename TypedSubscription<Msg>::Handler handler,
                                 size_t capacity, Overflow overflow = Overflow::kDropOldest) {
    return own(bus_.subscribe_queued<Msg>(channel, std::move(handler), capacity, overflow));
  }
  Subscription& subscribe_raw(const std::string& channel_regex, RawSubscription::Handler handler,
                              int queue_capacity = 30) {
    return own(bus_.subscribe_raw(channel_regex, std::move(handler), queue_capacity));
  }
  // Ends one of this node's subscriptions now (not from inside a handler).
  void unsubscribe(const Subscription& sub);

 private:
  Subscription& own(Subscription& sub) {
    subs_.push_back(&sub);
    return sub;
  }

  Bus& bus_;
  std::string name_;
  StatusReporter status_;
  std::vector<const Subscription*> subs_;
};

// Runs `node` until stop is requested or node.running() turns false: handles messages, calls
// tick(wall clock) between them, publishes status; publishes a last status on the way out.
void run(Node& node, int poll_ms = 50);

// The older loop of the nodes not yet on Node: `idle` between messages (exceptions counted
// in `status` as "loop_errors"), until stop is requested or `idle` returns false.
void run(Bus& bus, StatusReporter& status, const std::function<bool()>& idle = {}, int poll_ms = 50);

}  // namespace aerie::bus
