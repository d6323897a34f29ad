#include "ground/viewer/renderers/scene.hpp"

#include <octomap/OcTree.h>
#include <spdlog/spdlog.h>
#include <vtkAxesActor.h>
#include <vtkCamera.h>
#include <vtkCellArray.h>
#include <vtkFloatArray.h>
#include <vtkLookupTable.h>
#include <vtkMatrix4x4.h>
#include <vtkPointData.h>
#include <vtkPoints.h>
#include <vtkPolyData.h>
#include <vtkPolyDataMapper.h>
#include <vtkProperty.h>
#include <vtkRenderer.h>
#include <vtkSphereSource.h>
#include <vtkTextProperty.h>

#include <cstdio>
#include <condition_variable>
#include <deque>
#include <mutex>
#include <optional>
#include <thread>

#include "common/spherical/spherical_message.hpp"
#include "ground/map/octomap_message.hpp"
#include "common/util/time.hpp"
#include "ground/viewer/layout.hpp"
#include "ground/viewer/voxel_mesh.hpp"

namespace aerie::viewer {
namespace {

vtkSmartPointer<vtkActor> line_actor(double r, double g, double b, double width) {
  auto mapper = vtkSmartPointer<vtkPolyDataMapper>::New();
  mapper->SetInputData(vtkSmartPointer<vtkPolyData>::New());
  auto actor = vtkSmartPointer<vtkActor>::New();
  actor->SetMapper(mapper);
  actor->GetProperty()->SetColor(r, g, b);
  actor->GetProperty()->SetLineWidth(static_cast<float>(width));
  actor->GetProperty()->LightingOff();
  return actor;
}

vtkPolyData* poly_of(vtkActor* a) { return vtkPolyData::SafeDownCast(a->GetMapper()->GetInput()); }

// Camera frustum (apex at the optical centre, 0.3 m deep, 98 x 73 degree FOV) in the world.
void set_frustum(vtkPolyData* poly, const geometry::SE3& T) {
  const double d = 0.3, hx = d * std::tan(49.0 * M_PI / 180), hy = d * std::tan(36.5 * M_PI / 180);
  const Eigen::Vector3d c[5] = {{0, 0, 0}, {-hx, -hy, d}, {hx, -hy, d}, {hx, hy, d}, {-hx, hy, d}};
  auto pts = vtkSmartPointer<vtkPoints>::New();
  for (const auto& p : c) {
    const Eigen::Vector3d w = T * p;
    pts->InsertNextPoint(w.x(), w.y(), w.z());
  }
  auto lines = vtkSmartPointer<vtkCellArray>::New();
  const vtkIdType edges[8][2] = {{0, 1}, {0, 2}, {0, 3}, {0, 4}, {1, 2}, {2, 3}, {3, 4}, {4, 1}};
  for (const auto& e : edges) lines->InsertNextCell(2, e);
  poly->SetPoints(pts);
  poly->SetLines(lines);
  poly->Modified();
}

// Colours the map's surface by height in the display frame (z up) of T_display_map.
void colour_by_height(vtkActor* actor, const geometry::SE3& T_display_map) {
  auto* mapper = vtkPolyDataMapper::SafeDownCast(actor->GetMapper());
  auto* poly = vtkPolyData::SafeDownCast(mapper->GetInput());
  if (!poly || !poly->GetPoints() || poly->GetNumberOfPoints() == 0) return;
  const Eigen::Vector3d up = T_display_map.rotation().conjugate() * Eigen::Vector3d::UnitZ();  // in the map
  const double z0 = T_display_map.translation().z();
  auto height = vtkSmartPointer<vtkFloatArray>::New();
  height->SetName("height");
  height->SetNumberOfValues(poly->GetNumberOfPoints());
  double lo = 1e300, hi = -1e300;
  for (vtkIdType i = 0; i < poly->GetNumberOfPoints(); ++i) {
    double p[3];
    poly->GetPoint(i, p);
    const double z = up.dot(Eigen::Vector3d(p[0], p[1], p[2])) + z0;
    height->SetValue(i, static_cast<float>(z));
    lo = std::min(lo, z);
    hi = std::max(hi, z);
  }
  poly->GetPointData()->SetScalars(height);
  mapper->SetScalarRange(lo, std::max(hi, lo + 1e-3));
}

}  // namespace

// ---------------------------------------------------------------- world frame
void InWorld::place(vtkProp3D* prop, const geometry::SE3& T) {
  if (!prop) return;
  auto m = vtkSmartPointer<vtkMatrix4x4>::New();
  const Eigen::Matrix4d M = T.matrix();
  for (int r = 0; r < 4; ++r)
    for (int c = 0; c < 4; ++c) m->SetElement(r, c, M(r, c));
  prop->SetUserMatrix(m);
}

WorldFrameRenderer::WorldFrameRenderer(Options options)
    : Renderer("world"), options_(std::move(options)), vo_(options_.max_poses), gt_(options_.max_poses) {
  if (!(options_.align_period_s > 0)) throw std::invalid_argument("viewer: the GT alignment period must be > 0 s");
  if (options_.imu_samples == 0) throw std::invalid_argument("viewer: gravity needs at least one IMU sample");
}

void WorldFrameRenderer::subscribe(bus::Bus& bus) {
  bus.subscribe<aerie::pose_t>(options_.vo_channel, [this](const aerie::pose_t& m, const bus::ReceiveInfo&) {
    if (m.status == aerie::pose_t::RESET) {
      vo_.clear();
      ++resets_;
    }
    vo_.push({m.utime, geometry::SE3::from_wxyz(m.orientation, m.position)});
  });
  bus.subscribe<aerie::gt_pose_t>(options_.gt_channel, [this](const aerie::gt_pose_t& m, const bus::ReceiveInfo&) {
    gt_.push({m.utime, geometry::SE3::from_wxyz(m.orientation, m.position)});
  });
  bus.subscribe<aerie::imu_t>(options_.imu_channel, [this](const aerie::imu_t& m, const bus::ReceiveInfo&) {
    std::lock_guard lock(imu_m_);
    if (imu_.size() < options_.imu_samples)
      imu_.emplace_back(m.linear_acceleration[0], m.linear_acceleration[1], m.linear_acceleration[2]);
  });
}

void WorldFrameRenderer::attach(Layout& layout) {
  draws_in(layout.scene);
  label_ = vtkSmartPointer<vtkTextActor>::New();
  label_->GetTextProperty()->SetFontSize(12);
  label_->GetTextProperty()->SetColor(0.9, 0.9, 0.75);
  label_->GetTextProperty()->SetVerticalJustificationToTop();
  label_->GetPositionCoordinate()->SetCoordinateSystemToNormalizedViewport();
  label_->GetPositionCoordinate()->SetValue(0.01, 0.98);
  label_->SetInput(label().c_str());
  layout.scene->AddActor2D(label_);
  scene_ = layout.scene;
}

std::string WorldFrameRenderer::label() const {
  std::string gt = alignment_ ? alignment_->label() : gt_buf_.empty() ? "GT: none" : "GT: not aligned yet (in its own world)";
  return gravity_label(gravity_) + "\n" + gt;
}

bool WorldFrameRenderer::on_key(const std::string& key) {
  if (key != "g") return false;
  align_now_ = true;
  return true;
}

bool WorldFrameRenderer::update() {
  const bool vo_new = vo_.snapshot_if_newer(vo_seen_, vo_buf_);
  const bool gt_new = gt_.snapshot_if_newer(gt_seen_, gt_buf_);
  const geometry::SE3 old_vo = T_D_vo_, old_gt = T_D_gt_;
  bool moved_view = false;
  if (resets_ != resets_seen_) {  // a new VO world: decide again
    resets_seen_ = resets_;
    gravity_ = GravitySource::None;
    alignment_.reset();
    viewed_.reset();
    T_D_vo_ = geometry::SE3();
  }
  // Gravity: the first VO pose with a ground-truth pose of the same frame, else the IMU.
  if (gravity_ != GravitySource::FirstGtPose && !vo_buf_.empty() && !gt_buf_.empty()) {
    for (const auto& v : vo_buf_) {
      const auto g = std::find_if(gt_buf_.begin(), gt_buf_.end(), [&](const StampedPose& p) {
        return std::llabs(p.utime - v.utime) <= 5000;  // the same frame (5 ms)
      });
      if (g == gt_buf_.end()) continue;
      T_D_vo_ = frame_from_first_gt_pose(g->T_world_camera, v.T_world_camera);
      gravity_ = GravitySource::FirstGtPose;
      break;
    }
  }
  if (gravity_ == GravitySource::None && !vo_buf_.empty()) {
    std::vector<Eigen::Vector3d> imu;
    {
      std::lock_guard lock(imu_m_);
      if (imu_.size() >= options_.imu_samples) imu = imu_;
    }
    if (!imu.empty()) {
      try {
        T_D_vo_ = geometry::SE3(gravity_rotation(imu, options_.T_body_cam, vo_buf_.front().T_world_camera),
                                Eigen::Vector3d::Zero());
        gravity_ = GravitySource::Imu;
      } catch (const std::invalid_argument& e) {
        spdlog::warn("viewer: no gravity from {}: {}", options_.imu_channel, e.what());
        std::lock_guard lock(imu_m_);
        imu_.clear();  // the next samples, perhaps at rest
      }
    }
  }
  // Ground truth in the estimate's frame, every align_period_s (message handling never waits).
  const double now = util::mono_ms() / 1000.0;
  unaligned_ = unaligned_ || vo_new || gt_new;  // poses came since the last alignment
  if ((unaligned_ && now - last_align_s_ >= options_.align_period_s) || align_now_) {
    align_now_ = unaligned_ = false;
    last_align_s_ = now;
    eval::Trajectory gt, vo;
    for (const auto& p : gt_buf_) gt.push_back(static_cast<double>(p.utime) * 1e-6, p.T_world_camera);
    for (const auto& p : vo_buf_) vo.push_back(static_cast<double>(p.utime) * 1e-6, p.T_world_camera);
    if (auto a = align_ground_truth(gt, vo, 0.005)) alignment_ = a;
  }
  T_D_gt_ = alignment_ ? T_D_vo_ * alignment_->T_vo_gt : geometry::SE3();
  auto same = [](const geometry::SE3& a, const geometry::SE3& b) {
    return a.translation() == b.translation() && a.rotation().coeffs() == b.rotation().coeffs();
  };
  const bool moved = !same(old_vo, T_D_vo_) || !same(old_gt, T_D_gt_);
  if (moved) ++version_;
  if (options_.frame_vehicle && viewed_ != gravity_ && scene_ && !vo_buf_.empty()) {
    // Once per display frame: look at the vehicle's start from behind-left and above
    // (GridRenderer's direction), 8 m away, rather than at the whole grid.
    viewed_ = gravity_;
    const Eigen::Vector3d c = T_D_vo_ * vo_buf_.front().T_world_camera.translation();
    const Eigen::Vector3d eye = c + 8.0 * Eigen::Vector3d(-0.9, -1.3, 0.9).normalized();
    vtkCamera* cam = scene_->GetActiveCamera();
    cam->SetFocalPoint(c.x(), c.y(), c.z());
    cam->SetPosition(eye.x(), eye.y(), eye.z());
    cam->SetViewUp(0, 0, 1);
    scene_->ResetCameraClippingRange();
    moved_view = true;
  }
  const std::string text = label();
  const bool relabelled = text != shown_label_;
  if (relabelled && label_) label_->SetInput(text.c_str());
  shown_label_ = text;
  return moved || relabelled || moved_view;
}

// ---------------------------------------------------------------- grid
GridRenderer::GridRenderer(double half_size_m, double spacing_m)
    : Renderer("grid"), half_(half_size_m), spacing_(spacing_m) {}

void GridRenderer::attach(Layout& layout) {
  draws_in(layout.scene);
  grid_ = line_actor(0.45, 0.45, 0.5, 1);
  auto pts = vtkSmartPointer<vtkPoints>::New();
  auto lines = vtkSmartPointer<vtkCellArray>::New();
  for (double s = -half_; s <= half_ + 1e-9; s += spacing_) {
    const vtkIdType a = pts->InsertNextPoint(s, -half_, 0), b = pts->InsertNextPoint(s, half_, 0);
    const vtkIdType c = pts->InsertNextPoint(-half_, s, 0), d = pts->InsertNextPoint(half_, s, 0);
    const vtkIdType l1[2] = {a, b}, l2[2] = {c, d};
    lines->InsertNextCell(2, l1);
    lines->InsertNextCell(2, l2);
  }
  poly_of(grid_)->SetPoints(pts);
  poly_of(grid_)->SetLines(lines);
  auto axes = vtkSmartPointer<vtkAxesActor>::New();
  axes->SetTotalLength(1, 1, 1);
  axes->AxisLabelsOff();
  axes_ = axes;
  layout.scene->AddActor(grid_);
  layout.scene->AddActor(axes_);
  // An oblique view from behind-left and above; world z is up.
  vtkCamera* cam = layout.scene->GetActiveCamera();
  cam->SetFocalPoint(0, 0, 0);
  cam->SetPosition(-0.9 * half_, -1.3 * half_, 0.9 * half_);
  cam->SetViewUp(0, 0, 1);
  layout.scene->ResetCamera();
}

void GridRenderer::on_enabled(bool on) {
  if (grid_) grid_->SetVisibility(on);
  if (axes_) axes_->SetVisibility(on);
}

// ---------------------------------------------------------------- poses
PoseRenderer::PoseRenderer(std::string name, std::string channel, bool ground_truth, size_t max_poses)
    : Renderer(std::move(name)), channel_(std::move(channel)), gt_(ground_truth), poses_(max_poses) {
  if (max_poses == 0) throw std::invalid_argument("viewer: a trajectory needs at least one pose");
}

void PoseRenderer::subscribe(bus::Bus& bus) {
  if (gt_) {
    bus.subscribe<aerie::gt_pose_t>(channel_, [this](const aerie::gt_pose_t& m, const bus::ReceiveInfo&) {
      poses_.push({m.utime, geometry::SE3::from_wxyz(m.orientation, m.position)});
    });
  } else {
    bus.subscribe<aerie::pose_t>(channel_, [this](const aerie::pose_t& m, const bus::ReceiveInfo&) {
      if (m.status == aerie::pose_t::RESET) poses_.clear();
      poses_.push({m.utime, geometry::SE3::from_wxyz(m.orientation, m.position)});
    });
  }
}

void PoseRenderer::attach(Layout& layout) {
  draws_in(layout.scene);
  // Ground truth in green, the estimate in orange.
  const double r = gt_ ? 0.2 : 1.0, g = gt_ ? 0.9 : 0.55, b = gt_ ? 0.3 : 0.1;
  path_ = line_actor(r, g, b, 2);
  frustum_ = line_actor(r, g, b, 2);
  scene_ = layout.scene;
  scene_->AddActor(path_);
  scene_->AddActor(frustum_);
}

bool PoseRenderer::update() {
  if (world_changed()) {
    const geometry::SE3 T = gt_ ? from_gt() : from_vo();
    place(path_, T);
    place(frustum_, T);
    if (!poses_.snapshot_if_newer(seen_, buffer_)) return true;
  } else if (!poses_.snapshot_if_newer(seen_, buffer_)) {
    return false;
  }
  auto pts = vtkSmartPointer<vtkPoints>::New();
  auto line = vtkSmartPointer<vtkCellArray>::New();
  line->InsertNextCell(static_cast<vtkIdType>(buffer_.size()));
  for (const auto& p : buffer_) {
    const auto& t = p.T_world_camera.translation();
    line->InsertCellPoint(pts->InsertNextPoint(t.x(), t.y(), t.z()));
  }
  poly_of(path_)->SetPoints(pts);
  poly_of(path_)->SetLines(line);
  poly_of(path_)->Modified();
  if (!buffer_.empty()) set_frustum(poly_of(frustum_), buffer_.back().T_world_camera);
  shown_ = buffer_.size();
  if (!camera_fitted_ && shown_ > 1 && !world_frames_the_view()) {
    scene_->ResetCamera();
    camera_fitted_ = true;
  }
  return true;
}

int64_t PoseRenderer::latest_utime() const { return 0; }

void PoseRenderer::on_enabled(bool on) {
  if (path_) path_->SetVisibility(on);
  if (frustum_) frustum_->SetVisibility(on);
}

// ---------------------------------------------------------------- depth cloud
DepthCloudRenderer::DepthCloudRenderer(std::string channel) : Renderer("depth"), channel_(std::move(channel)) {}

void DepthCloudRenderer::subscribe(bus::Bus& bus) {
  bus.subscribe<aerie::spherical_depth_t>(
      channel_,
      [this](const aerie::spherical_depth_t& m, const bus::ReceiveInfo&) {
        const auto depth = spherical::from_message(m);
        const auto pose = spherical::pose_of(m);
        if (!pose) throw std::invalid_argument("VO_DEPTH frame without a pose cannot be placed in the world");
        std::vector<Eigen::Vector3f> pts = depth.decode();
        const Eigen::Matrix3f R = pose->rotation_matrix().cast<float>();
        const Eigen::Vector3f t = pose->translation().cast<float>();
        for (auto& p : pts) p = R * p + t;
        cloud_.set(std::move(pts));
      },
      2);
}

void DepthCloudRenderer::attach(Layout& layout) {
  draws_in(layout.scene);
  actor_ = line_actor(0.3, 0.9, 1.0, 1);
  actor_->GetProperty()->SetPointSize(2);
  layout.scene->AddActor(actor_);
}

bool DepthCloudRenderer::update() {
  const bool moved = world_changed();
  if (moved) place(actor_, from_vo());
  std::vector<Eigen::Vector3f> pts;
  if (!cloud_.take_if_newer(seen_, pts)) return moved;
  auto points = vtkSmartPointer<vtkPoints>::New();
  points->SetDataTypeToFloat();
  points->SetNumberOfPoints(static_cast<vtkIdType>(pts.size()));
  auto verts = vtkSmartPointer<vtkCellArray>::New();
  for (size_t i = 0; i < pts.size(); ++i) {
    points->SetPoint(static_cast<vtkIdType>(i), pts[i].x(), pts[i].y(), pts[i].z());
    const vtkIdType id = static_cast<vtkIdType>(i);
    verts->InsertNextCell(1, &id);
  }
  poly_of(actor_)->SetPoints(points);
  poly_of(actor_)->SetVerts(verts);
  poly_of(actor_)->Modified();
  shown_ = pts.size();
  return true;
}

void DepthCloudRenderer::on_enabled(bool on) {
  if (actor_) actor_->SetVisibility(on);
}

// ---------------------------------------------------------------- octomap
// The map is merged and meshed by a thread of its own, so that neither the LCM thread
// nor the render thread waits for a large map (100k voxels take ~100 ms to mesh).
struct OctomapRenderer::Map {
  struct Surface {
    VoxelMesh mesh;
    double zmin = 0, zmax = 1, resolution = 0;
    int coarsening_shown = 0;
  };
  std::mutex m;
  std::condition_variable wake;
  std::deque<std::pair<std::unique_ptr<octomap::OcTree>, bool>> inbox;  // parsed messages, full?
  int coarsening = 0;
  size_t max_quads = 0;
  uint64_t settings = 1;  // bumped when coarsening changes
  bool stop = false;
  std::optional<Surface> ready;  // the newest surface, until the render thread takes it
  std::thread mesher;

