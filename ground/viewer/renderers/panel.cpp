#include "ground/viewer/renderers/panel.hpp"

#include <vtkRenderer.h>
#include <vtkTextActor.h>
#include <vtkTextProperty.h>

#include <chrono>
#include <cstdio>

#include "common/util/time.hpp"
#include "ground/viewer/layout.hpp"

namespace aerie::viewer {
namespace {
int64_t now_ms() {
  return std::chrono::duration_cast<std::chrono::milliseconds>(std::chrono::steady_clock::now().time_since_epoch())
      .count();
}
}  // namespace

ProcmanPanel::ProcmanPanel(std::string status_channels)
    : Renderer("processes"), status_channels_(std::move(status_channels)) {}

void ProcmanPanel::subscribe(bus::Bus& bus) {
  bus_ = &bus;
  bus.subscribe<aerie::process_status_t>(status_channels_,
                                         [this](const aerie::process_status_t& m, const bus::ReceiveInfo& info) {
                                           std::lock_guard lock(m_);
                                           nodes_[info.channel] = m;
                                           ++version_;
                                         });
  bus.subscribe<bot_procman::info2_t>("PMD_INFO2", [this](const bot_procman::info2_t& m, const bus::ReceiveInfo&) {
    std::lock_guard lock(m_);
    observer_.on_info(m, now_ms());
    ++version_;
  });
}

void ProcmanPanel::attach(Layout& layout) {
  draws_in(layout.panel);
  actor_ = vtkSmartPointer<vtkTextActor>::New();
  actor_->GetTextProperty()->SetFontFamilyToCourier();
  actor_->GetTextProperty()->SetFontSize(11);
  actor_->GetTextProperty()->SetColor(0.85, 0.9, 0.85);
  actor_->GetTextProperty()->SetVerticalJustificationToTop();
  actor_->SetTextScaleModeToNone();
  actor_->GetPositionCoordinate()->SetCoordinateSystemToNormalizedViewport();
  actor_->GetPositionCoordinate()->SetValue(0.02, 0.97);
  actor_->SetInput("processes: waiting for PMD_INFO2 and STATUS_*");
  layout.panel->AddActor2D(actor_);
}

bot_procman::orders2_t ProcmanPanel::orders_for(const bot_procman::info2_t& info, int32_t sheriff_id, bool start,
                                                int64_t utime, const std::string& sheriff_name) {
  bot_procman::orders2_t o{};
  o.utime = utime;
  o.host = info.host;
  o.sheriff_name = sheriff_name;
  for (const auto& dc : info.cmds) {
    bot_procman::sheriff_cmd2_t sc{};
    sc.cmd = dc.cmd;
    sc.sheriff_id = dc.sheriff_id;
    sc.desired_runid = dc.actual_runid;  // unchanged: keep running or stopped
    sc.force_quit = 0;
    if (dc.sheriff_id == sheriff_id) {
      if (start)
        sc.desired_runid = dc.actual_runid + 1;  // a new run
      else
        sc.force_quit = 1;
    }
    o.cmds.push_back(sc);
  }
  o.ncmds = static_cast<int32_t>(o.cmds.size());
  o.num_options = 0;
  return o;
}

bool ProcmanPanel::toggle_selected() {
  bot_procman::orders2_t orders;
  {
    std::lock_guard lock(m_);
    const auto& cmds = observer_.commands();
    if (!bus_ || cmds.empty()) return false;
    const auto& c = cmds[selected_ % cmds.size()];
    if (!c.reported) return false;
    // The deputy's latest report of all its commands, as the observer keeps them.
    bot_procman::info2_t report{};
    report.host = c.host;
    for (const auto& other : cmds)
      if (other.host == c.host && other.reported) report.cmds.push_back(other.last);
    const bool running = c.last.pid != 0;
    orders = orders_for(report, c.sheriff_id, !running, util::wall_utime(), "aerie-viewer");
  }
  bus_->publish("PMD_ORDERS2", orders);
  return true;
}

bool ProcmanPanel::on_key(const std::string& key) {
  std::lock_guard lock(m_);
  const size_t n = observer_.commands().size();
  if (key == "bracketright" || key == "]") {
    if (n) selected_ = (selected_ + 1) % n;
  } else if (key == "bracketleft" || key == "[") {
    if (n) selected_ = (selected_ + n - 1) % n;
  } else if (key == "s") {
    m_.unlock();
    const bool sent = toggle_selected();
    m_.lock();
    return sent;
  } else {
    return false;
  }
  ++version_;
  return true;
}

std::string ProcmanPanel::text() const {
  std::lock_guard lock(m_);
  const int64_t now = now_ms();
  std::string s;
  char line[200];
  for (const auto& [host, dv] : observer_.deputies()) {
    std::snprintf(line, sizeof line, "host %-8.8s %-4s cpu %5.1f%% mem %6.0f MiB\n", host.c_str(),
                  observer_.deputy_alive(host, now) ? "ok" : "LOST", 100.0 * dv.info.cpu_load, dv.used_mib());
    s += line;
  }
  if (!observer_.commands().empty()) s += "  command          state       cpu    rss  rst\n";
  const auto& cmds = observer_.commands();
  for (size_t i = 0; i < cmds.size(); ++i) {
    const auto& c = cmds[i];
    std::snprintf(line, sizeof line, "%s %-16.16s %-10.10s %5.1f%% %5.0fM %3d\n", i == selected_ % cmds.size() ? ">" : " ",
                  c.cmd.command_name.c_str(), procman::to_string(observer_.status(c, now)),
                  c.reported ? 100.0 * c.last.cpu_usage : 0.0,
                  c.reported ? static_cast<double>(c.last.mem_rss_bytes) / 1048576.0 : 0.0, c.restarts);
    s += line;
  }
  if (!cmds.empty()) s += "  [ ] select   s start/stop\n";
  if (!nodes_.empty()) s += "\nnode          health\n";
  static const char* health[] = {"ok", "WARN", "ERROR"};
  for (const auto& [channel, m] : nodes_) {
    std::snprintf(line, sizeof line, "%-13.13s %-5s %.30s\n", m.node.c_str(),
                  health[std::min<int>(std::max<int>(m.health, 0), 2)], m.message.c_str());
    s += line;
  }
  return s.empty() ? "processes: waiting for PMD_INFO2 and STATUS_*" : s;
}

bool ProcmanPanel::update() {
  {
    std::lock_guard lock(m_);
    if (version_ == seen_) return false;
    seen_ = version_;
  }
  actor_->SetInput(text().c_str());
  return true;
}

void ProcmanPanel::on_enabled(bool on) {
  if (actor_) actor_->SetVisibility(on);
}

}  // namespace aerie::viewer
