#pragma once
// A viewer renderer (libbot-style plugin): a name, an enabled flag, its own LCM
// subscriptions (handled in the LCM thread, storing latest values), and an update
// called in the render thread that moves the latest data into VTK objects or onto
// the camera image pane.
#include <atomic>
#include <opencv2/core.hpp>
#include <string>

#include "common/bus/bus.hpp"

class vtkRenderer;

namespace aerie::viewer {

struct Layout;

class Renderer {
 public:
  explicit Renderer(std::string name) : name_(std::move(name)) {}
  virtual ~Renderer() = default;
  Renderer(const Renderer&) = delete;
  Renderer& operator=(const Renderer&) = delete;

  const std::string& name() const { return name_; }
  bool enabled() const { return enabled_; }
  void set_enabled(bool on) {
    enabled_ = on;
    on_enabled(on);
  }

  // LCM thread: subscribe to the channels this renderer shows.
  virtual void subscribe(bus::Bus& bus) = 0;
  // Render thread, once: create VTK actors in the layout's panes.
  virtual void attach(Layout&) {}
  // Render thread, every displayed frame while enabled. Returns true when it changed something.
  virtual bool update() { return false; }
  // Render thread: draw onto the camera pane's image (pixel coordinates of the source image).
  virtual void draw_image(cv::Mat&) {}
  // The newest message time (utime) this renderer has seen; the viewer follows it in replay.
  virtual int64_t latest_utime() const { return 0; }
  // Render thread: a key the viewer does not use itself; true when handled.
  virtual bool on_key(const std::string&) { return false; }
  // The window pane this renderer draws into (set by attach); nullptr for overlays on the
  // camera image. The viewer redraws a pane only when one of its renderers changed.
  vtkRenderer* pane() const { return pane_; }

 protected:
  virtual void on_enabled(bool) {}
  void draws_in(vtkRenderer* pane) { pane_ = pane; }

 private:
  std::string name_;
  std::atomic<bool> enabled_{true};
  vtkRenderer* pane_ = nullptr;
};

}  // namespace aerie::viewer
