#pragma once
// Renderers of the 3D scene: grid and axes, vehicle poses with a camera frustum and
// their trajectories (VO and ground truth), the current spherical depth as a point
// cloud, the OctoMap voxels coloured by height with a resolution selector, and the
// tracked target's 3D pose.
#include <aerie/gt_pose_t.hpp>
#include <aerie/imu_t.hpp>
#include <aerie/octomap_t.hpp>
#include <aerie/pose_t.hpp>
#include <aerie/spherical_depth_t.hpp>
#include <aerie/target_pose_t.hpp>
#include <vtkActor.h>
#include <vtkTextActor.h>
#include <vtkSmartPointer.h>

#include <Eigen/Core>
#include <atomic>
#include <mutex>
#include <optional>
#include <vector>

#include "common/geometry/se3.hpp"
#include "ground/viewer/latest.hpp"
#include "ground/viewer/renderer.hpp"
#include "ground/viewer/world_frame.hpp"

class vtkPolyData;
class vtkProp3D;
class vtkRenderer;

namespace aerie::viewer {

struct StampedPose {
  int64_t utime = 0;
  geometry::SE3 T_world_camera;
};

// The display frame of the 3D scene (world_frame.hpp): gravity from the first GT pose or
// the IMU, and the ground truth aligned to the estimate every `align_period_s` (and on
// 'g'). Writes what it used at the top of the scene pane. The scene's other renderers
// draw VO-world content with display_from_vo() and ground truth with display_from_gt().
class WorldFrameRenderer : public Renderer {
 public:
  struct Options {
    std::string vo_channel = "VO_POSE", gt_channel = "GT_POSE", imu_channel = "IMU";
    geometry::SE3 T_body_cam;  // the camera in the IMU's body frame (the IMU's gravity)
    size_t imu_samples = 100;  // the first samples, at rest: 0.5 s at 200 Hz
    double align_period_s = 2.0;
    size_t max_poses = 6000;
    // Once the display frame is known, look at the vehicle's start from 8 m (else the scene
    // is framed whole at the first poses, as before).
    bool frame_vehicle = false;
  };
  explicit WorldFrameRenderer(Options options);
  void subscribe(bus::Bus& bus) override;
  void attach(Layout& layout) override;
  bool update() override;
  bool on_key(const std::string& key) override;

  const geometry::SE3& display_from_vo() const { return T_D_vo_; }
  const geometry::SE3& display_from_gt() const { return T_D_gt_; }
  GravitySource gravity() const { return gravity_; }
  const std::optional<GtAlignment>& alignment() const { return alignment_; }
  std::string label() const;
  uint64_t version() const { return version_; }  // bumped when a transform changes
  bool frames_vehicle() const { return options_.frame_vehicle; }

 private:
  Options options_;
  History<StampedPose> vo_, gt_;
  mutable std::mutex imu_m_;
  std::vector<Eigen::Vector3d> imu_;
  uint64_t vo_seen_ = 0, gt_seen_ = 0;
  std::vector<StampedPose> vo_buf_, gt_buf_;
  std::atomic<uint64_t> resets_{0};
  uint64_t resets_seen_ = 0;
  GravitySource gravity_ = GravitySource::None;
  std::optional<GtAlignment> alignment_;
  geometry::SE3 T_D_vo_, T_D_gt_;
  double last_align_s_ = -1e9;
  bool align_now_ = false, unaligned_ = false;
  uint64_t version_ = 1;
  std::string shown_label_;
  std::optional<GravitySource> viewed_;  // the display frame the scene's camera was last moved to the vehicle in
  vtkRenderer* scene_ = nullptr;
  vtkSmartPointer<vtkTextActor> label_;
};

// Follows a WorldFrameRenderer's transforms (none: the identity).
class InWorld {
 public:
  void set_world(const WorldFrameRenderer* world) { world_ = world; }

 protected:
  // True once per change of the world's transforms.
  bool world_changed() {
    const uint64_t v = world_ ? world_->version() : 0;
    if (v == world_seen_) return false;
    world_seen_ = v;
    return true;
  }
  bool world_frames_the_view() const { return world_ && world_->frames_vehicle(); }
  geometry::SE3 from_vo() const { return world_ ? world_->display_from_vo() : geometry::SE3(); }
  geometry::SE3 from_gt() const { return world_ ? world_->display_from_gt() : geometry::SE3(); }
  static void place(vtkProp3D* prop, const geometry::SE3& T);

