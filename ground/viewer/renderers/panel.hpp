#pragma once
// The process panel: procman hosts and commands (from the deputies' PMD_INFO2 reports:
// state, CPU, memory, restarts) with start/stop of the selected command, and below them
// every node's heartbeat (STATUS_*: health and last message). Above them, one line each
// for the air-ground door (STATUS_LINK_AIR/_GROUND, tools/link/door_node.hpp: SECURE with
// the key fingerprint per half, INSECURE or a fingerprint mismatch in red) and for the
// autopilot as aerie-mavlink hears it (AUTOPILOT_STATE, docs/mavlink.md).
//
// Start/stop works as a sheriff does: the panel sends orders for that deputy built from its
// latest report, with only the selected command changed -- tagged with the mission key on
// PMD_ORDERS2_SEALED when the viewer has one (aerie-viewer --key; procman/orders_auth.hpp, as a
// keyed aerie-sheriff), else libbot2's plain PMD_ORDERS2, which keyed deputies refuse (the
// panel says so). While an `aerie-sheriff` (not in observer mode) runs, its own orders
// prevail (a keyed deputy follows one sheriff): use it to control.
#include <aerie/autopilot_state_t.hpp>
#include <aerie/process_status_t.hpp>
#include <bot_procman/info2_t.hpp>
#include <bot_procman/orders2_t.hpp>
#include <vtkSmartPointer.h>

#include <atomic>
#include <map>
#include <memory>
#include <mutex>
#include <optional>
#include <string>
#include <vector>

#include "ground/viewer/renderer.hpp"
#include "procman/orders_auth.hpp"
#include "procman/sheriff.hpp"

class vtkRenderer;
class vtkTextActor;

namespace aerie::viewer {

class ProcmanPanel : public Renderer {
 public:
  explicit ProcmanPanel(std::string status_channels = "STATUS_.*", std::string autopilot_channel = "AUTOPILOT_STATE");
  void subscribe(bus::Bus& bus) override;
  void attach(Layout& layout) override;
  bool update() override;
  // '[' / ']' select the previous / next command, 's' starts or stops it.
  bool on_key(const std::string& key) override;
  // The panel's text, `width_chars()` wide (long names and messages abbreviated).
  std::string text() const;
  // Characters of the panel's font that fit its viewport, measured (vtkTextRenderer) at every
  // update; kDefaultChars before the first.
  size_t width_chars() const { return width_chars_; }
  static constexpr size_t kDefaultChars = 46;
  // The drawn text's widest line and the room for it, in pixels (render thread).
  double text_width_px() const;
  double room_px() const;
  // `line` cut to `width` characters (UTF-8 aware), the last one an ellipsis when it was longer.
  static std::string fit(const std::string& line, size_t width);
  // A line drawn above the processes; `alarm` draws it in red.
  struct Line {
    std::string text;
    bool alarm = false;
  };
  // The door and autopilot lines as drawn (empty until a STATUS_LINK_* or AUTOPILOT_STATE).
  std::vector<Line> alerts() const;
  // The door's lines from the two halves' status (nullptr: not heard; age_s: since the last).
  static std::vector<Line> door_lines(const aerie::process_status_t* air, double air_age_s,
                                      const aerie::process_status_t* ground, double ground_age_s);
  // The autopilot's lines from AUTOPILOT_STATE (age_s: since it arrived).
  static std::vector<Line> autopilot_lines(const aerie::autopilot_state_t& s, double age_s);
  // Sends orders that start (or stop) the selected command; false when none is selected.
  bool toggle_selected();
  // Tag the orders as a keyed sheriff (`sheriff` != 0; from the mission key) from now on.
  void use_key(const seal::SecretKey& mission_key, uint32_t sheriff);
  bool keyed() const { return signer_ != nullptr; }
  size_t selected() const { return selected_; }

  // The orders that change only command `sheriff_id` of the reporting deputy: start it
  // (a new run id) or stop it (force_quit); every other command keeps its state.
  static bot_procman::orders2_t orders_for(const bot_procman::info2_t& info, int32_t sheriff_id, bool start,
                                           int64_t utime, const std::string& sheriff_name);

 protected:
  void on_enabled(bool on) override;

 private:
  std::string status_channels_, autopilot_channel_;
  bus::Bus* bus_ = nullptr;
  std::unique_ptr<procman::OrdersSigner> signer_;
  mutable std::mutex m_;
  procman::Sheriff observer_{"aerie-viewer", true};
  std::map<std::string, aerie::process_status_t> nodes_;
  std::map<std::string, int64_t> node_ms_;  // when each status arrived (steady ms)
  std::optional<aerie::autopilot_state_t> autopilot_;
  int64_t autopilot_ms_ = 0;
  uint64_t version_ = 0, seen_ = 0;
  size_t selected_ = 0;
  vtkSmartPointer<vtkTextActor> actor_;
  std::vector<vtkSmartPointer<vtkTextActor>> alert_actors_;  // one per line, all at actor_'s corner
  vtkRenderer* panel_ = nullptr;
  std::atomic<size_t> width_chars_{kDefaultChars};
  size_t measure_chars() const;
};

}  // namespace aerie::viewer
