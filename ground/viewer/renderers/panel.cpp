#include "ground/viewer/renderers/panel.hpp"

#include "procman/channels.hpp"

#include <vtkRenderWindow.h>
#include <vtkRenderer.h>
#include <vtkStdString.h>
#include <vtkTextRenderer.h>
#include <vtkTextActor.h>
#include <vtkTextProperty.h>

#include <algorithm>
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

// A status older than this is shown as silent (door halves and aerie-mavlink send at 1 Hz).
constexpr double kSilentS = 5.0;

// One door half as its status tells it (tools/link/door_node.cpp refresh_status/status_line):
// counters "secure" (1/0) and "epoch"; the fingerprint only in the message
// ("SECURE key <fingerprint> epoch ...").
struct DoorHalfState {
  bool secure = false;
  std::string fingerprint;
  int64_t epoch = -1;
};
DoorHalfState door_half(const aerie::process_status_t& m) {
  DoorHalfState h;
  bool has_secure = false;
  for (int i = 0; i < m.ncounters && i < static_cast<int>(std::min(m.counter_names.size(), m.counter_values.size())); ++i) {
    const std::string& n = m.counter_names[i];
    if (n == "secure") {
      h.secure = m.counter_values[i] != 0;
      has_secure = true;
    } else if (n == "epoch") {
      h.epoch = m.counter_values[i];
    }
  }
  if (!has_secure) h.secure = m.message.rfind("SECURE", 0) == 0;
  const auto k = m.message.find("key ");
  if (h.secure && k != std::string::npos) {
    const auto b = k + 4;
    h.fingerprint = m.message.substr(b, m.message.find_first_of(" ;", b) - b);
  }
  if (h.secure && h.fingerprint.empty()) h.fingerprint = "?";
  return h;
}

std::string silent(double age_s) {
  return age_s > kSilentS ? " silent " + std::to_string(static_cast<int64_t>(age_s)) + " s" : "";
}

// "3fa2:1b4c:d5e6:f789" -> "3fa2:…": the summary line fits the panel; the halves' lines show it whole.
std::string short_fingerprint(const std::string& fp) {
  const auto colon = fp.find(':');
  return colon == std::string::npos ? fp : fp.substr(0, colon + 1) + "\u2026";
}
}  // namespace

ProcmanPanel::ProcmanPanel(std::string status_channels, std::string autopilot_channel)
    : Renderer("processes"),
      status_channels_(std::move(status_channels)),
      autopilot_channel_(std::move(autopilot_channel)) {}

std::vector<ProcmanPanel::Line> ProcmanPanel::door_lines(const aerie::process_status_t* air, double air_age_s,
                                                         const aerie::process_status_t* ground,
                                                         double ground_age_s) {
  if (!air && !ground) return {};
  std::optional<DoorHalfState> a, g;
  if (air) a = door_half(*air);
  if (ground) g = door_half(*ground);
  const bool air_insecure = a && !a->secure, ground_insecure = g && !g->secure;
  std::vector<Line> lines;
  if (air_insecure || ground_insecure) {
    const char* which = air_insecure && ground_insecure ? "both halves" : air_insecure ? "air half" : "ground half";
    lines.push_back({std::string("door: INSECURE (") + which + ": no key)", true});
  } else if (a && g && a->fingerprint != g->fingerprint) {
    lines.push_back({"door: KEY MISMATCH (air != ground)", true});
  } else if (a && g) {
    lines.push_back({"door: SECURE " + short_fingerprint(a->fingerprint) + " (air and ground agree)", false});
  } else {
    lines.push_back({"door: SECURE " + short_fingerprint((a ? a : g)->fingerprint) + (a ? " (ground" : " (air") +
                         " not heard)",
                     false});
  }
  auto half = [&](const char* name, const std::optional<DoorHalfState>& h, double age_s) {
    char line[160];
    if (!h)
      std::snprintf(line, sizeof line, "  %-6s not heard", name);
    else if (!h->secure)
      std::snprintf(line, sizeof line, "  %-6s INSECURE%s", name, silent(age_s).c_str());
    else
      std::snprintf(line, sizeof line, "  %-6s SECURE %s ep %lld%s", name, h->fingerprint.c_str(),
                    static_cast<long long>(h->epoch), silent(age_s).c_str());
    const bool mismatch = h && h->secure && a && g && a->secure && g->secure && a->fingerprint != g->fingerprint;
    lines.push_back({line, (h && !h->secure) || mismatch || (h && age_s > kSilentS)});
  };
  half("air", a, air_age_s);
  half("ground", g, ground_age_s);
  return lines;
}

