#include "ground/viewer/viewer.hpp"

#include <spdlog/spdlog.h>
#include <vtkCallbackCommand.h>
#include <vtkCamera.h>
#include <vtkCommand.h>
#include <vtkInteractorStyleTrackballCamera.h>
#include <vtkObjectFactory.h>
#include <vtkPNGWriter.h>
#include <vtkRenderWindowInteractor.h>
#include <vtkTextActor.h>
#include <vtkTextProperty.h>
#include <vtkWindowToImageFilter.h>

#include <opencv2/imgproc.hpp>

#include "air/track/factory.hpp"
#include "air/nav/nav_config.hpp"
#include "air/track/node/default_tracker.hpp"
#include "common/bus/node.hpp"
#include "common/util/heap.hpp"
#include "common/util/time.hpp"
#include "ground/viewer/keys.hpp"
#include "ground/viewer/renderers/charts.hpp"
#include "ground/viewer/renderers/panel.hpp"
#include "ground/viewer/renderers/scene.hpp"
#include "tools/cmd/command.hpp"

namespace aerie::viewer {

std::vector<std::string> tracker_cycle() {
  std::vector<std::string> names{track::kDefaultTracker};
  for (const auto& list : {track::aerie_tracker_names(), track::opencv_tracker_names()})
    for (const auto& name : list)
      if (name != names.front()) names.push_back(name);
  return names;
}

struct Viewer::Help {
  vtkSmartPointer<vtkTextActor> text = vtkSmartPointer<vtkTextActor>::New();
};

Viewer::Viewer(bus::Bus& bus, ViewerOptions options)
    : bus_(bus), options_(std::move(options)), status_(bus, "viewer"), help_(std::make_unique<Help>()) {
  if (options_.trackers.empty()) throw std::invalid_argument("viewer: the tracker menu is empty");
  if (!(options_.pane_fps > 0)) throw std::invalid_argument("viewer: pane_fps must be positive");
  if (!(options_.trim_period_s >= 0)) throw std::invalid_argument("viewer: trim_period_s must be >= 0");
  last_trim_s_ = util::mono_ms() / 1000.0;
  layout_ = Layout::create(options_.width, options_.height, options_.offscreen, options_.multisamples);
  panes_.push_back({layout_.image});
  panes_.push_back({layout_.scene});
  panes_.push_back({layout_.panel});
  for (const auto& chart : layout_.charts) panes_.push_back({chart});
  image_pane_ = std::make_unique<ImagePane>(layout_.image);
  help_->text->GetTextProperty()->SetFontSize(13);
  help_->text->GetTextProperty()->SetColor(1, 1, 0.6);
  help_->text->SetPosition(6, 6);
  layout_.image->AddActor2D(help_->text);
  update_help_text();
}

Viewer::~Viewer() { stop(); }

Renderer& Viewer::add(std::unique_ptr<Renderer> renderer) {
  if (auto* cam = dynamic_cast<CameraRenderer*>(renderer.get())) camera_ = cam;
  renderer->attach(layout_);
  renderers_.push_back(std::move(renderer));
  update_help_text();
  return *renderers_.back();
}

void Viewer::add_default_renderers() {
  // The display frame first built, added last (renderers 1-9 keep their numbers); the
  // scene's renderers follow it.
  WorldFrameRenderer::Options wo;
  wo.T_body_cam = options_.T_body_cam ? *options_.T_body_cam : nav::sim_forward_rig_T_body_cam();
  wo.align_period_s = options_.align_period_s;
  wo.frame_vehicle = options_.frame_vehicle;
  wo.max_poses = options_.trajectory_poses;
  auto world = std::make_unique<WorldFrameRenderer>(wo);
  auto in_world = [&](auto renderer) {
    renderer->set_world(world.get());
    return renderer;
  };
  add(std::make_unique<CameraRenderer>(options_.image_channel));
  add(std::make_unique<TrackOverlay>());
  add(std::make_unique<GtBoxOverlay>());
  add(std::make_unique<PilotOverlay>());
  add(std::make_unique<GridRenderer>());
  add(in_world(std::make_unique<PoseRenderer>("vo-pose", "VO_POSE", false, options_.trajectory_poses)));
  add(in_world(std::make_unique<PoseRenderer>("gt-pose", "GT_POSE", true, options_.trajectory_poses)));
  add(in_world(std::make_unique<DepthCloudRenderer>()));
  add(in_world(std::make_unique<OctomapRenderer>("MAP_OCTOMAP", options_.map_max_quads)));
  add(in_world(std::make_unique<TargetPoseRenderer>()));
  add_default_charts(*this);
  add(std::make_unique<ProcmanPanel>());
  add(std::move(world));
}

Renderer* Viewer::find(const std::string& name) const {
  for (const auto& r : renderers_)
    if (r->name() == name) return r.get();
  return nullptr;
}

void Viewer::start() {
  if (running_) return;
  for (auto& r : renderers_) r->subscribe(bus_);
  running_ = true;
  lcm_thread_ = std::thread([this] {
    while (running_ && !bus::stop_requested()) {
      try {
        bus_.handle(50);
      } catch (const std::exception& e) {
        spdlog::error("LCM handling: {}", e.what());
      }
    }
  });
}

void Viewer::stop() {
  running_ = false;
  if (lcm_thread_.joinable()) lcm_thread_.join();
}

int64_t Viewer::message_time() const {
  int64_t t = 0;
  for (const auto& r : renderers_) t = std::max(t, r->latest_utime());
  return t;
}

bool Viewer::compose_image_pane(bool force) {
  bool changed = force;
  if (camera_ && camera_->enabled()) {
    cv::Mat img;
    if (camera_->take_image(img)) {
      base_image_ = img;
      changed = true;
    }
  }
  if (!changed || base_image_.empty()) return false;
  cv::Mat canvas;
  if (base_image_.channels() == 1)
    cv::cvtColor(base_image_, canvas, cv::COLOR_GRAY2BGR);
  else
    canvas = base_image_.clone();
  for (auto& r : renderers_)
    if (r->enabled() && r.get() != camera_) r->draw_image(canvas);
  if (selection_) cv::rectangle(canvas, *selection_, cv::Scalar(255, 255, 0), 1);
  image_pane_->show(canvas);
  return true;
}

namespace {
std::array<double, 11> view_of(vtkRenderer* pane) {
  vtkCamera* c = pane->GetActiveCamera();
  std::array<double, 11> v{};
  c->GetPosition(&v[0]);
  c->GetFocalPoint(&v[3]);
  c->GetViewUp(&v[6]);
  v[9] = c->GetViewAngle();
  v[10] = c->GetParallelScale();
  return v;
}
}  // namespace

bool Viewer::schedule_panes(bool image_changed, const std::vector<vtkRenderer*>& changed) {
  const int* size = layout_.window->GetSize();
  if (size[0] != window_size_[0] || size[1] != window_size_[1]) redraw_all_ = true;
  window_size_ = {size[0], size[1]};
  const double now = util::mono_ms() / 1000.0;
  bool any = false;
  for (auto& s : panes_) {
    const bool is_image = s.pane == layout_.image.Get();
    s.pending = s.pending || (is_image ? image_changed : std::count(changed.begin(), changed.end(), s.pane) > 0);
    // Due at once when its view moved (interaction); after a content change at most
    // pane_fps times a second and at most half of the time (twice its last cost apart);
    // the camera image with every new frame.
    const double interval = std::max(1.0 / options_.pane_fps, 2.0 * s.cost_s);
    const bool due = redraw_all_ || options_.always_redraw || view_of(s.pane) != s.view ||
                     (s.pending && (is_image || now - s.last_drawn_s >= interval));
    s.pane->SetDraw(due);
    if (due) {
      s.pending = false;
      s.last_drawn_s = now;
    }
    any = any || due;
  }
  redraw_all_ = false;
  return any;
}

void Viewer::housekeeping() {
  const double now = util::mono_ms() / 1000.0;
  if (options_.trim_period_s > 0 && now - last_trim_s_ >= options_.trim_period_s) {
    status_.count("heap_trims");
    status_.count("heap_released_kb", util::trim_heap());
    last_trim_s_ = now;
  }
  if (now - last_status_s_ < 1.0) return;
  last_status_s_ = now;
  const util::HeapFigures heap = util::heap_figures();
  status_.set("frames_rendered", frames_rendered_);
  status_.set("heap_in_use_kb", heap.in_use_kb);
  status_.set("heap_free_kb", heap.free_kb);
  status_.set("rss_kb", heap.rss_kb);
  status_.tick();
}

bool Viewer::render_frame() {
  housekeeping();
  bool overlay_changed = selection_.has_value();
  bool changed = false;
  std::vector<vtkRenderer*> changed_panes;
  for (auto& r : renderers_) {
    if (!r->enabled() || r.get() == camera_) continue;
    if (r->update()) {
      changed = true;
      if (r->pane())
        changed_panes.push_back(r->pane());
      else
        overlay_changed = true;
    }
  }
  if (paused_) return false;
  const bool image_changed = compose_image_pane(overlay_changed);
  if (schedule_panes(image_changed, changed_panes)) {
    // Panes not due keep their pixels: VTK renders into its own framebuffer and each
    // renderer clears only its viewport.
    const double start = util::mono_ms();
    layout_.window->Render();
    const double cost_s = (util::mono_ms() - start) / 1000.0;
    ++frames_rendered_;
    for (auto& s : panes_) {
      s.view = view_of(s.pane);
      if (s.pane->GetDraw()) s.cost_s = cost_s;
    }
  }
  for (auto& s : panes_) s.pane->SetDraw(true);  // interactor renders and snapshots draw all
  return changed;
}

void Viewer::snapshot(const std::string& png_path) {
  compose_image_pane(true);
  layout_.window->Render();
  auto grab = vtkSmartPointer<vtkWindowToImageFilter>::New();
  grab->SetInput(layout_.window);
  grab->ReadFrontBufferOff();
  grab->Update();
  auto writer = vtkSmartPointer<vtkPNGWriter>::New();
  writer->SetFileName(png_path.c_str());
  writer->SetInputConnection(grab->GetOutputPort());
  writer->Write();
  if (writer->GetErrorCode() != 0) throw std::runtime_error("cannot write snapshot " + png_path);
}

void Viewer::begin_selection(double x, double y) {
  const auto p = image_pane_->display_to_image(x, y);
  if (!p) return;
  selection_start_ = *p;
  selection_ = cv::Rect2d(*p, *p);
}

void Viewer::drag_selection(double x, double y) {
  if (!selection_) return;
  // Outside the pane the selection is clamped to its border.
  int* size = layout_.window->GetSize();
  double vp[4];
  layout_.image->GetViewport(vp);
  x = std::clamp(x, vp[0] * size[0], vp[2] * size[0] - 1);
  y = std::clamp(y, vp[1] * size[1], vp[3] * size[1] - 1);
  if (const auto p = image_pane_->display_to_image(x, y)) selection_ = cv::Rect2d(selection_start_, *p);
}

std::optional<cv::Rect2d> Viewer::end_selection(double x, double y) {
  if (!selection_) return std::nullopt;
  drag_selection(x, y);
  const cv::Size s = image_pane_->image_size();
  cv::Rect2d box = *selection_ & cv::Rect2d(0, 0, s.width, s.height);
  selection_.reset();
  if (box.width < 4 || box.height < 4) return std::nullopt;  // a click, not a box
  send_track_command(aerie::track_cmd_t::INIT, box);
  return box;
}

void Viewer::send_track_command(int8_t command, const std::optional<cv::Rect2d>& box) {
  std::optional<aerie::cmd::Box> b;
  if (box) b = aerie::cmd::Box{box->x, box->y, box->width, box->height};
  // The message aerie-cmd sends (tools/cmd/command.hpp): one builder for both operators.
  const aerie::track_cmd_t cmd =
      aerie::cmd::track_command(command, current_tracker(), options_.image_channel, b, message_time(), cmd_seq_++);
  bus_.publish(options_.track_cmd_channel, cmd);
  spdlog::info("TRACK_CMD {} tracker={} box=({:.0f},{:.0f},{:.0f},{:.0f})", command, cmd.tracker, cmd.x, cmd.y,
               cmd.width, cmd.height);
}

void Viewer::on_key(const std::string& key) {
  if (key == "t") {
    tracker_index_ = (tracker_index_ + 1) % options_.trackers.size();
    send_track_command(aerie::track_cmd_t::SET_TRACKER);
  } else if (key == "x") {
    send_track_command(aerie::track_cmd_t::STOP);
  } else if (key == "r") {
    send_track_command(aerie::track_cmd_t::RESET);
  } else if (key == "c") {
    image_pane_->reset_view();
    layout_.scene->ResetCamera();
  } else if (key == "p") {
    paused_ = !paused_;
  } else if (key == "h") {
    help_->text->SetVisibility(!help_->text->GetVisibility());
  } else if (key.size() == 1 && key[0] >= '1' && key[0] <= '9') {
    const size_t i = static_cast<size_t>(key[0] - '1');
    if (i < renderers_.size()) renderers_[i]->set_enabled(!renderers_[i]->enabled());
  } else {
    for (auto& r : renderers_)
      if (r->enabled() && r->on_key(key)) break;
  }
  update_help_text();
  redraw_all();
}

std::string Viewer::help_text() const {
  // Every key of keys.hpp (the table docs/viewer.md lists), wrapped to the pane.
  constexpr size_t kLine = 72;
  std::string s, line;
  for (const auto& k : kKeys) {
    std::string item = std::string(k.key) + ": " + std::string(k.overlay);
    if (k.key == "t") item += " [" + current_tracker() + "]";
    if (k.key == "p" && paused_) item += " (PAUSED)";
    if (!line.empty() && line.size() + 2 + item.size() > kLine) {
      s += line + "\n";
      line.clear();
    }
    line += (line.empty() ? "" : "  ") + item;
  }
  s += line + "\n";
  for (size_t i = 0; i < renderers_.size() && i < 9; ++i)
    s += std::to_string(i + 1) + (renderers_[i]->enabled() ? ":[x] " : ":[ ] ") + renderers_[i]->name() +
         (i % 5 == 4 ? "\n" : "  ");
  return s;
}

void Viewer::update_help_text() { help_->text->SetInput(help_text().c_str()); }

namespace {

// Routes mouse and keys to the viewer: left-drag on the camera pane selects a box;
// elsewhere the trackball camera style moves the 3D scene.
class InteractorStyle : public vtkInteractorStyleTrackballCamera {
 public:
  static InteractorStyle* New();
  vtkTypeMacro(InteractorStyle, vtkInteractorStyleTrackballCamera)
  Viewer* viewer = nullptr;
  bool selecting = false;

