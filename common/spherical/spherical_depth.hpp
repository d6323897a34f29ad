#pragma once
// Compact spherical depth (thesis section 4.2.2, eq. 4.17): every depth point of a
// frame as radial distance r, polar angle phi and azimuth theta, binned on a regular
// angular grid with one range per bin. Equal angular bins keep the near field dense
// and the far field sparse, like the sensor itself. The air side encodes a depth or
// disparity map with SphericalEncoder and sends the bins (VO_DEPTH); the ground decodes
// them back to 3D points with SphericalDepth::decode.
//
// Frames. Eq. 4.17 is applied in the *sensor frame* s of the left camera: x forward,
// y left, z up (the UAV body convention), so that the poles (phi = 0 straight up,
// phi = pi straight down) lie outside any forward-looking camera's field of view and
// the image maps onto the equator band almost like a panorama:
//   x_s = z_c,  y_s = -x_c,  z_s = -y_c     (c: camera frame, x right, y down, z forward)
// Points given to and returned by the encoder/decoder are in the camera frame c.
#include <Eigen/Core>
#include <opencv2/core.hpp>

#include <cstdint>
#include <numbers>
#include <vector>

namespace aerie::spherical {

// A point in spherical coordinates (eq. 4.17): r = |p|, polar = acos(z / r) in [0, pi],
// azimuth = atan2(y, x) in (-pi, pi] (the four-quadrant form of tan^-1(y / x)).
struct Spherical {
  float r = 0.f;
  float polar = 0.f;
  float azimuth = 0.f;
};

// Eq. 4.17 on a point of the sensor frame. At the origin all three are 0; on the polar
// axis (x = y = 0) the azimuth is 0.
Spherical to_spherical(const Eigen::Vector3f& p_sensor);
// Inverse of eq. 4.17: x = r sin(polar) cos(azimuth), y = r sin(polar) sin(azimuth), z = r cos(polar).
Eigen::Vector3f to_cartesian(const Spherical& s);

inline Eigen::Vector3f camera_to_sensor(const Eigen::Vector3f& c) { return {c.z(), -c.x(), -c.y()}; }
inline Eigen::Vector3f sensor_to_camera(const Eigen::Vector3f& s) { return {-s.y(), -s.z(), s.x()}; }

inline constexpr float deg_to_rad(float deg) { return deg * std::numbers::pi_v<float> / 180.f; }

// Pinhole intrinsics of the rectified left camera; baseline (metres) only for disparity input.
struct Intrinsics {
  double fx = 0, fy = 0, cx = 0, cy = 0;
  double baseline = 0;
};

// Regular grid over (polar, azimuth). Bin index = polar_index * n_azimuth + azimuth_index;
// bin (i, j) covers [polar_min + i*polar_step, +polar_step) x [azimuth_min + j*azimuth_step, ...).
struct AngularGrid {
  float polar_min = 0.f;
  float polar_step = 0.f;
  int n_polar = 0;
  float azimuth_min = 0.f;
  float azimuth_step = 0.f;
  int n_azimuth = 0;

  // The smallest grid of square bins of `step` radians that covers every pixel ray of a
  // width x height image (one pixel margin).
  static AngularGrid for_camera(const Intrinsics& k, cv::Size image, float step_rad);
  // The whole sphere at `step` radians (for point clouds of any direction).
  static AngularGrid full_sphere(float step_rad);