std::vector<ProcmanPanel::Line> ProcmanPanel::autopilot_lines(const aerie::autopilot_state_t& s, double age_s) {
  using A = aerie::autopilot_state_t;
  std::vector<Line> lines;
  if (s.link == A::LINK_NONE) {
    lines.push_back({"autopilot: no heartbeat yet" + silent(age_s), age_s > kSilentS});
  } else {
    const char* ap = s.autopilot == A::AUTOPILOT_PX4 ? "PX4" : s.autopilot == A::AUTOPILOT_ARDUPILOT ? "ArduPilot" : "autopilot";
    const bool lost = s.link != A::LINK_OK;
    lines.push_back({std::string("autopilot: ") + ap + " " + (s.mode.empty() ? "?" : s.mode) + " " +
                         (s.armed ? "ARMED" : "disarmed") + " " + (s.signing ? "signed" : "UNSIGNED"),
                     !s.signing});
    lines.push_back({std::string("  link ") + (lost ? "LOST" : "OK") + silent(age_s), lost || age_s > kSilentS});
  }
  if (!s.last_command.empty()) {
    const std::string& r = s.last_result;
    const bool refused = !r.empty() && r.rfind("ACCEPTED", 0) != 0 && r.rfind("IN_PROGRESS", 0) != 0;
    const std::string cmd = s.last_command.rfind("MAV_CMD_", 0) == 0 ? s.last_command.substr(8) : s.last_command;
    lines.push_back({"  " + cmd + ": " + (r.empty() ? "no answer yet" : r), refused});
  }
  return lines;
}

std::vector<ProcmanPanel::Line> ProcmanPanel::alerts() const {
  std::lock_guard lock(m_);
  const int64_t now = now_ms();
  auto find = [&](const char* channel, double& age_s) -> const aerie::process_status_t* {
    const auto it = nodes_.find(channel);
    if (it == nodes_.end()) return nullptr;
    age_s = static_cast<double>(now - node_ms_.at(channel)) * 1e-3;
    return &it->second;
  };
  double air_age = 0, ground_age = 0;
  const auto* air = find("STATUS_LINK_AIR", air_age);
  const auto* ground = find("STATUS_LINK_GROUND", ground_age);
  std::vector<Line> lines = door_lines(air, air_age, ground, ground_age);
  if (autopilot_) {
    auto ap = autopilot_lines(*autopilot_, static_cast<double>(now - autopilot_ms_) * 1e-3);
    lines.insert(lines.end(), ap.begin(), ap.end());
  }
  return lines;
}

