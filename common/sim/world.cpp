#include "common/sim/world.hpp"

#include <opencv2/imgproc.hpp>

#include <algorithm>
#include <cmath>
#include <fstream>
#include <limits>
#include <stdexcept>
#include <string>

#include "common/sim/texture.hpp"

namespace aerie::sim {

namespace {

constexpr double kPi = 3.14159265358979323846;
constexpr int kBoundaryFaces = 6;           // surfaces 0-5: the room's faces / the field's ground and sky
constexpr double kSkyTexelsPerMetre = 10;   // the sky is smooth and far: a coarse texture is enough
constexpr double kVehicleClearance = 1.5;   // xy gap other obstacles keep from the landing object (m)

void check(bool ok, const std::string& what) {
  if (!ok) throw std::invalid_argument("sim::WorldConfig: " + what);
}

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

// The helipad_image option: a binary Netpbm image (P5 gray or P6 RGB, maxval 255) as 8-bit gray.
// aerie_sim links no image codec library; Netpbm needs none.
cv::Mat read_helipad_image(const std::string& path) {
  auto bad = [&](const std::string& what) { throw std::invalid_argument("sim::WorldConfig: helipad_image '" + path + "': " + what); };
  std::ifstream in(path, std::ios::binary);
  if (!in) bad("cannot be read");
  std::string magic;
  in >> magic;
  if (magic != "P5" && magic != "P6") bad("not a binary PGM (P5) or PPM (P6) image");
  int fields[3] = {0, 0, 0};  // width, height, maxval
  for (int& f : fields) {
    while (in >> std::ws && in.peek() == '#') in.ignore(std::numeric_limits<std::streamsize>::max(), '\n');
    if (!(in >> f)) bad("truncated header");
  }
  in.get();  // the single whitespace before the pixels
  if (fields[0] < 8 || fields[1] < 8 || fields[0] > 8192 || fields[1] > 8192) bad("width and height must be in [8, 8192]");
  if (fields[2] != 255) bad("maxval must be 255 (8 bit)");
  const int channels = magic == "P5" ? 1 : 3;
  cv::Mat img(fields[1], fields[0], channels == 1 ? CV_8UC1 : CV_8UC3);
  for (int r = 0; r < img.rows; ++r)
    if (!in.read(reinterpret_cast<char*>(img.ptr(r)), static_cast<std::streamsize>(img.cols) * channels)) bad("truncated pixels");
  if (channels == 3) cv::cvtColor(img, img, cv::COLOR_RGB2GRAY);
  return img;
}

// Paints the helipad (dark square, white ring, white H; or `image` over the square) into the
// texture of an upward-facing surface (the room's floor, the top of the field's landing object),
// with 4x4 supersampling per texel for anti-aliased edges.
void paint_helipad(cv::Mat& tex, const Surface& floor, const Helipad& pad, double density, const cv::Mat& image) {
  CV_Assert(floor.axis == 2 && floor.normal_sign == 1 && floor.u_axis == 0 && floor.v_sign == -1);
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
    if (!image.empty()) {  // nearest image pixel: column along +x, row along -y
      const int c = std::min(image.cols - 1, static_cast<int>((lx + 0.5) * image.cols));
      const int r = std::min(image.rows - 1, static_cast<int>((0.5 - ly) * image.rows));
      return image.at<uint8_t>(r, c) / 255.0;
    }
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

// The light sources of a world.
struct Lighting {
  double ambient = 0.3;
  std::vector<Eigen::Vector3d> lamps;         // point lamps: Lambertian, inverse-square falloff
  double lamp_power = 0.0;
  Eigen::Vector3d sun = Eigen::Vector3d::Zero();  // unit vector towards the sun (directional, no falloff)
  double sun_irradiance = 0.0;                // 0: no sun
};

// Diffuse light baked into a surface's texture (view-independent, so both cameras agree):
// ambient plus Lambertian lamps and sun with hard shadows of the obstacles, evaluated every
// 10 cm and interpolated (which softens the shadow edges).
void bake_lighting(const World& w, const Surface& s, const Lighting& lights, cv::Mat& tex) {
  constexpr double kStep = 0.1, kMax = 1.05;
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
      double e = lights.ambient;
      for (const auto& lamp : lights.lamps) {
        const Eigen::Vector3d l = lamp - p;
        const double r2 = l.squaredNorm(), cos_in = n.dot(l) / std::sqrt(r2);
        if (cos_in <= 0) continue;
        if (w.raycast(p + 1e-6 * n, l, 1.0 - 1e-6)) continue;  // in the shadow of an obstacle
        e += lights.lamp_power * cos_in / r2;
      }
      if (lights.sun_irradiance > 0) {
        const double cos_in = n.dot(lights.sun);
        // The sun is beyond the sky faces: only an obstacle on the way casts a shadow.
        const auto hit = cos_in > 0 ? w.raycast(p + 1e-6 * n, lights.sun) : std::nullopt;
        if (cos_in > 0 && (!hit || hit->surface < kBoundaryFaces)) e += lights.sun_irradiance * cos_in;
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

// The survey route `route_margin` inside the bounds' xy faces, home in the middle of its west edge.
World::Route make_route(const Aabb& bounds, const WorldConfig& cfg) {
  World::Route r;
  r.x_min = bounds.min.x() + cfg.route_margin;
  r.x_max = bounds.max.x() - cfg.route_margin;
  r.y_min = bounds.min.y() + cfg.route_margin;
  r.y_max = bounds.max.y() - cfg.route_margin;
  r.corner_radius = std::min(1.0, 0.3 * std::min(r.x_max - r.x_min, r.y_max - r.y_min));
  r.altitude = cfg.cruise_altitude;
  r.home = {r.x_min, 0.5 * (r.y_min + r.y_max), 0.0};
  return r;
}

// Adds cfg.n_obstacles random boxes and pillars standing in `area`, at least route_clearance
// (xy) from every keep-out point, 0.3 m from each other and kVehicleClearance from a landing
// object. pillar_height(rng) gives a pillar's height.
template <typename PillarHeight>
void place_obstacles(std::vector<Obstacle>& obstacles, const Aabb& area, const std::vector<Eigen::Vector2d>& keep_out,
                     const WorldConfig& cfg, cv::RNG& rng, PillarHeight pillar_height) {
  const size_t target = obstacles.size() + static_cast<size_t>(cfg.n_obstacles);
  int attempts = 0;
  while (obstacles.size() < target) {
    if (++attempts > 20000)
      throw std::invalid_argument("sim::WorldConfig: cannot place " + std::to_string(cfg.n_obstacles) +
                                  " obstacles clear of the route; lower n_obstacles or "
                                  "route_clearance, or enlarge the " + cfg.kind);
    Obstacle o;
    o.kind = rng.uniform(0.0, 1.0) < 0.35 ? Obstacle::Kind::Pillar : Obstacle::Kind::Box;
    Eigen::Vector3d size;
    if (o.kind == Obstacle::Kind::Pillar) {
      const double a = rng.uniform(0.3, 0.6);
      size = {a, a, pillar_height(rng)};
    } else {
      size = {rng.uniform(0.4, 1.4), rng.uniform(0.4, 1.4), rng.uniform(0.4, 2.0)};
    }
    // One draw per statement: a call's arguments are evaluated in an unspecified order (x86-64
    // GCC right to left, arm64 left to right); this is x86's order, now on every architecture.
    const double lo_y = rng.uniform(area.min.y(), area.max.y() - size.y());
    const Eigen::Vector3d lo(rng.uniform(area.min.x(), area.max.x() - size.x()), lo_y, 0.0);
    o.box = {lo, lo + size};
    bool ok = true;
    for (const auto& p : keep_out)
      if (footprint_distance(o.box, p.x(), p.y()) < cfg.route_clearance) {
        ok = false;
        break;
      }
    for (const auto& other : obstacles) {
      // at least 0.3 m between obstacles, so that none hides inside another
      const double gap = other.kind == Obstacle::Kind::Vehicle ? kVehicleClearance : 0.3;
      Aabb grown = other.box;
      grown.min.head<2>().array() -= gap;
      grown.max.head<2>().array() += gap;
      if (!(o.box.max.x() < grown.min.x() || o.box.min.x() > grown.max.x() ||
            o.box.max.y() < grown.min.y() || o.box.min.y() > grown.max.y()))
        ok = false;
    }
    if (ok) obstacles.push_back(o);
  }
}

// True when v is NaN ("not set") or finite.
bool unset_or_finite(double v) { return std::isnan(v) || std::isfinite(v); }

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

World World::make(const WorldConfig& cfg) {
  if (cfg.kind == "room") return room(cfg);
  if (cfg.kind == "field") return field(cfg);
  throw std::invalid_argument("sim::WorldConfig: kind must be room or field (got '" + cfg.kind + "')");
}

World World::room(const WorldConfig& cfg) {
  check(cfg.kind == "room", "kind is '" + cfg.kind + "': World::room builds a room (use World::make)");
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
  check(unset_or_finite(cfg.helipad_x) && unset_or_finite(cfg.helipad_y), "helipad_x, helipad_y must be finite");
  const cv::Mat pad_image = cfg.helipad_image.empty() ? cv::Mat() : read_helipad_image(cfg.helipad_image);

  World w;
  w.config_ = cfg;
  w.bounds_.min = {-0.5 * cfg.room_x, -0.5 * cfg.room_y, 0.0};
  w.bounds_.max = {0.5 * cfg.room_x, 0.5 * cfg.room_y, cfg.room_z};

  // Survey route and home (middle of its west edge), helipad on the approach line east of
  // the room centre unless helipad_x / helipad_y place it.
  const Route& r = w.route_ = make_route(w.bounds_, cfg);
  w.helipad_.center = {std::isnan(cfg.helipad_x) ? 0.4 * r.x_max : cfg.helipad_x,
                       std::isnan(cfg.helipad_y) ? r.home.y() : cfg.helipad_y, 0.0};
  w.helipad_.yaw = cfg.helipad_yaw_deg * kPi / 180.0;
  w.helipad_.size = cfg.helipad_size;
  if (!std::isnan(cfg.helipad_x) || !std::isnan(cfg.helipad_y))
    for (const auto& c : w.helipad_.corners())
      check(std::abs(c.x()) <= 0.5 * cfg.room_x - 0.05 && std::abs(c.y()) <= 0.5 * cfg.room_y - 0.05,
            "helipad_x, helipad_y: the helipad must lie on the floor, 5 cm from the walls");

  // Obstacles: random boxes and floor-to-ceiling pillars clear of the route and of each other.
  cv::RNG rng(mix_seed(cfg.seed, 1));
  place_obstacles(w.obstacles_, w.bounds_, route_samples(r, w.helipad_), cfg, rng,
                  [&](cv::RNG&) { return cfg.room_z; });

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
  paint_helipad(images[4], w.surfaces_[4], w.helipad_, density, pad_image);  // surface 4: the floor
  // Ceiling lamps on a ~3 m grid (none inside a pillar); the ceiling itself is lit only by
  // the ambient term, its light panels are in its texture.
  Lighting light;
  light.ambient = 0.3;
  light.lamp_power = 0.25 * cfg.room_z * cfg.room_z;
  const int nx = std::max(1, static_cast<int>(std::lround(cfg.room_x / 3.0)));
  const int ny = std::max(1, static_cast<int>(std::lround(cfg.room_y / 3.0)));
  for (int j = 0; j < ny; ++j)
    for (int i = 0; i < nx; ++i) {
      const Eigen::Vector3d lamp(w.bounds_.min.x() + cfg.room_x * (i + 0.5) / nx,
                                 w.bounds_.min.y() + cfg.room_y * (j + 0.5) / ny, cfg.room_z - 0.1);
      if (!w.occupied(lamp)) light.lamps.push_back(lamp);
    }
  auto textures = std::make_shared<Textures>();
  for (size_t k = 0; k < images.size(); ++k) {
    if (k == 5) {
      w.surfaces_[k].shade = 0.7f;
    } else {
      bake_lighting(w, w.surfaces_[k], light, images[k]);
    }
    textures->surfaces.emplace_back(images[k], density);
  }
  w.textures_ = std::move(textures);
  return w;
}

World World::field(const WorldConfig& cfg) {
  check(cfg.kind == "field", "kind is '" + cfg.kind + "': World::field builds a field (use World::make)");
  check(cfg.field_x >= 10 && cfg.field_y >= 10 && cfg.field_x <= 500 && cfg.field_y <= 500,
        "field_x, field_y must be in [10, 500] m");
  check(cfg.field_texels_per_metre >= 8 && cfg.field_texels_per_metre <= 1000,
        "field_texels_per_metre must be in [8, 1000]");
  const double ground_texels = cfg.field_x * cfg.field_y * cfg.field_texels_per_metre * cfg.field_texels_per_metre;
  check(ground_texels <= 100e6, "field_texels_per_metre: the ground texture would have " +
                                    std::to_string(static_cast<long long>(ground_texels / 1e6)) +
                                    " Mtexels (> 100); lower it or the field size");
  check(cfg.vehicle_length >= 0.5 && cfg.vehicle_width >= 0.5 && cfg.vehicle_length <= 20 && cfg.vehicle_width <= 20,
        "vehicle_length, vehicle_width must be in [0.5, 20] m");
  check(cfg.vehicle_height >= 0.2 && cfg.vehicle_height <= 10, "vehicle_height must be in [0.2, 10] m");
  check(cfg.vehicle_texels_per_metre >= 8 && cfg.vehicle_texels_per_metre <= 2000 &&
            cfg.vehicle_length * cfg.vehicle_width * cfg.vehicle_texels_per_metre * cfg.vehicle_texels_per_metre <= 20e6,
        "vehicle_texels_per_metre must be in [8, 2000] and give at most 20 Mtexels on the vehicle's top");
  check(std::isnan(cfg.vehicle_yaw_deg) ||
            (std::isfinite(cfg.vehicle_yaw_deg) && std::remainder(cfg.vehicle_yaw_deg, 90.0) == 0.0),
        "vehicle_yaw_deg must be a multiple of 90 (the landing object is an axis-aligned box)");
  check(cfg.sky_z >= 5 && cfg.sky_z <= 1000, "sky_z must be in [5, 1000] m");
  check(cfg.road_width >= 0 && cfg.road_width <= cfg.field_y - 2, "road_width must be in [0, field_y - 2] m");
  check(std::isnan(cfg.sun_elevation_deg) || (cfg.sun_elevation_deg >= 10 && cfg.sun_elevation_deg <= 90),
        "sun_elevation_deg must be in [10, 90]");
  check(unset_or_finite(cfg.sun_azimuth_deg), "sun_azimuth_deg must be finite");
  check(cfg.n_obstacles >= 0, "n_obstacles must be >= 0");
  check(cfg.helipad_size > 0.1, "helipad_size must be > 0.1 m");
  const cv::Mat pad_image = cfg.helipad_image.empty() ? cv::Mat() : read_helipad_image(cfg.helipad_image);
  check(cfg.route_margin >= 0.5 && 2 * cfg.route_margin < std::min(cfg.field_x, cfg.field_y) - 1.0,
        "route_margin must be >= 0.5 m and leave at least 1 m of route");
  check(cfg.cruise_altitude >= cfg.vehicle_height + 0.5 && cfg.cruise_altitude <= cfg.sky_z - 0.3,
        "cruise_altitude must be >= vehicle_height + 0.5 m and <= sky_z - 0.3 m");
  check(unset_or_finite(cfg.helipad_x) && unset_or_finite(cfg.helipad_y), "helipad_x, helipad_y must be finite");

  World w;
  w.config_ = cfg;
  w.bounds_.min = {-0.5 * cfg.field_x, -0.5 * cfg.field_y, 0.0};
  w.bounds_.max = {0.5 * cfg.field_x, 0.5 * cfg.field_y, cfg.sky_z};
  const Route& r = w.route_ = make_route(w.bounds_, cfg);

  // Seeded layout; every draw is made even when its key overrides it, so that setting one
  // key leaves the other choices unchanged.
  cv::RNG layout(mix_seed(cfg.seed, 2));
  const double pad_x = layout.uniform(-0.25, 0.25) * cfg.field_x, pad_y = layout.uniform(-0.25, 0.25) * cfg.field_y;
  const double yaw_deg = layout.uniform(0.0, 1.0) < 0.5 ? 0.0 : 90.0;
  const double road_y = layout.uniform(-0.5, 0.5) * (cfg.field_y - cfg.road_width - 2.0);
  const double sun_az = layout.uniform(0.0, 360.0), sun_el = layout.uniform(35.0, 65.0);

  // The landing object (obstacle 0) centred under the helipad, the marking on its top face.
  w.helipad_.center = {std::isnan(cfg.helipad_x) ? pad_x : cfg.helipad_x,
                       std::isnan(cfg.helipad_y) ? pad_y : cfg.helipad_y, cfg.vehicle_height};
  w.helipad_.yaw = cfg.helipad_yaw_deg * kPi / 180.0;
  w.helipad_.size = cfg.helipad_size;
  const bool along_y = std::abs(std::remainder(std::isnan(cfg.vehicle_yaw_deg) ? yaw_deg : cfg.vehicle_yaw_deg,
                                               180.0)) == 90.0;
  const Eigen::Vector3d half(0.5 * (along_y ? cfg.vehicle_width : cfg.vehicle_length),
                             0.5 * (along_y ? cfg.vehicle_length : cfg.vehicle_width), 0.0);
  Obstacle vehicle;
  vehicle.kind = Obstacle::Kind::Vehicle;
  vehicle.box.min = w.helipad_.center - half;
  vehicle.box.max = w.helipad_.center + half;
  vehicle.box.min.z() = 0.0;
  check(vehicle.box.min.x() >= w.bounds_.min.x() + 1 && vehicle.box.max.x() <= w.bounds_.max.x() - 1 &&
            vehicle.box.min.y() >= w.bounds_.min.y() + 1 && vehicle.box.max.y() <= w.bounds_.max.y() - 1,
        "helipad_x, helipad_y: the landing object must stand at least 1 m inside the field");
  for (const auto& c : w.helipad_.corners())
    check(c.x() >= vehicle.box.min.x() && c.x() <= vehicle.box.max.x() && c.y() >= vehicle.box.min.y() &&
              c.y() <= vehicle.box.max.y(),
          "helipad_size, helipad_yaw_deg: the marking must fit on the landing object's top face "
          "(vehicle_length x vehicle_width)");
  w.obstacles_.push_back(vehicle);
  w.landing_ = 0;

  // Crates and tree-like pillars (3-7 m) clear of the route, the approach and the vehicle.
  cv::RNG rng(mix_seed(cfg.seed, 1));
  place_obstacles(w.obstacles_, w.bounds_, route_samples(r, w.helipad_), cfg, rng,
                  [](cv::RNG& g) { return g.uniform(3.0, 7.0); });

  // Surfaces and textures: sky faces (emissive), ground with a road, obstacles.
  std::vector<cv::Mat> images;
  std::vector<double> densities;
  auto add = [&](Surface s, Material m, uint64_t stream, double density) {
    images.push_back(make_texture(m, s.u_len, s.v_len, density, mix_seed(cfg.seed, stream)));
    densities.push_back(density);
    w.surfaces_.push_back(s);
  };
  for (int axis = 0; axis < 3; ++axis)
    for (int side = 0; side < 2; ++side) {
      Surface s = make_face(w.bounds_, axis, side, true);
      if (axis == 2 && side == 0) {
        s.tint = {0.78f, 1.0f, 0.88f};  // grass green (the road, painted in, a greenish grey)
        add(s, Material::Grass, 100 + 2 * axis + side, cfg.field_texels_per_metre);
      } else {
        s.tint = {1.1f, 1.0f, 0.92f};   // pale blue
        add(s, axis == 2 ? Material::Sky : Material::Horizon, 100 + 2 * axis + side, kSkyTexelsPerMetre);
      }
    }
  if (cfg.road_width > 0) {
    // The road along x: rows of the ground texture run towards -y from its north edge.
    const Surface& g = w.surfaces_[4];
    const double density = cfg.field_texels_per_metre;
    const cv::Mat road = make_texture(Material::Asphalt, g.u_len, cfg.road_width, density, mix_seed(cfg.seed, 200));
    const int row0 = static_cast<int>(std::lround((g.v0 - (road_y + 0.5 * cfg.road_width)) * density));
    const cv::Rect dst = cv::Rect(0, row0, road.cols, road.rows) & cv::Rect(0, 0, images[4].cols, images[4].rows);
    road(cv::Rect(0, dst.y - row0, dst.width, dst.height)).copyTo(images[4](dst));
  }
  for (size_t i = 0; i < w.obstacles_.size(); ++i) {
    const auto& o = w.obstacles_[i];
    Material m = Material::Crate;
    cv::Vec3f tint(0.7f, 0.95f, 1.2f);
    if (o.kind == Obstacle::Kind::Pillar) {
      m = Material::Pillar;
      tint = {0.6f, 0.8f, 1.0f};  // bark brown
    } else if (o.kind == Obstacle::Kind::Vehicle) {
      m = Material::Vehicle;
      tint = {0.55f, 0.6f, 1.35f};  // red paint
    }
    for (int axis = 0; axis < 3; ++axis)
      for (int side = 0; side < 2; ++side) {
        Surface s = make_face(o.box, axis, side, false);
        s.tint = tint;
        const bool top = o.kind == Obstacle::Kind::Vehicle && axis == 2 && side == 1;
        add(s, m, 1000 + 6 * i + 2 * axis + side, top ? cfg.vehicle_texels_per_metre : cfg.field_texels_per_metre);
      }
  }
  const int top = kBoundaryFaces + 6 * w.landing_ + 5;  // the landing object's top face
  paint_helipad(images[top], w.surfaces_[top], w.helipad_, densities[top], pad_image);

  // Sunlight with hard shadows plus sky light; the sky faces are emissive (not lit).
  const double az = (std::isnan(cfg.sun_azimuth_deg) ? sun_az : cfg.sun_azimuth_deg) * kPi / 180.0;
  const double el = (std::isnan(cfg.sun_elevation_deg) ? sun_el : cfg.sun_elevation_deg) * kPi / 180.0;
  w.sun_ = {std::cos(el) * std::cos(az), std::cos(el) * std::sin(az), std::sin(el)};
  Lighting light;
  light.ambient = 0.4;
  light.sun = w.sun_;
  light.sun_irradiance = 0.7;
  auto textures = std::make_shared<Textures>();
  for (size_t k = 0; k < images.size(); ++k) {
    if (k == 4 || k >= kBoundaryFaces) bake_lighting(w, w.surfaces_[k], light, images[k]);
    textures->surfaces.emplace_back(images[k], densities[k]);
  }
  w.textures_ = std::move(textures);
  return w;
}

World World::with_landing_offset(const Eigen::Vector2d& offset) const {
  if (landing_ < 0)
    throw std::invalid_argument("sim::World: a moving platform needs world.kind field (the room's helipad is the floor)");
  World w = *this;
  const Eigen::Vector3d d(offset.x(), offset.y(), 0.0);
  Aabb& box = w.obstacles_[landing_].box;
  box.min += d;
  box.max += d;
  w.helipad_.center += d;
  // Its six faces: the plane moves along its axis, the texture origin along the face.
  for (int k = 0; k < 6; ++k) {
    Surface& s = w.surfaces_[kBoundaryFaces + 6 * landing_ + k];
    if (s.axis < 2) s.offset += d[s.axis];
    if (s.u_axis < 2) s.u0 += d[s.u_axis];
    if (s.v_axis < 2) s.v0 += d[s.v_axis];
  }
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
    best.surface = static_cast<int>(kBoundaryFaces + 6 * i + 2 * axis + (dir[axis] > 0 ? 0 : 1));
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
