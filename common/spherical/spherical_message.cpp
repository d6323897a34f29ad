#include "common/spherical/spherical_message.hpp"

#include <cmath>
#include <stdexcept>
#include <string>

namespace aerie::spherical {

namespace {
void require(bool ok, const std::string& what) {
  if (!ok) throw std::invalid_argument("spherical_depth_t: " + what);
}
}  // namespace

aerie::spherical_depth_t to_message(const SphericalDepth& d, int64_t utime, int64_t seq,
                                    const std::optional<geometry::SE3>& T_world_camera) {
  aerie::spherical_depth_t m{};
  m.utime = utime;
  m.seq = seq;
  m.has_pose = T_world_camera.has_value();
  if (T_world_camera) {
    T_world_camera->to_wxyz(m.orientation);
    for (int i = 0; i < 3; ++i) m.position[i] = T_world_camera->translation()[i];
  }
  m.polar_min_rad = d.grid.polar_min;
  m.polar_step_rad = d.grid.polar_step;
  m.n_polar = d.grid.n_polar;
  m.azimuth_min_rad = d.grid.azimuth_min;
  m.azimuth_step_rad = d.grid.azimuth_step;
  m.n_azimuth = d.grid.n_azimuth;
  m.range_scale_m = d.range_scale_m;
  m.max_range_m = d.max_range_m;
  m.focal_px = d.focal_px;
  m.baseline_m = d.baseline_m;
  // Sparse costs 6 bytes per filled bin, dense 2 bytes per bin of the grid.
  const bool dense = d.size() * 3 > static_cast<size_t>(d.grid.size());
  if (dense) {
    m.range.assign(static_cast<size_t>(d.grid.size()), 0);
    for (size_t i = 0; i < d.size(); ++i) m.range[static_cast<size_t>(d.bins[i])] = d.range_q[i];
  } else {
    m.bin = d.bins;
    m.range = d.range_q;
  }
  m.nbins = static_cast<int32_t>(m.bin.size());
  m.nrange = static_cast<int32_t>(m.range.size());
  return m;
}

SphericalDepth from_message(const aerie::spherical_depth_t& m) {
  SphericalDepth d;
  d.grid = {m.polar_min_rad, m.polar_step_rad, m.n_polar, m.azimuth_min_rad, m.azimuth_step_rad, m.n_azimuth};
  d.grid.validate();
  d.range_scale_m = m.range_scale_m;
  d.max_range_m = m.max_range_m;
  require(std::isfinite(m.focal_px) && m.focal_px >= 0 && std::isfinite(m.baseline_m) && m.baseline_m >= 0,
          "focal_px and baseline_m must be finite and >= 0");
  d.focal_px = m.focal_px;
  d.baseline_m = m.baseline_m;
  require(m.nbins >= 0 && m.nrange >= 0, "negative nbins/nrange");
  if (m.nbins == 0) {
    require(m.nrange == 0 || m.nrange == d.grid.size(),
            "dense layout needs nrange == n_polar * n_azimuth (" + std::to_string(d.grid.size()) + "), got " +
                std::to_string(m.nrange));
    for (int32_t b = 0; b < m.nrange; ++b) {
      const int16_t q = m.range[static_cast<size_t>(b)];
      if (q < 0) require(false, "negative range in bin " + std::to_string(b));  // message built only then
      if (q == 0) continue;
      d.bins.push_back(b);
      d.range_q.push_back(q);
    }
  } else {
    require(m.nrange == m.nbins, "sparse layout needs nrange == nbins");
    d.bins = m.bin;
    d.range_q = m.range;
  }
  d.validate();
  return d;
}

std::optional<geometry::SE3> pose_of(const aerie::spherical_depth_t& m) {
  if (!m.has_pose) return std::nullopt;
  const Eigen::Vector4d q(m.orientation[0], m.orientation[1], m.orientation[2], m.orientation[3]);
  const Eigen::Vector3d t(m.position[0], m.position[1], m.position[2]);
  require(q.allFinite() && t.allFinite(), "pose is not finite");
  require(std::abs(q.norm() - 1.0) < 1e-3, "orientation is not a unit quaternion (norm " +
                                               std::to_string(q.norm()) + ")");
  return geometry::SE3::from_wxyz(m.orientation, m.position);
}

}  // namespace aerie::spherical