void ProcmanPanel::subscribe(bus::Bus& bus) {
  bus_ = &bus;
  bus.subscribe<aerie::process_status_t>(status_channels_,
                                         [this](const aerie::process_status_t& m, const bus::ReceiveInfo& info) {
                                           std::lock_guard lock(m_);
                                           nodes_[info.channel] = m;
                                           node_ms_[info.channel] = now_ms();
                                           ++version_;
                                         });
  bus.subscribe<aerie::autopilot_state_t>(autopilot_channel_,
                                          [this](const aerie::autopilot_state_t& m, const bus::ReceiveInfo&) {
                                            std::lock_guard lock(m_);
                                            autopilot_ = m;
                                            autopilot_ms_ = now_ms();
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
  actor_->GetTextProperty()->SetFontSize(10);
  actor_->GetTextProperty()->SetColor(0.85, 0.9, 0.85);
  actor_->GetTextProperty()->SetVerticalJustificationToTop();
  actor_->SetTextScaleModeToNone();
  actor_->GetPositionCoordinate()->SetCoordinateSystemToNormalizedViewport();
  actor_->GetPositionCoordinate()->SetValue(0.02, 0.97);
  actor_->SetInput("processes: waiting for PMD_INFO2 and STATUS_*");
  layout.panel->AddActor2D(actor_);
  panel_ = layout.panel;
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
  if (signer_) {
    const auto sealed = signer_->sign(orders, util::wall_utime());
    bus_->publish_raw(procman::kSealedOrdersChannel, sealed.data(), sealed.size());
  } else {
    bus_->publish("PMD_ORDERS2", orders);
  }
  return true;
}

void ProcmanPanel::use_key(const seal::SecretKey& mission_key, uint32_t sheriff) {
  std::lock_guard lock(m_);
  signer_ = std::make_unique<procman::OrdersSigner>(mission_key, sheriff);
  ++version_;
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

std::string ProcmanPanel::fit(const std::string& line, size_t width) {
  // Count UTF-8 characters (not continuation bytes).
  size_t chars = 0, cut = line.size();
  for (size_t i = 0; i < line.size(); ++i) {
    if ((static_cast<unsigned char>(line[i]) & 0xC0) == 0x80) continue;
    if (chars + 1 == width) cut = i;  // where the ellipsis goes if the line is too long
    if (++chars > width) return line.substr(0, cut) + "\u2026";
  }
  return line;
}

std::string ProcmanPanel::text() const {
  std::lock_guard lock(m_);
  const int64_t now = now_ms();
  const size_t W = std::max<size_t>(width_chars_, 24);
  std::string s;
  auto add = [&](const std::string& line) { s += fit(line, W) + "\n"; };
  char line[400];
  for (const auto& [host, dv] : observer_.deputies()) {
    std::snprintf(line, sizeof line, "host %-8.8s %-4s cpu %5.1f%% mem %6.0f MiB", host.c_str(),
                  observer_.deputy_alive(host, now) ? "ok" : "LOST", 100.0 * dv.info.cpu_load, dv.used_mib());
    add(line);
  }
  // Columns: "> " name, state (10), cpu (6), rss (6), restarts (3): the name gets what is left, 6..16.
  const int name_w = static_cast<int>(std::clamp<size_t>(W > 31 ? W - 31 : 0, 6, 16));
  const auto& cmds = observer_.commands();
  if (!cmds.empty()) {
    std::snprintf(line, sizeof line, "  %-*s %-10s %6s %6s %3s", name_w, "command", "state", "cpu", "rss", "rst");
    add(line);
  }
  for (size_t i = 0; i < cmds.size(); ++i) {
    const auto& c = cmds[i];
    std::snprintf(line, sizeof line, "%s %-*.*s %-10.10s %5.1f%% %5.0fM %3d", i == selected_ % cmds.size() ? ">" : " ",
                  name_w, name_w, c.cmd.command_name.c_str(), procman::to_string(observer_.status(c, now)),
                  c.reported ? 100.0 * c.last.cpu_usage : 0.0,
                  c.reported ? static_cast<double>(c.last.mem_rss_bytes) / 1048576.0 : 0.0, c.restarts);
    add(line);
  }
  if (!cmds.empty()) {
    add("  [ ] select  s start/stop" + std::string(signer_ ? " (keyed orders)" : ""));
    if (!signer_) add("  plain orders: keyed deputies refuse (--key)");
  }
  if (!nodes_.empty()) s += "\nnode          health\n";
  static const char* health[] = {"ok", "WARN", "ERROR"};
  for (const auto& [channel, m] : nodes_) {
    // The message gets the rest of the line; fit() marks a cut one.
    std::snprintf(line, sizeof line, "%-13.13s %-5s %s", m.node.c_str(),
                  health[std::min<int>(std::max<int>(m.health, 0), 2)], m.message.c_str());
    add(line);
  }
  return s.empty() ? "processes: waiting for PMD_INFO2 and STATUS_*" : s;
}

size_t ProcmanPanel::measure_chars() const {
  if (!panel_ || !panel_->GetRenderWindow()) return kDefaultChars;
  const std::string probe(40, 'M');
  int bb[4] = {0, 0, 0, 0};
  vtkTextRenderer* tr = vtkTextRenderer::GetInstance();
  auto bold = vtkSmartPointer<vtkTextProperty>::New();
  bold->ShallowCopy(actor_->GetTextProperty());
  bold->SetBold(true);  // alarm lines are bold: never narrower
  if (!tr || !tr->GetBoundingBox(bold.Get(), vtkStdString(probe), bb, panel_->GetRenderWindow()->GetDPI()) || bb[1] <= bb[0])
    return kDefaultChars;
  const double char_px = static_cast<double>(bb[1] - bb[0] + 1) / static_cast<double>(probe.size());
  return static_cast<size_t>(std::max(0.0, room_px() / char_px));
}

double ProcmanPanel::room_px() const {
  if (!panel_ || !panel_->GetRenderWindow()) return 0;
  double vp[4];
  panel_->GetViewport(vp);
  const double x0 = actor_->GetPositionCoordinate()->GetValue()[0];  // normalized viewport
  return (vp[2] - vp[0]) * panel_->GetRenderWindow()->GetSize()[0] * (1.0 - x0 - 0.01);
}

double ProcmanPanel::text_width_px() const {
  if (!panel_ || !panel_->GetRenderWindow()) return 0;
  vtkTextRenderer* tr = vtkTextRenderer::GetInstance();
  double widest = 0;
  std::vector<vtkTextActor*> actors{actor_.Get()};
  for (const auto& a : alert_actors_) actors.push_back(a.Get());
  for (auto* a : actors) {
    if (!a->GetInput() || !*a->GetInput()) continue;
    int bb[4] = {0, 0, 0, 0};
    if (tr->GetBoundingBox(a->GetTextProperty(), vtkStdString(a->GetInput()), bb, panel_->GetRenderWindow()->GetDPI()))
      widest = std::max(widest, static_cast<double>(bb[1] - bb[0] + 1));
  }
  return widest;
}

bool ProcmanPanel::update() {
  const size_t chars = measure_chars();  // the window may have been resized
  {
    std::lock_guard lock(m_);
    if (version_ == seen_ && chars == width_chars_) return false;
    seen_ = version_;
    width_chars_ = chars;
  }
  // Each alert line is its own actor (its own colour) at the panel's corner, pushed down by
  // blank lines; the processes follow below them.
  const std::vector<Line> lines = alerts();
  std::string pad;
  for (size_t i = 0; i < lines.size(); ++i) {
    if (i == alert_actors_.size()) {
      auto a = vtkSmartPointer<vtkTextActor>::New();
      a->GetTextProperty()->ShallowCopy(actor_->GetTextProperty());
      a->SetTextScaleModeToNone();
      a->GetPositionCoordinate()->SetCoordinateSystemToNormalizedViewport();
      a->GetPositionCoordinate()->SetValue(actor_->GetPositionCoordinate()->GetValue());
      a->SetVisibility(actor_->GetVisibility());
      panel_->AddActor2D(a);
      alert_actors_.push_back(a);
    }
    auto* p = alert_actors_[i]->GetTextProperty();
    p->SetBold(lines[i].alarm);
    if (lines[i].alarm) p->SetColor(1.0, 0.25, 0.2);
    else p->SetColor(0.55, 0.95, 0.55);
    alert_actors_[i]->SetInput((pad + fit(lines[i].text, width_chars_)).c_str());
    pad += " \n";
  }
  for (size_t i = lines.size(); i < alert_actors_.size(); ++i) alert_actors_[i]->SetInput("");
  const std::string body = text();
  if (!lines.empty() && body.front() != '\n') pad += " \n";  // one blank line between them
  actor_->SetInput((pad + body).c_str());
  return true;
}

void ProcmanPanel::on_enabled(bool on) {
  if (actor_) actor_->SetVisibility(on);
  for (auto& a : alert_actors_) a->SetVisibility(on);
}

}  // namespace aerie::viewer