  int size() const { return n_polar * n_azimuth; }
  // Bin of a direction, -1 when it falls outside the grid.
  int bin(float polar, float azimuth) const;
  // Centre angles of a bin.
  float polar_of(int bin) const { return polar_min + (static_cast<float>(bin / n_azimuth) + 0.5f) * polar_step; }
  float azimuth_of(int bin) const { return azimuth_min + (static_cast<float>(bin % n_azimuth) + 0.5f) * azimuth_step; }
  // Throws std::invalid_argument naming the field when the grid is unusable.
  void validate() const;
  bool operator==(const AngularGrid&) const = default;
};

// How the points that fall into one bin become its single range.
enum class Reduction {
  Median,   // the (lower) median: robust to isolated stereo mismatches; the default
  Nearest,  // the smallest range: conservative for obstacle avoidance, keeps thin foreground
};

struct EncoderConfig {
  // Bin size (both angles). About map resolution / max range keeps the decoded points
  // less than a voxel apart up to the map's range (0.1 m / 5 m ~ 1.1 deg); 1 deg is ~2.8 px
  // of the 376x240 demo camera (fx 163) and makes VO_DEPTH ~12x smaller than raw disparity.
  float angular_resolution_rad = deg_to_rad(1.0f);
  float min_range_m = 0.1f;   // points nearer than this are dropped
  float max_range_m = 20.f;   // points farther than this are dropped
  float range_scale_m = 0.001f;  // quantum of the transmitted ranges (int16: max 32767 * scale)
  Reduction reduction = Reduction::Median;
  int min_points_per_bin = 1;  // bins with fewer points are left empty
  void validate() const;      // throws std::invalid_argument naming the key
};

// One frame's compact depth: the filled bins (ascending) and their quantised ranges
// (r = range_q * range_scale_m, 1 <= range_q <= 32767).
struct SphericalDepth {
  AngularGrid grid;
  float range_scale_m = 0.001f;
  float max_range_m = 0.f;
  // The stereo camera that produced the depth (0 = unknown), for the map's range error
  // model sigma_r = r^2 sigma_d / (f b).
  float focal_px = 0.f;
  float baseline_m = 0.f;
  std::vector<int32_t> bins;
  std::vector<int16_t> range_q;

  size_t size() const { return bins.size(); }
  float range(size_t i) const { return static_cast<float>(range_q[i]) * range_scale_m; }
  // The 3D point of filled bin i (bin centre direction, decoded range) in the camera frame.
  Eigen::Vector3f point_camera(size_t i) const;
  // All points in the camera frame (appended to `out`).
  void decode(std::vector<Eigen::Vector3f>& out) const;
  std::vector<Eigen::Vector3f> decode() const;
  // Throws std::invalid_argument on inconsistent contents (sizes, order, ranges).
  void validate() const;
};

// Encodes points of the camera frame on any grid (used for point clouds and by the tests).
SphericalDepth encode_points(const std::vector<Eigen::Vector3f>& points_camera, const AngularGrid& grid,
                             const EncoderConfig& cfg = {});

// Encoder for images of one size and camera: each pixel's bin and the ratio
// r / z = |(u - cx)/fx, (v - cy)/fy, 1| are computed once, so encoding a frame is a
// table look-up per pixel plus the per-bin reduction (O(pixels)).
class SphericalEncoder {
 public:
  SphericalEncoder(const Intrinsics& k, cv::Size image, const EncoderConfig& cfg = {});

  // depth: CV_32F, metres along the optical axis z; <= 0 or non-finite = no depth.
  SphericalDepth encode_depth(const cv::Mat& depth) const;
  // disparity: CV_32F pixels, or CV_16S fixed point x16 (cv::StereoSGBM's output);
  // <= 0 or non-finite = no depth. z = fx * baseline / d. Needs Intrinsics::baseline > 0.
  SphericalDepth encode_disparity(const cv::Mat& disparity) const;

  const AngularGrid& grid() const { return grid_; }
  const EncoderConfig& config() const { return cfg_; }
  cv::Size image_size() const { return size_; }

 private:
  template <typename Range>
  SphericalDepth encode(Range&& range_of_pixel) const;

  Intrinsics k_;
  cv::Size size_;
  EncoderConfig cfg_;
  AngularGrid grid_;
  std::vector<int32_t> pixel_bin_;    // per pixel, -1 outside the grid
  std::vector<float> pixel_r_per_z_;  // per pixel
};

}  // namespace aerie::spherical
