#pragma once
// The ground viewer: renderers (plugins) fed by LCM in a handling thread, drawn by the
// render thread into one VTK window (layout.hpp). Operator interaction: drag a box on
// the camera pane to start tracking it (TRACK_CMD INIT with the chosen tracker), keys
// to stop/reset tracking, toggle renderers, reset the camera and pause the display.
#include <aerie/track_cmd_t.hpp>

#include <array>
#include <atomic>
#include <memory>
#include <optional>
#include <string>
#include <thread>
#include <vector>

#include "common/bus/bus.hpp"
#include "common/bus/status.hpp"
#include "common/geometry/se3.hpp"
#include "ground/viewer/image_pane.hpp"
#include "ground/viewer/layout.hpp"
#include "ground/viewer/renderer.hpp"
#include "ground/viewer/renderers/camera.hpp"

namespace aerie::viewer {

// The 't' key's cycle: aerie-track's default tracker (air/track/node/default_tracker.hpp)
// first, then every other tracker the factory builds (air/track/factory.hpp), ours then
// OpenCV's references.
std::vector<std::string> tracker_cycle();

struct ViewerOptions {
  int width = 1280;
  int height = 800;
  bool offscreen = false;
  // OpenGL multisampling (anti-aliasing). Off by default: software OpenGL (llvmpipe, no
  // GPU) spends most of a frame resolving 8 samples per pixel.
  int multisamples = 0;
  // Panes other than the camera image (3D scene, charts, panel) are redrawn when their
  // content or view changed, at most this many times per second and at most half of
  // the time (a pane whose frame took 80 ms waits 160 ms), so a large map never starves
  // the camera pane, which is redrawn with every new image. `always_redraw` draws every
  // pane every frame.
  double pane_fps = 10;
  bool always_redraw = false;
  // OctoMap display: more quads than this and the map is shown one level coarser (0: no limit).
  size_t map_max_quads = 60000;
  // Trajectories (VO_POSE, GT_POSE) show the newest this many poses: 6000 is 5 minutes at
  // 20 Hz, and bounds their memory in a long session.
  size_t trajectory_poses = 6000;
  // Freed memory that glibc's arenas hold is handed back to the kernel this often
  // (util::trim_heap, common/util/heap.hpp); 0: never.
  double trim_period_s = 10;
  // The display frame (world_frame.hpp): the camera in the IMU's body frame, for gravity
  // from IMU (default: the simulator's forward rig, nav::sim_forward_rig_T_body_cam), and
  // how often the ground truth is aligned to the estimate.
  std::optional<geometry::SE3> T_body_cam;  // nullopt: the simulator's forward rig
  double align_period_s = 2.0;
  bool frame_vehicle = false;  // WorldFrameRenderer::Options::frame_vehicle
  std::string image_channel = "CAM_LEFT";
  std::string track_cmd_channel = "TRACK_CMD";
  std::vector<std::string> trackers = tracker_cycle();
};

class Viewer {
 public:
  Viewer(bus::Bus& bus, ViewerOptions options);
  ~Viewer();

  // Adds the standard renderers (camera pane, tracking, 3D scene, charts, procman panel).
  void add_default_renderers();
  Renderer& add(std::unique_ptr<Renderer> renderer);
  Renderer* find(const std::string& name) const;
  const std::vector<std::unique_ptr<Renderer>>& renderers() const { return renderers_; }

  // Subscribes every renderer and starts the LCM handling thread.
  void start();
  void stop();

  // Render thread: pulls the latest data into every enabled renderer and renders the
  // panes that changed (unless paused). Returns true when anything changed.
  bool render_frame();
  // Draw every pane at the next frame (after keys, window resizes).
  void redraw_all() { redraw_all_ = true; }
  // Writes a PNG of the whole window (renders first).
  void snapshot(const std::string& png_path);

  // Operator interaction (display coordinates: pixels, origin bottom-left).
  void begin_selection(double x, double y);
  void drag_selection(double x, double y);
  // Sends TRACK_CMD INIT for the selected box in image pixels; returns it when sent.
  std::optional<cv::Rect2d> end_selection(double x, double y);
  // Keys (keys.hpp): 't' next tracker, 'x' stop, 'r' reset tracking, 'c' reset cameras,
  // 'p' pause/resume, '1'..'9' toggle renderer N, 'h' toggle the help text; the others go
  // to the renderers.
  void on_key(const std::string& key);
  // The help overlay's text: every key of keys.hpp, then renderers 1-9 and their state.
  std::string help_text() const;
  void send_track_command(int8_t command, const std::optional<cv::Rect2d>& box = std::nullopt);

  const std::string& current_tracker() const { return options_.trackers[tracker_index_]; }
  bool paused() const { return paused_; }
  Layout& layout() { return layout_; }
  ImagePane& image_pane() { return *image_pane_; }
  int64_t frames_rendered() const { return frames_rendered_; }
  // Latest message time seen (utime, µs): the viewer's clock, so replays follow log time.
  int64_t message_time() const;
  // Runs the interactive window until it is closed or stop is requested.
  void run_interactive(double fps);

 private:
  // Redraws the camera pane's image when a new image arrived or `force`; true when it did.
  bool compose_image_pane(bool force);
  // Chooses the panes due for drawing (vtkRenderer::SetDraw); false when none is.
  bool schedule_panes(bool image_changed, const std::vector<vtkRenderer*>& changed);
  void update_help_text();
  // Once a second: STATUS_VIEWER with the frames drawn and the heap (util::heap_figures); the heap trim.
  void housekeeping();

  bus::Bus& bus_;
  ViewerOptions options_;
  Layout layout_;
  std::unique_ptr<ImagePane> image_pane_;
  std::vector<std::unique_ptr<Renderer>> renderers_;
  CameraRenderer* camera_ = nullptr;
  cv::Mat base_image_;
  std::optional<cv::Rect2d> selection_;  // image pixels, while dragging
  cv::Point2d selection_start_;
  size_t tracker_index_ = 0;
  bool paused_ = false;
  int64_t frames_rendered_ = 0;
  bus::StatusReporter status_;
  double last_trim_s_ = 0, last_status_s_ = -1;
  struct PaneState {
    vtkRenderer* pane;
    bool pending = true;            // content changed since it was last drawn
    double last_drawn_s = -1e9;     // monotonic seconds
    double cost_s = 0;              // wall time of the last frame that drew it
    std::array<double, 11> view{};  // camera when last drawn: an interaction moved it if different
  };
  std::vector<PaneState> panes_;  // the camera image pane first
  std::array<int, 2> window_size_{};
  bool redraw_all_ = true;
  int64_t cmd_seq_ = 0;
  std::atomic<bool> running_{false};
  std::thread lcm_thread_;
  struct Help;
  std::unique_ptr<Help> help_;
};

}  // namespace aerie::viewer
