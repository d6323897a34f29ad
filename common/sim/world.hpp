#pragma once
// The simulated flight environment, one of two kinds (WorldConfig::kind):
// * "room": a textured room (floor with a helipad, four walls, ceiling), boxes and pillars;
// * "field": an outdoor field (grass with an asphalt road) under an open sky, with a
//   car-sized box carrying the helipad on its top face, crates and tree-like pillars, lit by
//   a sun with hard shadows. The sky is the field's far boundary (five faces of Sky
//   material), so the geometry stays a closed box like the room's.
// World frame: x east, y north, z up (metres); the floor/ground is z = 0 and the world is
// centred on the origin in x and y.
// The geometry is exact and public so that other components can take their ground truth
// from it (occupancy for mapping, distances for planning, ray casts for depth).
#include <Eigen/Core>

#include <array>
#include <cstdint>
#include <limits>
#include <memory>
#include <optional>
#include <string>
#include <vector>

#include <opencv2/core.hpp>

namespace aerie::sim {

struct WorldConfig {
  static constexpr double kAuto = std::numeric_limits<double>::quiet_NaN();  // "not set"

  std::string kind = "room";      // "room" | "field" (World::make dispatches on it)
  uint64_t seed = 1;              // every random choice (layout, textures) derives from it
  // Room only.
  double room_x = 12.0;           // interior size along x, y, z (m)
  double room_y = 10.0;
  double room_z = 4.0;
  double texels_per_metre = 200;  // resolution of the procedural textures (level 0)
  // Both kinds.
  int n_obstacles = 6;            // boxes and pillars (trees in the field), clear of the route
  double helipad_size = 1.0;      // side of the square helipad marking (m)
  double helipad_yaw_deg = 0.0;   // rotation of the marking about z
  // An image painted over the helipad's square instead of the H (helipad_size wide; column =
  // the pad's +x, row = its -y; white paint where the image is white, the pad's dark where it is
  // black): a binary Netpbm file (PGM P5 or PPM P6, 8 bit). Empty: the built-in H.
  std::string helipad_image;
  // Helipad centre in xy (NaN = default: room x = 0.4 * route x_max, y = home y; field: a
  // seeded place in the central half). In the field the landing object stands centred under it.
  double helipad_x = kAuto;
  double helipad_y = kAuto;
  double route_margin = 1.6;      // distance of the survey route from the walls / field edge (m)
  double route_clearance = 0.7;   // obstacles keep at least this xy distance from the route (m)
  double cruise_altitude = 1.5;   // altitude of the survey route (m); field: >= vehicle_height + 0.5
  // Field only.
  double field_x = 30.0;          // ground size along x, y (m), centred on the origin
  double field_y = 30.0;
  double sky_z = 30.0;            // height of the sky's top face (the side faces are the field edges)
  double field_texels_per_metre = 100;    // ground, obstacle and vehicle-side textures
  double vehicle_texels_per_metre = 400;  // the vehicle's top face (the helipad must stay sharp)
  double vehicle_length = 4.2;    // landing object ("car") size (m): along its own x, y, and z
  double vehicle_width = 1.8;
  double vehicle_height = 1.4;
  double vehicle_yaw_deg = kAuto; // multiple of 90 (0: length along x); NaN = seeded 0 or 90
  double road_width = 5.0;        // asphalt strip along x at a seeded y (m); 0 = none
  double sun_azimuth_deg = kAuto;   // direction towards the sun, from +x towards +y; NaN = seeded
  double sun_elevation_deg = kAuto; // above the horizon, in [10, 90]; NaN = seeded in [35, 65]
};

// Axis-aligned box [min, max].
struct Aabb {
  Eigen::Vector3d min = Eigen::Vector3d::Zero();
  Eigen::Vector3d max = Eigen::Vector3d::Zero();
  bool contains(const Eigen::Vector3d& p) const {
    return (p.array() >= min.array()).all() && (p.array() <= max.array()).all();
  }
  Eigen::Vector3d size() const { return max - min; }
  Eigen::Vector3d center() const { return 0.5 * (min + max); }
};

struct Obstacle {
  enum class Kind { Box, Pillar, Vehicle };  // Vehicle: the field's landing object
  Kind kind = Kind::Box;
  Aabb box;
};

// The helipad marking: a dark square of side `size` with a white ring and a white "H",
// centred at `center` (z = 0 on the room's floor, z = vehicle_height on the field's landing
// object), rotated by `yaw` about z.
struct Helipad {
  Eigen::Vector3d center = Eigen::Vector3d::Zero();
  double yaw = 0.0;   // rad; the H's bar is along the pad's local x axis
  double size = 1.0;  // m
  // Corners of the square, counter-clockwise seen from above, starting at local (-s/2, -s/2).
  std::array<Eigen::Vector3d, 4> corners() const;
};

// A flat textured rectangle on the plane x[axis] == offset, facing `normal_sign` along that
// axis. Texture coordinates are metres along (u_axis, v_axis) from (u0, v0), v_sign flips v.
struct Surface {
  int axis = 2;
  double offset = 0.0;
  int normal_sign = 1;
  int u_axis = 0, v_axis = 1;
  double u0 = 0, v0 = 0;
  int v_sign = 1;
  double u_len = 0, v_len = 0;      // extent (m)
  cv::Vec3f tint{1.f, 1.f, 1.f};    // BGR multiplier for colour output
  float shade = 1.f;                // constant diffuse shading of the face
};

struct RayHit {
  double t = 0.0;                 // ray parameter: point = origin + t * direction
  Eigen::Vector3d point = Eigen::Vector3d::Zero();
  Eigen::Vector3d normal = Eigen::Vector3d::Zero();
  int surface = -1;               // index into World::surfaces()
};

class Textures;  // mip-mapped procedural textures, one per surface (texture.hpp)

class World {
 public:
  // The world config.kind asks for (throws std::invalid_argument for an unknown kind).
  static World make(const WorldConfig& config);
  // The standard room of issue 2 (deterministic for a config; kind must be "room").
  static World room(const WorldConfig& config);
  // The outdoor field (deterministic for a config; kind must be "field").
  static World field(const WorldConfig& config);

