#pragma once
// Renderers of the 3D scene: grid and axes, vehicle poses with a camera frustum and
// their trajectories (VO and ground truth), the current spherical depth as a point
// cloud, the OctoMap voxels coloured by height with a resolution selector, and the
// tracked target's 3D pose.
#include <aerie/gt_pose_t.hpp>
#include <aerie/octomap_t.hpp>
#include <aerie/pose_t.hpp>
#include <aerie/spherical_depth_t.hpp>
#include <aerie/target_pose_t.hpp>
#include <vtkActor.h>
#include <vtkTextActor.h>
#include <vtkSmartPointer.h>

#include <Eigen/Core>

#include "common/geometry/se3.hpp"
#include "ground/viewer/latest.hpp"
#include "ground/viewer/renderer.hpp"

class vtkPolyData;
class vtkRenderer;

namespace aerie::viewer {

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

struct StampedPose {
  int64_t utime = 0;
  geometry::SE3 T_world_camera;
};

// A pose stream (aerie.pose_t on VO_POSE, or aerie.gt_pose_t on GT_POSE): the
// trajectory of the newest `max_poses` poses as a polyline and the camera frustum at the
// newest pose.
class PoseRenderer : public Renderer {
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
class DepthCloudRenderer : public Renderer {
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
class OctomapRenderer : public Renderer {
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
class TargetPoseRenderer : public Renderer {
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
  Latest<geometry::SE3> camera_;
  uint64_t seen_target_ = 0, seen_camera_ = 0;
  std::optional<aerie::target_pose_t> current_;
  std::optional<geometry::SE3> current_camera_;
  vtkSmartPointer<vtkActor> actor_;
};

}  // namespace aerie::viewer
