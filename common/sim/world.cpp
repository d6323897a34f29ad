#include "common/sim/world.hpp"

#include <opencv2/imgproc.hpp>

#include <algorithm>
#include <cmath>
#include <limits>
#include <stdexcept>
#include <string>

#include "common/sim/texture.hpp"

namespace aerie::sim {

namespace {

constexpr double kPi = 3.14159265358979323846;

// Surface indices: the room's six faces first (2 * axis + side, side 1 = max face), then
// six per obstacle in the same order.
Surface make_face(const Aabb& box, int axis, int side, bool room) {
  Surface s;
  s.axis = axis;
  s.offset = side ? box.max[axis] : box.min[axis];
  // Room faces look inwards, obstacle faces outwards.
  s.normal_sign = (side == 0) == room ? 1 : -1;
  if (axis == 2) {
    s.u_axis = 0;
    s.v_axis = 1;
    s.u0 = box.min[0];
    s.v0 = box.max[1];  // image rows run towards -y (north up when seen from above)
    s.v_sign = -1;
  } else {
    s.u_axis = axis == 0 ? 1 : 0;
    s.v_axis = 2;
    s.u0 = box.min[s.u_axis];
    s.v0 = box.max[2];  // image rows run downwards
    s.v_sign = -1;
  }
  s.u_len = box.max[s.u_axis] - box.min[s.u_axis];
  s.v_len = box.max[s.v_axis] - box.min[s.v_axis];
  return s;
}

// xy distance from a point to an axis-aligned footprint.
double footprint_distance(const Aabb& b, double x, double y) {
  const double dx = std::max({b.min.x() - x, 0.0, x - b.max.x()});
  const double dy = std::max({b.min.y() - y, 0.0, y - b.max.y()});
  return std::hypot(dx, dy);
}

// Points along the route the trajectories fly (survey rounded rectangle, approach line,
// helipad), used to keep obstacles clear of it.
std::vector<Eigen::Vector2d> route_samples(const World::Route& r, const Helipad& pad) {
  std::vector<Eigen::Vector2d> pts;
  const double step = 0.05;
  auto line = [&](Eigen::Vector2d a, Eigen::Vector2d b) {
    const int n = std::max(1, static_cast<int>(std::ceil((b - a).norm() / step)));
    for (int i = 0; i <= n; ++i) pts.push_back(a + (b - a) * (static_cast<double>(i) / n));
  };
  line({r.x_min, r.y_min}, {r.x_max, r.y_min});
  line({r.x_max, r.y_min}, {r.x_max, r.y_max});
  line({r.x_max, r.y_max}, {r.x_min, r.y_max});
  line({r.x_min, r.y_max}, {r.x_min, r.y_min});
  line(r.home.head<2>(), pad.center.head<2>());
  // The helipad square itself (with its diagonal so that its inside is covered).
  const auto c = pad.corners();
  for (int i = 0; i < 4; ++i) line(c[i].head<2>(), c[(i + 1) % 4].head<2>());
  line(c[0].head<2>(), c[2].head<2>());
  line(c[1].head<2>(), c[3].head<2>());
  return pts;
}

// Paints the helipad (dark square, white ring, white H) into the floor texture, with
// 4x4 supersampling per texel for anti-aliased edges.
void paint_helipad(cv::Mat& tex, const Surface& floor, const Helipad& pad, double density) {
  const double s = pad.size;
  const double half = 0.5 * s * std::sqrt(2.0) + 0.02;
  const double cy = std::cos(pad.yaw), sy = std::sin(pad.yaw);
  // Texel range covering the pad.
  auto to_texel_u = [&](double x) { return (x - floor.u0) * density; };
  auto to_texel_v = [&](double y) { return (floor.v0 - y) * density; };
  const int u_lo = std::max(0, static_cast<int>(to_texel_u(pad.center.x() - half)));
  const int u_hi = std::min(tex.cols - 1, static_cast<int>(to_texel_u(pad.center.x() + half)) + 1);
  const int v_lo = std::max(0, static_cast<int>(to_texel_v(pad.center.y() + half)));
  const int v_hi = std::min(tex.rows - 1, static_cast<int>(to_texel_v(pad.center.y() - half)) + 1);
  // Marking in pad-local coordinates normalised by the size: returns paint (1 white,
  // 0 dark) or -1 outside the pad.
  auto marking = [&](double lx, double ly) -> double {
    const double ax = std::abs(lx), ay = std::abs(ly);
    if (ax > 0.5 || ay > 0.5) return -1.0;
    const double r = std::hypot(lx, ly);
    if (r > 0.40 && r < 0.46) return 1.0;  // ring
    // "H": two vertical legs and a bar; the bar runs along local x.
    const bool leg = ay < 0.24 && ax > 0.11 && ax < 0.19;
    const bool bar = ax < 0.11 && ay < 0.035;
    if (leg || bar) return 1.0;
    if (ax > 0.485 || ay > 0.485) return 1.0;  // thin white border
    return 0.0;
  };
  for (int v = v_lo; v <= v_hi; ++v) {
    auto* row = tex.ptr<uint8_t>(v);
    for (int u = u_lo; u <= u_hi; ++u) {
      double paint = 0.0;
      int inside = 0;
      for (int j = 0; j < 4; ++j)
        for (int i = 0; i < 4; ++i) {
          const double x = floor.u0 + (u + (i + 0.5) / 4.0) / density - pad.center.x();
          const double y = floor.v0 - (v + (j + 0.5) / 4.0) / density - pad.center.y();
          const double lx = (cy * x + sy * y) / s, ly = (-sy * x + cy * y) / s;
          const double m = marking(lx, ly);
          if (m >= 0) {
            paint += m;
            ++inside;
          }
        }
      if (!inside) continue;
      // Dark pad with a faint trace of the floor texture, white paint.
      const double base = 0.25 * row[u] + 20.0;
      const double col = (paint * 235.0 + (inside - paint) * base) / inside;
      const double w = inside / 16.0;
      row[u] = cv::saturate_cast<uint8_t>(w * col + (1.0 - w) * row[u]);
    }
  }
}

// Diffuse light baked into a surface's texture (view-independent, so both cameras agree):
// ambient plus Lambertian lamps with inverse-square falloff and hard shadows of the
// obstacles, evaluated every 10 cm and interpolated (which softens the shadow edges).
void bake_lighting(const World& w, const Surface& s, const std::vector<Eigen::Vector3d>& lamps, cv::Mat& tex) {
  constexpr double kStep = 0.1, kAmbient = 0.3, kMax = 1.05;
  const double power = 0.25 * w.config().room_z * w.config().room_z;
  const int nu = std::max(2, static_cast<int>(std::ceil(s.u_len / kStep)) + 1);
  const int nv = std::max(2, static_cast<int>(std::ceil(s.v_len / kStep)) + 1);
  Eigen::Vector3d n = Eigen::Vector3d::Zero();
  n[s.axis] = s.normal_sign;
  cv::Mat light(nv, nu, CV_32F);
  for (int j = 0; j < nv; ++j)
    for (int i = 0; i < nu; ++i) {
      Eigen::Vector3d p;
      p[s.axis] = s.offset;
      p[s.u_axis] = s.u0 + s.u_len * i / (nu - 1);
      p[s.v_axis] = s.v0 + s.v_sign * s.v_len * j / (nv - 1);
      double e = kAmbient;
      for (const auto& lamp : lamps) {
        const Eigen::Vector3d l = lamp - p;
        const double r2 = l.squaredNorm(), cos_in = n.dot(l) / std::sqrt(r2);
        if (cos_in <= 0) continue;
        if (w.raycast(p + 1e-6 * n, l, 1.0 - 1e-6)) continue;  // in the shadow of an obstacle
        e += power * cos_in / r2;
      }
      light.at<float>(j, i) = static_cast<float>(std::min(e, kMax));
    }
  cv::Mat up;
  cv::resize(light, up, tex.size(), 0, 0, cv::INTER_LINEAR);
  cv::Mat lit;
  tex.convertTo(lit, CV_32F);
  lit = lit.mul(up);
  lit.convertTo(tex, CV_8U);
}

}  // namespace

std::array<Eigen::Vector3d, 4> Helipad::corners() const {
  const double h = 0.5 * size, c = std::cos(yaw), s = std::sin(yaw);
  const double local[4][2] = {{-h, -h}, {h, -h}, {h, h}, {-h, h}};
  std::array<Eigen::Vector3d, 4> out;
  for (int i = 0; i < 4; ++i)
    out[i] = center + Eigen::Vector3d(c * local[i][0] - s * local[i][1],
                                      s * local[i][0] + c * local[i][1], 0.0);
  return out;
}

World World::room(const WorldConfig& cfg) {
  auto check = [](bool ok, const std::string& what) {
    if (!ok) throw std::invalid_argument("sim::WorldConfig: " + what);
  };
  check(cfg.room_x >= 4 && cfg.room_y >= 4 && cfg.room_z >= 2,
        "room_x, room_y must be >= 4 m and room_z >= 2 m");
  check(cfg.n_obstacles >= 0, "n_obstacles must be >= 0");
  check(cfg.helipad_size > 0.1 && cfg.helipad_size < 0.5 * std::min(cfg.room_x, cfg.room_y),
        "helipad_size must be in (0.1, half the room)");
  check(cfg.texels_per_metre >= 8 && cfg.texels_per_metre <= 1000,
        "texels_per_metre must be in [8, 1000]");
  check(cfg.route_margin >= 0.5 && 2 * cfg.route_margin < std::min(cfg.room_x, cfg.room_y) - 1.0,
        "route_margin must be >= 0.5 m and leave at least 1 m of route");
  check(cfg.cruise_altitude > 0.3 && cfg.cruise_altitude < cfg.room_z - 0.3,
        "cruise_altitude must be at least 0.3 m from floor and ceiling");

  World w;
  w.config_ = cfg;
  w.bounds_.min = {-0.5 * cfg.room_x, -0.5 * cfg.room_y, 0.0};
  w.bounds_.max = {0.5 * cfg.room_x, 0.5 * cfg.room_y, cfg.room_z};

  // Survey route and home (middle of its west edge), helipad on the approach line east of
  // the room centre.
  Route& r = w.route_;
  r.x_min = w.bounds_.min.x() + cfg.route_margin;
  r.x_max = w.bounds_.max.x() - cfg.route_margin;
  r.y_min = w.bounds_.min.y() + cfg.route_margin;
  r.y_max = w.bounds_.max.y() - cfg.route_margin;
  r.corner_radius = std::min(1.0, 0.3 * std::min(r.x_max - r.x_min, r.y_max - r.y_min));
  r.altitude = cfg.cruise_altitude;
  r.home = {r.x_min, 0.5 * (r.y_min + r.y_max), 0.0};
  w.helipad_.center = {0.4 * r.x_max, r.home.y(), 0.0};
  w.helipad_.yaw = cfg.helipad_yaw_deg * kPi / 180.0;
  w.helipad_.size = cfg.helipad_size;

  // Obstacles: random boxes and pillars clear of the route and of each other.
  cv::RNG rng(mix_seed(cfg.seed, 1));
  const auto keep_out = route_samples(r, w.helipad_);
  int attempts = 0;
  while (static_cast<int>(w.obstacles_.size()) < cfg.n_obstacles) {
    if (++attempts > 20000)
      throw std::invalid_argument("sim::WorldConfig: cannot place " +
                                  std::to_string(cfg.n_obstacles) +
                                  " obstacles clear of the route; lower n_obstacles or "
                                  "route_clearance, or enlarge the room");
    Obstacle o;
    o.kind = rng.uniform(0.0, 1.0) < 0.35 ? Obstacle::Kind::Pillar : Obstacle::Kind::Box;
    Eigen::Vector3d size;
    if (o.kind == Obstacle::Kind::Pillar) {
      const double a = rng.uniform(0.3, 0.6);
      size = {a, a, cfg.room_z};
    } else {
      size = {rng.uniform(0.4, 1.4), rng.uniform(0.4, 1.4), rng.uniform(0.4, 2.0)};
    }
    const Eigen::Vector3d lo(rng.uniform(w.bounds_.min.x(), w.bounds_.max.x() - size.x()),
                             rng.uniform(w.bounds_.min.y(), w.bounds_.max.y() - size.y()), 0.0);
    o.box = {lo, lo + size};
    bool ok = true;
    for (const auto& p : keep_out)
      if (footprint_distance(o.box, p.x(), p.y()) < cfg.route_clearance) {
        ok = false;
        break;
      }
    for (const auto& other : w.obstacles_) {
      // at least 0.3 m between obstacles, so that none hides inside another
      Aabb grown = other.box;
      grown.min.head<2>().array() -= 0.3;
      grown.max.head<2>().array() += 0.3;
      if (!(o.box.max.x() < grown.min.x() || o.box.min.x() > grown.max.x() ||
            o.box.max.y() < grown.min.y() || o.box.min.y() > grown.max.y()))
        ok = false;
    }
    if (ok) w.obstacles_.push_back(o);
  }

  // Surfaces and their textures (level 0 first; lighting and the helipad go on top).
  const double density = cfg.texels_per_metre;
  std::vector<cv::Mat> images;
  auto add = [&](Surface s, Material m, uint64_t stream) {
    images.push_back(make_texture(m, s.u_len, s.v_len, density, mix_seed(cfg.seed, stream)));
    w.surfaces_.push_back(s);
  };
  const cv::Vec3f wall_tints[4] = {{0.85f, 0.95f, 1.1f}, {1.1f, 0.95f, 0.85f},
                                   {0.9f, 1.1f, 0.9f}, {1.05f, 1.0f, 1.05f}};
  for (int axis = 0; axis < 3; ++axis)
    for (int side = 0; side < 2; ++side) {
      Surface s = make_face(w.bounds_, axis, side, true);
      Material m = Material::Wall;
      if (axis < 2) {
        s.tint = wall_tints[2 * axis + side];
      } else if (side == 0) {
        m = Material::Floor;
        s.tint = {0.95f, 1.0f, 1.0f};
      } else {
        m = Material::Ceiling;
      }
      add(s, m, 100 + 2 * axis + side);
    }
  for (size_t i = 0; i < w.obstacles_.size(); ++i) {
    const auto& o = w.obstacles_[i];
    const cv::Vec3f tint = o.kind == Obstacle::Kind::Pillar ? cv::Vec3f(1.0f, 1.0f, 1.0f)
                                                            : cv::Vec3f(0.7f, 0.95f, 1.2f);
    for (int axis = 0; axis < 3; ++axis)
      for (int side = 0; side < 2; ++side) {
        Surface s = make_face(o.box, axis, side, false);
        s.tint = tint;
        add(s, o.kind == Obstacle::Kind::Pillar ? Material::Pillar : Material::Crate,
            1000 + 6 * i + 2 * axis + side);
      }
  }
  paint_helipad(images[4], w.surfaces_[4], w.helipad_, density);  // surface 4: the floor
  // Ceiling lamps on a ~3 m grid (none inside a pillar); the ceiling itself is lit only by
  // the ambient term, its light panels are in its texture.
  std::vector<Eigen::Vector3d> lamps;
  const int nx = std::max(1, static_cast<int>(std::lround(cfg.room_x / 3.0)));
  const int ny = std::max(1, static_cast<int>(std::lround(cfg.room_y / 3.0)));
  for (int j = 0; j < ny; ++j)
    for (int i = 0; i < nx; ++i) {
      const Eigen::Vector3d lamp(w.bounds_.min.x() + cfg.room_x * (i + 0.5) / nx,
                                 w.bounds_.min.y() + cfg.room_y * (j + 0.5) / ny, cfg.room_z - 0.1);
      if (!w.occupied(lamp)) lamps.push_back(lamp);
    }
  auto textures = std::make_shared<Textures>();
  for (size_t k = 0; k < images.size(); ++k) {
    if (k == 5) {
      w.surfaces_[k].shade = 0.7f;
    } else {
      bake_lighting(w, w.surfaces_[k], lamps, images[k]);
    }
    textures->surfaces.emplace_back(images[k], density);
  }
  w.textures_ = std::move(textures);
  return w;
}

bool World::occupied(const Eigen::Vector3d& p) const { return signed_distance(p) < 0.0; }

double World::distance(const Eigen::Vector3d& p) const { return std::abs(signed_distance(p)); }

double World::signed_distance(const Eigen::Vector3d& p) const {
  // Room interior: distance to the nearest wall plane; outside: distance to the box.
  double d;
  if (bounds_.contains(p)) {
    d = std::min((p - bounds_.min).minCoeff(), (bounds_.max - p).minCoeff());
  } else {
    const Eigen::Vector3d out =
        (bounds_.min - p).cwiseMax(p - bounds_.max).cwiseMax(Eigen::Vector3d::Zero());
    return -out.norm();
  }
  for (const auto& o : obstacles_) {
    const Eigen::Vector3d out =
        (o.box.min - p).cwiseMax(p - o.box.max).cwiseMax(Eigen::Vector3d::Zero());
    if (out.isZero()) {
      // Inside: depth to the nearest face (negative).
      const double depth = std::min((p - o.box.min).minCoeff(), (o.box.max - p).minCoeff());
      return -depth;
    }
    d = std::min(d, out.norm());
  }
  return d;
}

std::optional<RayHit> World::raycast(const Eigen::Vector3d& o, const Eigen::Vector3d& dir,
                                     double max_t) const {
  if (dir.isZero()) throw std::invalid_argument("World::raycast: zero direction");
  RayHit best;
  best.t = std::numeric_limits<double>::infinity();
  // Room faces, from inside (only when the origin is inside the room).
  if (bounds_.contains(o)) {
    for (int a = 0; a < 3; ++a) {
      if (dir[a] == 0.0) continue;
      const int side = dir[a] > 0 ? 1 : 0;
      const double t = ((side ? bounds_.max[a] : bounds_.min[a]) - o[a]) / dir[a];
      if (t > 0 && t < best.t) {
        best.t = t;
        best.surface = 2 * a + side;
      }
    }
  }
  // Obstacles: slab test, entry face.
  for (size_t i = 0; i < obstacles_.size(); ++i) {
    const Aabb& b = obstacles_[i].box;
    double t_near = -std::numeric_limits<double>::infinity();
    double t_far = std::numeric_limits<double>::infinity();
    int axis = -1;
    bool miss = false;
    for (int a = 0; a < 3 && !miss; ++a) {
      if (dir[a] == 0.0) {
        if (o[a] < b.min[a] || o[a] > b.max[a]) miss = true;
        continue;
      }
      double t1 = (b.min[a] - o[a]) / dir[a], t2 = (b.max[a] - o[a]) / dir[a];
      if (t1 > t2) std::swap(t1, t2);
      if (t1 > t_near) {
        t_near = t1;
        axis = a;
      }
      t_far = std::min(t_far, t2);
    }
    if (miss || axis < 0 || t_near > t_far || t_near <= 0 || t_near >= best.t) continue;
    best.t = t_near;
    best.surface = static_cast<int>(6 + 6 * i + 2 * axis + (dir[axis] > 0 ? 0 : 1));
  }
  if (best.surface < 0 || best.t > max_t) return std::nullopt;
  best.point = o + best.t * dir;
  const Surface& s = surfaces_[best.surface];
  best.normal = Eigen::Vector3d::Zero();
  best.normal[s.axis] = s.normal_sign;
  best.point[s.axis] = s.offset;  // exactly on the plane
  return best;
}

}  // namespace aerie::sim