  void OnLeftButtonDown() override {
    int* p = GetInteractor()->GetEventPosition();
    if (viewer->image_pane().contains_display(p[0], p[1])) {
      selecting = true;
      viewer->begin_selection(p[0], p[1]);
      return;
    }
    vtkInteractorStyleTrackballCamera::OnLeftButtonDown();
  }
  void OnMouseMove() override {
    if (selecting) {
      int* p = GetInteractor()->GetEventPosition();
      viewer->drag_selection(p[0], p[1]);
      return;
    }
    vtkInteractorStyleTrackballCamera::OnMouseMove();
  }
  void OnLeftButtonUp() override {
    if (selecting) {
      int* p = GetInteractor()->GetEventPosition();
      viewer->end_selection(p[0], p[1]);
      selecting = false;
      return;
    }
    vtkInteractorStyleTrackballCamera::OnLeftButtonUp();
  }
  void OnChar() override {
    const char* sym = GetInteractor()->GetKeySym();
    const std::string key = sym ? sym : "";
    if (key == "q" || key == "Escape") {
      GetInteractor()->ExitCallback();
      return;
    }
    viewer->on_key(key.size() == 1 ? key : std::string(1, GetInteractor()->GetKeyCode()));
  }
};
vtkStandardNewMacro(InteractorStyle);

void on_timer(vtkObject*, unsigned long, void* client, void*) {
  auto* v = static_cast<Viewer*>(client);
  v->render_frame();
  if (bus::stop_requested()) v->layout().window->GetInteractor()->ExitCallback();
}

}  // namespace

void Viewer::run_interactive(double fps) {
  auto interactor = vtkSmartPointer<vtkRenderWindowInteractor>::New();
  interactor->SetRenderWindow(layout_.window);
  auto style = vtkSmartPointer<InteractorStyle>::New();
  style->viewer = this;
  style->SetDefaultRenderer(layout_.scene);
  interactor->SetInteractorStyle(style);
  interactor->Initialize();
  auto cb = vtkSmartPointer<vtkCallbackCommand>::New();
  cb->SetCallback(on_timer);
  cb->SetClientData(this);
  interactor->AddObserver(vtkCommand::TimerEvent, cb);
  interactor->CreateRepeatingTimer(static_cast<unsigned long>(1000.0 / fps));
  interactor->Start();
}

}  // namespace aerie::viewer