 private:
  const WorldFrameRenderer* world_ = nullptr;
  uint64_t world_seen_ = 0;
};

class GridRenderer : public Renderer {
 public:
  explicit GridRenderer(double half_size_m = 10, double spacing_m = 1);
  void subscribe(bus::Bus&) override {}
  void attach(Layout& layout) override;

 protected:
  void on_enabled(bool on) override;

 private:
  double half_, spacing_;
  vtkSmartPointer<vtkActor> grid_;
  vtkSmartPointer<vtkProp> axes_;
};

// A pose stream (aerie.pose_t on VO_POSE, or aerie.gt_pose_t on GT_POSE): the
// trajectory of the newest `max_poses` poses as a polyline and the camera frustum at the
// newest pose.
class PoseRenderer : public Renderer, public InWorld {
 public:
  PoseRenderer(std::string name, std::string channel, bool ground_truth, size_t max_poses = 6000);
  void subscribe(bus::Bus& bus) override;
  void attach(Layout& layout) override;
  bool update() override;
  int64_t latest_utime() const override;
  size_t trajectory_size() const { return shown_; }

 protected:
  void on_enabled(bool on) override;

 private:
  std::string channel_;
  bool gt_;
  History<StampedPose> poses_;
  uint64_t seen_ = 0;
  size_t shown_ = 0;
  std::vector<StampedPose> buffer_;
  vtkSmartPointer<vtkActor> path_, frustum_;
  vtkRenderer* scene_ = nullptr;
  bool camera_fitted_ = false;
};

// VO_DEPTH: the newest frame's spherical depth decoded to points in the world.
class DepthCloudRenderer : public Renderer, public InWorld {
 public:
  explicit DepthCloudRenderer(std::string channel = "VO_DEPTH");
  void subscribe(bus::Bus& bus) override;
  void attach(Layout& layout) override;
  bool update() override;
  size_t points_shown() const { return shown_; }

 protected:
  void on_enabled(bool on) override;

 private:
  std::string channel_;
  Latest<std::vector<Eigen::Vector3f>> cloud_;
  uint64_t seen_ = 0;
  size_t shown_ = 0;
  vtkSmartPointer<vtkActor> actor_;
};

// MAP_OCTOMAP: occupied voxels coloured by height (like the thesis' Fig. 4.10), drawn as
// their merged visible surface. 'v' cycles the display resolution (OctoMap tree depth:
// finest, then coarser levels). Software OpenGL draws about 2 million quads a second, so
// a map whose surface needs more than `max_quads` quads is shown one level coarser (and
// so on) and the pane says so; 0 = no limit.
class OctomapRenderer : public Renderer, public InWorld {
 public:
  explicit OctomapRenderer(std::string channel = "MAP_OCTOMAP", size_t max_quads = 60000);
  ~OctomapRenderer() override;
  void subscribe(bus::Bus& bus) override;
  void attach(Layout& layout) override;
  bool update() override;
  bool on_key(const std::string& key) override;
  // 0 = finest; n = n levels coarser (voxels 2^n times larger).
  void set_coarsening(int levels);
  int coarsening() const { return coarsening_; }
  int coarsening_shown() const { return shown_coarsening_; }  // after the quad budget
  size_t voxels_shown() const { return shown_; }
  size_t quads_shown() const { return quads_; }

 protected:
  void on_enabled(bool on) override;

 private:
  struct Map;

  std::string channel_;
  std::unique_ptr<Map> map_;
  int coarsening_ = 0, shown_coarsening_ = 0;
  size_t shown_ = 0, quads_ = 0;
  vtkSmartPointer<vtkActor> actor_;
  vtkSmartPointer<vtkTextActor> label_;
};

// TARGET_POSE (relative to the camera) placed in the world with the newest camera pose
// from GT_POSE or VO_POSE.
class TargetPoseRenderer : public Renderer, public InWorld {
 public:
  TargetPoseRenderer(std::string channel = "TARGET_POSE", std::string pose_channel = "VO_POSE",
                     std::string gt_pose_channel = "GT_POSE");
  void subscribe(bus::Bus& bus) override;
  void attach(Layout& layout) override;
  bool update() override;

 protected:
  void on_enabled(bool on) override;

 private:
  std::string channel_, pose_channel_, gt_pose_channel_;
  Latest<aerie::target_pose_t> target_;
  struct Camera {
    geometry::SE3 T;
    bool ground_truth;
  };
  Latest<Camera> camera_;
  uint64_t seen_target_ = 0, seen_camera_ = 0;
  std::optional<aerie::target_pose_t> current_;
  std::optional<Camera> current_camera_;
  vtkSmartPointer<vtkActor> actor_;
};

}  // namespace aerie::viewer
