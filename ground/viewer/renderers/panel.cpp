#include "ground/viewer/renderers/panel.hpp"

#include <vtkRenderer.h>
#include <vtkTextActor.h>
#include <vtkTextProperty.h>

#include <cstdio>

#include "ground/viewer/layout.hpp"

namespace aerie::viewer {

ProcmanPanel::ProcmanPanel(std::string status_channels)
    : Renderer("processes"), status_channels_(std::move(status_channels)) {}

void ProcmanPanel::subscribe(bus::Bus& bus) {
  bus.subscribe<aerie::process_status_t>(status_channels_,
                                         [this](const aerie::process_status_t& m, const bus::ReceiveInfo& info) {
                                           std::lock_guard lock(m_);
                                           nodes_[info.channel] = m;
                                           ++version_;
                                         });
}

void ProcmanPanel::attach(Layout& layout) {
  actor_ = vtkSmartPointer<vtkTextActor>::New();
  actor_->GetTextProperty()->SetFontFamilyToCourier();
  actor_->GetTextProperty()->SetFontSize(11);
  actor_->GetTextProperty()->SetColor(0.85, 0.9, 0.85);
  actor_->GetTextProperty()->SetVerticalJustificationToTop();
  actor_->SetTextScaleModeToNone();
  actor_->GetPositionCoordinate()->SetCoordinateSystemToNormalizedViewport();
  actor_->GetPositionCoordinate()->SetValue(0.02, 0.97);
  actor_->SetInput("processes: waiting for STATUS_* heartbeats");
  layout.panel->AddActor2D(actor_);
}

std::string ProcmanPanel::text() const {
  std::lock_guard lock(m_);
  std::string s = "node          host      health\n";
  static const char* health[] = {"ok", "WARN", "ERROR"};
  for (const auto& [channel, m] : nodes_) {
    char line[160];
    std::snprintf(line, sizeof(line), "%-13.13s %-9.9s %-6s %s\n", m.node.c_str(), m.host.c_str(),
                  health[std::min<int>(std::max<int>(m.health, 0), 2)], m.message.substr(0, 40).c_str());
    s += line;
  }
  return s;
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