  const WorldConfig& config() const { return config_; }
  // Interior of the room (free space is inside it and outside every obstacle).
  const Aabb& bounds() const { return bounds_; }
  const std::vector<Obstacle>& obstacles() const { return obstacles_; }
  const Helipad& helipad() const { return helipad_; }
  // The field's landing object (the box carrying the helipad); nullptr in the room.
  const Obstacle* landing_object() const { return landing_ < 0 ? nullptr : &obstacles_[landing_]; }
  // Unit vector towards the sun (zero in the room, which is lit by lamps).
  const Eigen::Vector3d& sun_direction() const { return sun_; }
  // This world with the field's landing object, its faces, textures and the helipad moved by
  // `offset` (m) in xy: the moving platform at one instant (common/sim/flight/platform.hpp).
  // The lighting baked into the ground (the car's shadow) stays where the car was built.
  // Throws std::invalid_argument in the room (its helipad is painted on the floor).
  World with_landing_offset(const Eigen::Vector2d& offset) const;

  // True inside an obstacle or outside the room interior (walls, and the field's sky faces,
  // are solid: the geometry is exactly what the renderer draws).
  bool occupied(const Eigen::Vector3d& p) const;
  // Euclidean distance to the nearest surface (wall, floor, ceiling, obstacle face).
  double distance(const Eigen::Vector3d& p) const;
  // Signed version: > 0 in free space, < 0 inside solid (obstacles or beyond the walls).
  double signed_distance(const Eigen::Vector3d& p) const;
  // First surface hit by origin + t * direction with t in (0, max_t]; direction need not
  // be unit (t is then in units of |direction|).
  std::optional<RayHit> raycast(const Eigen::Vector3d& origin, const Eigen::Vector3d& direction,
                                double max_t = 1e9) const;

  // The survey route the scripted trajectories fly (xy rounded rectangle at cruise altitude,
  // `route_margin` from the walls) and the take-off point (on the route, on the floor).
  struct Route {
    double x_min, x_max, y_min, y_max, corner_radius, altitude;
    Eigen::Vector3d home;
  };
  const Route& route() const { return route_; }

  const std::vector<Surface>& surfaces() const { return surfaces_; }
  const Textures& textures() const { return *textures_; }

 private:
  WorldConfig config_;
  Aabb bounds_;
  std::vector<Obstacle> obstacles_;
  Helipad helipad_;
  int landing_ = -1;                       // index of the landing object in obstacles_
  Eigen::Vector3d sun_ = Eigen::Vector3d::Zero();
  Route route_{};
  std::vector<Surface> surfaces_;
  std::shared_ptr<const Textures> textures_;  // shared: copies of a World are cheap
};

}  // namespace aerie::sim
