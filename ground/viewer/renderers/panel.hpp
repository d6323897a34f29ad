#pragma once
// The text panel: processes and their health. Heartbeats of every node (STATUS_*:
// health, last message, CPU-relevant counters) — and, from procman deputies, hosts and
// commands with state, CPU and memory.
#include <aerie/process_status_t.hpp>
#include <vtkSmartPointer.h>

#include <map>
#include <mutex>

#include "ground/viewer/renderer.hpp"

class vtkTextActor;

namespace aerie::viewer {

class ProcmanPanel : public Renderer {
 public:
  explicit ProcmanPanel(std::string status_channels = "STATUS_.*");
  void subscribe(bus::Bus& bus) override;
  void attach(Layout& layout) override;
  bool update() override;
  std::string text() const;

 protected:
  void on_enabled(bool on) override;

 private:
  std::string status_channels_;
  mutable std::mutex m_;
  std::map<std::string, aerie::process_status_t> nodes_;
  uint64_t version_ = 0, seen_ = 0;
  vtkSmartPointer<vtkTextActor> actor_;
};

}  // namespace aerie::viewer
