#pragma once
// The process panel: procman hosts and commands (from the deputies' PMD_INFO2 reports:
// state, CPU, memory, restarts) with start/stop of the selected command, and below them
// every node's heartbeat (STATUS_*: health and last message).
//
// Start/stop works as a libbot2 sheriff does: the panel sends PMD_ORDERS2 for that
// deputy built from its latest report, with only the selected command changed. While an
// `aerie-sheriff` (not in observer mode) runs, its own orders prevail: use it to control.
#include <aerie/process_status_t.hpp>
#include <bot_procman/info2_t.hpp>
#include <bot_procman/orders2_t.hpp>
#include <vtkSmartPointer.h>

#include <map>
#include <memory>
#include <mutex>

#include "ground/viewer/renderer.hpp"
#include "procman/sheriff.hpp"

class vtkTextActor;

namespace aerie::viewer {

class ProcmanPanel : public Renderer {
 public:
  explicit ProcmanPanel(std::string status_channels = "STATUS_.*");
  void subscribe(bus::Bus& bus) override;
  void attach(Layout& layout) override;
  bool update() override;
  // '[' / ']' select the previous / next command, 's' starts or stops it.
  bool on_key(const std::string& key) override;
  std::string text() const;
  // Sends orders that start (or stop) the selected command; false when none is selected.
  bool toggle_selected();
  size_t selected() const { return selected_; }

  // The orders that change only command `sheriff_id` of the reporting deputy: start it
  // (a new run id) or stop it (force_quit); every other command keeps its state.
  static bot_procman::orders2_t orders_for(const bot_procman::info2_t& info, int32_t sheriff_id, bool start,
                                           int64_t utime, const std::string& sheriff_name);

 protected:
  void on_enabled(bool on) override;

 private:
  std::string status_channels_;
  bus::Bus* bus_ = nullptr;
  mutable std::mutex m_;
  procman::Sheriff observer_{"aerie-viewer", true};
  std::map<std::string, aerie::process_status_t> nodes_;
  uint64_t version_ = 0, seen_ = 0;
  size_t selected_ = 0;
  vtkSmartPointer<vtkTextActor> actor_;
};

}  // namespace aerie::viewer