  void run();
};

void OctomapRenderer::Map::run() {
  std::unique_ptr<octomap::OcTree> tree;
  uint64_t meshed_settings = 0;
  int last_levels = 0;  // shown last time: a growing map does not get finer again
  for (;;) {
    std::deque<std::pair<std::unique_ptr<octomap::OcTree>, bool>> messages;
    int levels = 0;
    size_t budget = 0;
    {
      std::unique_lock lock(m);
      wake.wait(lock, [&] { return stop || !inbox.empty() || settings != meshed_settings; });
      if (stop) return;
      messages.swap(inbox);
      levels = settings != meshed_settings ? coarsening : std::max(coarsening, last_levels);
      budget = max_quads;
      meshed_settings = settings;
    }
    for (auto& [incoming, full] : messages) {
      if (full || !tree || tree->getResolution() != incoming->getResolution()) {
        tree = std::move(incoming);
      } else {
        // A changed region: its leaves (occupied and free) overwrite the local copy.
        for (auto it = incoming->begin_leafs(); it != incoming->end_leafs(); ++it)
          tree->setNodeValue(it.getCoordinate(), it->getLogOdds(), true);
      }
    }
    if (!tree) continue;
    Surface s;
    double lo[3], hi[3];
    tree->getMetricMin(lo[0], lo[1], lo[2]);
    tree->getMetricMax(hi[0], hi[1], hi[2]);
    s.zmin = lo[2];
    s.zmax = std::max(hi[2], s.zmin + 1e-3);
    s.coarsening_shown = levels;
    s.mesh = mesh_occupied_surface(*tree, levels);
    while (budget > 0 && s.mesh.quads.size() > budget && s.coarsening_shown < 4)
      s.mesh = mesh_occupied_surface(*tree, ++s.coarsening_shown);
    s.resolution = tree->getNodeSize(tree->getTreeDepth() - static_cast<unsigned>(s.coarsening_shown));
    last_levels = s.coarsening_shown;
    std::lock_guard lock(m);
    ready = std::move(s);
  }
}

OctomapRenderer::OctomapRenderer(std::string channel, size_t max_quads)
    : Renderer("octomap"), channel_(std::move(channel)), map_(std::make_unique<Map>()) {
  map_->max_quads = max_quads;
  map_->mesher = std::thread([this] { map_->run(); });
}

OctomapRenderer::~OctomapRenderer() {
  {
    std::lock_guard lock(map_->m);
    map_->stop = true;
  }
  map_->wake.notify_all();
  map_->mesher.join();
}

void OctomapRenderer::subscribe(bus::Bus& bus) {
  bus.subscribe<aerie::octomap_t>(
      channel_,
      [this](const aerie::octomap_t& m, const bus::ReceiveInfo&) {
        auto incoming = map::decode_octree(m);  // a malformed message throws here and is counted
        {
          std::lock_guard lock(map_->m);
          map_->inbox.emplace_back(std::move(incoming), m.full);
        }
        map_->wake.notify_one();
      },
      4);
}

void OctomapRenderer::attach(Layout& layout) {
  draws_in(layout.scene);
  auto mapper = vtkSmartPointer<vtkPolyDataMapper>::New();
  mapper->SetInputData(vtkSmartPointer<vtkPolyData>::New());
  mapper->SetScalarModeToUsePointData();
  mapper->InterpolateScalarsBeforeMappingOn();  // height colours per pixel, not per corner
  mapper->ScalarVisibilityOn();
  auto lut = vtkSmartPointer<vtkLookupTable>::New();
  lut->SetHueRange(0.667, 0.0);  // blue (low) to red (high)
  lut->Build();
  mapper->SetLookupTable(lut);
  actor_ = vtkSmartPointer<vtkActor>::New();
  actor_->SetMapper(mapper);
  actor_->GetProperty()->BackfaceCullingOn();  // the quads face out of the occupied space
  layout.scene->AddActor(actor_);
  label_ = vtkSmartPointer<vtkTextActor>::New();
  label_->GetTextProperty()->SetFontSize(12);
  label_->GetTextProperty()->SetColor(0.8, 0.8, 0.8);
  label_->SetPosition(6, 6);
  layout.scene->AddActor2D(label_);
}

void OctomapRenderer::set_coarsening(int levels) {
  coarsening_ = std::clamp(levels, 0, 4);
  {
    std::lock_guard lock(map_->m);
    map_->coarsening = coarsening_;
    ++map_->settings;
  }
  map_->wake.notify_one();
}

bool OctomapRenderer::on_key(const std::string& key) {
  if (key != "v") return false;
  set_coarsening((coarsening_ + 1) % 4);
  return true;
}

// The mesher's newest surface (voxel_mesh.hpp) to VTK, coloured by height: the corners
// carry their z, interpolated across each quad.
bool OctomapRenderer::update() {
  std::optional<Map::Surface> surface;
  {
    std::lock_guard lock(map_->m);
    surface.swap(map_->ready);
  }
  if (world_changed()) {
    place(actor_, from_vo());
    colour_by_height(actor_, from_vo());
    if (!surface) return true;
  }
  if (!surface) return false;
  const VoxelMesh& mesh = surface->mesh;
  auto points = vtkSmartPointer<vtkPoints>::New();
  points->SetDataTypeToFloat();
  points->SetNumberOfPoints(static_cast<vtkIdType>(mesh.points.size()));
  auto height = vtkSmartPointer<vtkFloatArray>::New();
  height->SetName("height");
  height->SetNumberOfValues(static_cast<vtkIdType>(mesh.points.size()));
  for (vtkIdType i = 0; i < static_cast<vtkIdType>(mesh.points.size()); ++i) {
    const auto& p = mesh.points[static_cast<size_t>(i)];
    points->SetPoint(i, p.data());
    height->SetValue(i, p[2]);
  }
  auto quads = vtkSmartPointer<vtkCellArray>::New();
  quads->AllocateExact(static_cast<vtkIdType>(mesh.quads.size()), static_cast<vtkIdType>(4 * mesh.quads.size()));
  for (const auto& q : mesh.quads) {
    const vtkIdType ids[4] = {q[0], q[1], q[2], q[3]};
    quads->InsertNextCell(4, ids);
  }
  auto poly = vtkSmartPointer<vtkPolyData>::New();
  poly->SetPoints(points);
  poly->SetPolys(quads);
  poly->GetPointData()->SetScalars(height);
  auto* mapper = vtkPolyDataMapper::SafeDownCast(actor_->GetMapper());
  mapper->SetInputData(poly);
  colour_by_height(actor_, from_vo());  // height in the display frame (z up), not in VO's world
  shown_ = mesh.voxels;
  quads_ = mesh.quads.size();
  shown_coarsening_ = surface->coarsening_shown;
  char text[128];
  std::snprintf(text, sizeof(text), "map: %zu voxels of %.2f m%s", shown_, surface->resolution,
                shown_coarsening_ > coarsening_ ? " (coarser: quad budget)" : "");
  label_->SetInput(text);
  return true;
}

void OctomapRenderer::on_enabled(bool on) {
  if (actor_) actor_->SetVisibility(on);
  if (label_) label_->SetVisibility(on);
}

// ---------------------------------------------------------------- target
TargetPoseRenderer::TargetPoseRenderer(std::string channel, std::string pose_channel, std::string gt_pose_channel)
    : Renderer("target"),
      channel_(std::move(channel)),
      pose_channel_(std::move(pose_channel)),
      gt_pose_channel_(std::move(gt_pose_channel)) {}

void TargetPoseRenderer::subscribe(bus::Bus& bus) {
  bus.subscribe<aerie::target_pose_t>(channel_,
                                      [this](const aerie::target_pose_t& m, const bus::ReceiveInfo&) { target_.set(m); });
  bus.subscribe<aerie::pose_t>(pose_channel_, [this](const aerie::pose_t& m, const bus::ReceiveInfo&) {
    camera_.set({geometry::SE3::from_wxyz(m.orientation, m.position), false});
  });
  bus.subscribe<aerie::gt_pose_t>(gt_pose_channel_, [this](const aerie::gt_pose_t& m, const bus::ReceiveInfo&) {
    camera_.set({geometry::SE3::from_wxyz(m.orientation, m.position), true});
  });
}

void TargetPoseRenderer::attach(Layout& layout) {
  draws_in(layout.scene);
  auto sphere = vtkSmartPointer<vtkSphereSource>::New();
  sphere->SetRadius(0.15);
  auto mapper = vtkSmartPointer<vtkPolyDataMapper>::New();
  mapper->SetInputConnection(sphere->GetOutputPort());
  actor_ = vtkSmartPointer<vtkActor>::New();
  actor_->SetMapper(mapper);
  actor_->GetProperty()->SetColor(1, 0.1, 0.1);
  actor_->VisibilityOff();
  layout.scene->AddActor(actor_);
}

bool TargetPoseRenderer::update() {
  aerie::target_pose_t t;
  Camera c;
  bool changed = world_changed();
  if (target_.take_if_newer(seen_target_, t)) {
    current_ = t;
    changed = true;
  }
  if (camera_.take_if_newer(seen_camera_, c)) {
    current_camera_ = c;
    changed = true;
  }
  if (!changed || !current_ || !current_camera_) return false;
  const geometry::SE3 T_display_cam =
      (current_camera_->ground_truth ? from_gt() : from_vo()) * current_camera_->T;
  const Eigen::Vector3d w =
      T_display_cam * Eigen::Vector3d(current_->position[0], current_->position[1], current_->position[2]);
  actor_->SetPosition(w.x(), w.y(), w.z());
  actor_->SetVisibility(enabled());
  return true;
}

void TargetPoseRenderer::on_enabled(bool on) {
  if (actor_) actor_->SetVisibility(on && current_.has_value());
}

}  // namespace aerie::viewer
