#include "common/spherical/spherical_depth.hpp"

#include <algorithm>
#include <cmath>
#include <limits>
#include <stdexcept>
#include <string>

namespace aerie::spherical {

namespace {

constexpr float kPi = std::numbers::pi_v<float>;
constexpr int kMaxRangeQ = std::numeric_limits<int16_t>::max();

void require(bool ok, const std::string& what) {
  if (!ok) throw std::invalid_argument(what);
}

// Index of `value` in cells [min + k*step, min + (k+1)*step), k < n; a value a rounding
// error past the last edge goes to the last cell; -1 outside.
int cell(float value, float min, float step, int n) {
  const float t = (value - min) / step;
  if (!(t >= 0.f)) return -1;  // also NaN
  const int k = static_cast<int>(t);
  if (k < n) return k;
  return t <= static_cast<float>(n) * (1.f + 1e-6f) ? n - 1 : -1;
}

// One range per bin from (bin, range) samples, by a counting sort on the bin (O(n)).
SphericalDepth reduce(const AngularGrid& grid, const EncoderConfig& cfg, const std::vector<int32_t>& sample_bin,
                      const std::vector<float>& sample_range) {
  SphericalDepth out;
  out.grid = grid;
  out.range_scale_m = cfg.range_scale_m;
  out.max_range_m = cfg.max_range_m;
  std::vector<int32_t> start(static_cast<size_t>(grid.size()) + 1, 0);
  for (int32_t b : sample_bin) ++start[static_cast<size_t>(b) + 1];
  for (size_t b = 1; b < start.size(); ++b) start[b] += start[b - 1];
  std::vector<float> sorted(sample_range.size());
  {
    std::vector<int32_t> fill(start.begin(), start.end() - 1);
    for (size_t i = 0; i < sample_bin.size(); ++i) sorted[static_cast<size_t>(fill[sample_bin[i]]++)] = sample_range[i];
  }
  for (int32_t b = 0; b < grid.size(); ++b) {
    const auto first = sorted.begin() + start[b];
    const auto last = sorted.begin() + start[b + 1];
    const auto n = last - first;
    if (n < cfg.min_points_per_bin || n == 0) continue;
    float r;
    if (cfg.reduction == Reduction::Nearest) {
      r = *std::min_element(first, last);
    } else {
      const auto mid = first + (n - 1) / 2;  // lower median: always a measured range
      std::nth_element(first, mid, last);
      r = *mid;
    }
    const long q = std::lround(r / cfg.range_scale_m);
    out.bins.push_back(b);
    out.range_q.push_back(static_cast<int16_t>(std::clamp<long>(q, 1, kMaxRangeQ)));
  }
  return out;
}

}  // namespace

Spherical to_spherical(const Eigen::Vector3f& p) {
  Spherical s;
  s.r = p.norm();
  // polar = acos(z / r) of eq. 4.17, computed as atan2(|(x, y)|, z): the same angle, but
  // well conditioned near the poles, where acos loses the small angle in float.
  s.polar = std::atan2(std::hypot(p.x(), p.y()), p.z());
  s.azimuth = (p.x() == 0.f && p.y() == 0.f) ? 0.f : std::atan2(p.y(), p.x());
  return s;
}

Eigen::Vector3f to_cartesian(const Spherical& s) {
  const float sp = std::sin(s.polar);
  return {s.r * sp * std::cos(s.azimuth), s.r * sp * std::sin(s.azimuth), s.r * std::cos(s.polar)};
}

// ---------------------------------------------------------------- AngularGrid

AngularGrid AngularGrid::for_camera(const Intrinsics& k, cv::Size image, float step) {
  require(k.fx > 0 && k.fy > 0, "spherical: intrinsics fx and fy must be > 0");
  require(image.width > 0 && image.height > 0, "spherical: image size must be positive");
  require(step > 0.f && step < kPi, "spherical: angular_resolution must be in (0, pi) rad");
  float pmin = kPi, pmax = 0.f, amin = kPi, amax = -kPi;
  // Every pixel centre, with a one-pixel margin around the image (simple and exact;
  // done once per camera).
  for (int v = -1; v <= image.height; ++v) {
    for (int u = -1; u <= image.width; ++u) {
      const Eigen::Vector3f ray(static_cast<float>((u - k.cx) / k.fx), static_cast<float>((v - k.cy) / k.fy), 1.f);
      const Spherical s = to_spherical(camera_to_sensor(ray));
      pmin = std::min(pmin, s.polar);
      pmax = std::max(pmax, s.polar);
      amin = std::min(amin, s.azimuth);
      amax = std::max(amax, s.azimuth);
    }
  }
  AngularGrid g;
  g.polar_step = g.azimuth_step = step;
  g.polar_min = std::max(0.f, std::floor(pmin / step) * step);
  g.n_polar = std::max(1, static_cast<int>(std::ceil((pmax - g.polar_min) / step)));
  g.azimuth_min = std::floor(amin / step) * step;
  g.n_azimuth = std::max(1, static_cast<int>(std::ceil((amax - g.azimuth_min) / step)));
  return g;
}

AngularGrid AngularGrid::full_sphere(float step) {
  require(step > 0.f && step < kPi, "spherical: angular_resolution must be in (0, pi) rad");
  AngularGrid g;
  g.n_polar = static_cast<int>(std::ceil(kPi / step));
  g.polar_step = kPi / static_cast<float>(g.n_polar);
  g.polar_min = 0.f;
  g.n_azimuth = static_cast<int>(std::ceil(2.f * kPi / step));
  g.azimuth_step = 2.f * kPi / static_cast<float>(g.n_azimuth);
  g.azimuth_min = -kPi;
  return g;
}

int AngularGrid::bin(float polar, float azimuth) const {
  const int i = cell(polar, polar_min, polar_step, n_polar);
  const int j = cell(azimuth, azimuth_min, azimuth_step, n_azimuth);
  return (i < 0 || j < 0) ? -1 : i * n_azimuth + j;
}

void AngularGrid::validate() const {
  require(std::isfinite(polar_step) && polar_step > 0.f, "spherical grid: polar_step must be > 0");
  require(std::isfinite(azimuth_step) && azimuth_step > 0.f, "spherical grid: azimuth_step must be > 0");
  require(n_polar > 0 && n_azimuth > 0, "spherical grid: n_polar and n_azimuth must be > 0");
  require(std::isfinite(polar_min) && polar_min >= -1e-6f &&
              polar_min + static_cast<float>(n_polar) * polar_step <= kPi * (1.f + 1e-5f),
          "spherical grid: polar range must lie in [0, pi]");
  require(std::isfinite(azimuth_min) && azimuth_min >= -kPi * (1.f + 1e-5f) &&
              azimuth_min + static_cast<float>(n_azimuth) * azimuth_step <= kPi * (1.f + 1e-5f),
          "spherical grid: azimuth range must lie in [-pi, pi]");
  require(static_cast<int64_t>(n_polar) * n_azimuth <= (int64_t{1} << 26),
          "spherical grid: more than 2^26 bins (n_polar * n_azimuth)");
}

void EncoderConfig::validate() const {
  require(angular_resolution_rad > 0.f && angular_resolution_rad < kPi,
          "spherical: angular_resolution must be in (0, pi) rad");
  require(min_range_m >= 0.f && max_range_m > min_range_m, "spherical: need 0 <= min_range < max_range");
  require(range_scale_m > 0.f && max_range_m / range_scale_m <= static_cast<float>(kMaxRangeQ),
          "spherical: max_range / range_scale must be <= 32767 (int16 ranges)");
  require(min_points_per_bin >= 1, "spherical: min_points_per_bin must be >= 1");
}

// ---------------------------------------------------------------- SphericalDepth

Eigen::Vector3f SphericalDepth::point_camera(size_t i) const {
  return sensor_to_camera(to_cartesian({range(i), grid.polar_of(bins[i]), grid.azimuth_of(bins[i])}));
}

void SphericalDepth::decode(std::vector<Eigen::Vector3f>& out) const {
  out.reserve(out.size() + size());
  for (size_t i = 0; i < size(); ++i) out.push_back(point_camera(i));
}

std::vector<Eigen::Vector3f> SphericalDepth::decode() const {
  std::vector<Eigen::Vector3f> out;
  decode(out);
  return out;
}

void SphericalDepth::validate() const {
  grid.validate();
  require(std::isfinite(range_scale_m) && range_scale_m > 0.f, "spherical depth: range_scale_m must be > 0");
  require(bins.size() == range_q.size(), "spherical depth: bins and ranges differ in count");
  // The messages are built only for a bad bin: this loop runs over every bin of every VO_DEPTH.
  for (size_t i = 0; i < bins.size(); ++i) {
    if (bins[i] < 0 || bins[i] >= grid.size())
      throw std::invalid_argument("spherical depth: bin " + std::to_string(bins[i]) + " outside the grid");
    if (i > 0 && bins[i] <= bins[i - 1]) throw std::invalid_argument("spherical depth: bins not strictly ascending");
    if (range_q[i] <= 0)
      throw std::invalid_argument("spherical depth: range of bin " + std::to_string(bins[i]) + " is not positive");
  }
}

// ---------------------------------------------------------------- encoders

SphericalDepth encode_points(const std::vector<Eigen::Vector3f>& points, const AngularGrid& grid,
                             const EncoderConfig& cfg) {
  cfg.validate();
  grid.validate();
  std::vector<int32_t> bins;
  std::vector<float> ranges;
  bins.reserve(points.size());
  ranges.reserve(points.size());
  for (const auto& p : points) {
    if (!p.allFinite()) continue;
    const Spherical s = to_spherical(camera_to_sensor(p));
    if (s.r < cfg.min_range_m || s.r > cfg.max_range_m) continue;
    const int b = grid.bin(s.polar, s.azimuth);
    if (b < 0) continue;
    bins.push_back(b);
    ranges.push_back(s.r);
  }
  return reduce(grid, cfg, bins, ranges);
}

SphericalEncoder::SphericalEncoder(const Intrinsics& k, cv::Size image, const EncoderConfig& cfg)
    : k_(k), size_(image), cfg_(cfg) {
  cfg_.validate();
  grid_ = AngularGrid::for_camera(k_, size_, cfg_.angular_resolution_rad);
  grid_.validate();
  const size_t n = static_cast<size_t>(size_.area());
  pixel_bin_.resize(n);
  pixel_r_per_z_.resize(n);
  for (int v = 0; v < size_.height; ++v) {
    for (int u = 0; u < size_.width; ++u) {
      const Eigen::Vector3f ray(static_cast<float>((u - k_.cx) / k_.fx), static_cast<float>((v - k_.cy) / k_.fy), 1.f);
      const Spherical s = to_spherical(camera_to_sensor(ray));
      const size_t i = static_cast<size_t>(v) * static_cast<size_t>(size_.width) + static_cast<size_t>(u);
      pixel_bin_[i] = grid_.bin(s.polar, s.azimuth);
      pixel_r_per_z_[i] = s.r;
    }
  }
}

template <typename Range>
SphericalDepth SphericalEncoder::encode(Range&& z_of_pixel) const {
  std::vector<int32_t> bins;
  std::vector<float> ranges;
  bins.reserve(pixel_bin_.size());
  ranges.reserve(pixel_bin_.size());
  size_t i = 0;
  for (int v = 0; v < size_.height; ++v) {
    for (int u = 0; u < size_.width; ++u, ++i) {
      const float z = z_of_pixel(v, u);
      if (!(z > 0.f) || !std::isfinite(z) || pixel_bin_[i] < 0) continue;
      const float r = z * pixel_r_per_z_[i];
      if (r < cfg_.min_range_m || r > cfg_.max_range_m) continue;
      bins.push_back(pixel_bin_[i]);
      ranges.push_back(r);
    }
  }
  SphericalDepth out = reduce(grid_, cfg_, bins, ranges);
  out.focal_px = static_cast<float>(k_.fx);
  out.baseline_m = static_cast<float>(k_.baseline);
  return out;
}

SphericalDepth SphericalEncoder::encode_depth(const cv::Mat& depth) const {
  require(depth.type() == CV_32FC1, "spherical: depth must be CV_32FC1 (metres along z)");
  require(depth.size() == size_, "spherical: depth is " + std::to_string(depth.cols) + "x" +
                                     std::to_string(depth.rows) + ", encoder expects " + std::to_string(size_.width) +
                                     "x" + std::to_string(size_.height));
  return encode([&](int v, int u) { return depth.at<float>(v, u); });
}

SphericalDepth SphericalEncoder::encode_disparity(const cv::Mat& disparity) const {
  require(k_.baseline > 0, "spherical: disparity input needs Intrinsics::baseline > 0");
  require(disparity.type() == CV_32FC1 || disparity.type() == CV_16SC1,
          "spherical: disparity must be CV_32FC1 (pixels) or CV_16SC1 (pixels x 16)");
  require(disparity.size() == size_, "spherical: disparity is " + std::to_string(disparity.cols) + "x" +
                                         std::to_string(disparity.rows) + ", encoder expects " +
                                         std::to_string(size_.width) + "x" + std::to_string(size_.height));
  const float fb = static_cast<float>(k_.fx * k_.baseline);
  if (disparity.type() == CV_16SC1)
    return encode([&](int v, int u) {
      const int16_t d = disparity.at<int16_t>(v, u);
      return d > 0 ? fb * 16.f / static_cast<float>(d) : 0.f;
    });
  return encode([&](int v, int u) {
    const float d = disparity.at<float>(v, u);
    return d > 0.f ? fb / d : 0.f;
  });
}

}  // namespace aerie::spherical
