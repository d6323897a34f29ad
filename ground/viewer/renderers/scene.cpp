#include "ground/viewer/renderers/scene.hpp"

#include <octomap/OcTree.h>
#include <spdlog/spdlog.h>
#include <vtkAxesActor.h>
#include <vtkCamera.h>
#include <vtkCellArray.h>
#include <vtkFloatArray.h>
#include <vtkLookupTable.h>
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

}  // namespace

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
  if (!poses_.snapshot_if_newer(seen_, buffer_)) return false;
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
  if (!camera_fitted_ && shown_ > 1) {
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
  std::vector<Eigen::Vector3f> pts;
  if (!cloud_.take_if_newer(seen_, pts)) return false;
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
  mapper->SetScalarRange(surface->zmin, surface->zmax);
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
    camera_.set(geometry::SE3::from_wxyz(m.orientation, m.position));
  });
  bus.subscribe<aerie::gt_pose_t>(gt_pose_channel_, [this](const aerie::gt_pose_t& m, const bus::ReceiveInfo&) {
    camera_.set(geometry::SE3::from_wxyz(m.orientation, m.position));
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
  geometry::SE3 c;
  bool changed = false;
  if (target_.take_if_newer(seen_target_, t)) {
    current_ = t;
    changed = true;
  }
  if (camera_.take_if_newer(seen_camera_, c)) {
    current_camera_ = c;
    changed = true;
  }
  if (!changed || !current_ || !current_camera_) return false;
  const Eigen::Vector3d w = *current_camera_ * Eigen::Vector3d(current_->position[0], current_->position[1], current_->position[2]);
  actor_->SetPosition(w.x(), w.y(), w.z());
  actor_->SetVisibility(enabled());
  return true;
}

void TargetPoseRenderer::on_enabled(bool on) {
  if (actor_) actor_->SetVisibility(on && current_.has_value());
}

}  // namespace aerie::viewer
