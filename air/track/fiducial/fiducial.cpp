#include "air/track/fiducial/fiducial.hpp"

#include <apriltag/apriltag.h>
#include <apriltag/tag16h5.h>
#include <apriltag/tag25h9.h>
#include <apriltag/tag36h10.h>
#include <apriltag/tag36h11.h>
#include <apriltag/tagCircle21h7.h>
#include <apriltag/tagCircle49h12.h>
#include <apriltag/tagCustom48h12.h>
#include <apriltag/tagStandard41h12.h>
#include <apriltag/tagStandard52h13.h>
#include <opencv2/aruco.hpp>
#include <opencv2/calib3d.hpp>
#include <opencv2/imgproc.hpp>

#include <Eigen/Dense>
#include <algorithm>
#include <cmath>
#include <map>
#include <sstream>
#include <stdexcept>

namespace aerie::track {

namespace {

struct AprilFamily {
  const char* name;
  apriltag_family_t* (*create)();
  void (*destroy)(apriltag_family_t*);
};
const AprilFamily kAprilFamilies[] = {
    {"tag36h11", tag36h11_create, tag36h11_destroy},
    {"tag36h10", tag36h10_create, tag36h10_destroy},
    {"tag25h9", tag25h9_create, tag25h9_destroy},
    {"tag16h5", tag16h5_create, tag16h5_destroy},
    {"tagStandard41h12", tagStandard41h12_create, tagStandard41h12_destroy},
    {"tagStandard52h13", tagStandard52h13_create, tagStandard52h13_destroy},
    {"tagCircle21h7", tagCircle21h7_create, tagCircle21h7_destroy},
    {"tagCircle49h12", tagCircle49h12_create, tagCircle49h12_destroy},
    {"tagCustom48h12", tagCustom48h12_create, tagCustom48h12_destroy},
};

#define AERIE_ARUCO(name) {#name, cv::aruco::name}
const std::pair<const char*, cv::aruco::PREDEFINED_DICTIONARY_NAME> kArucoDictionaries[] = {
    AERIE_ARUCO(DICT_4X4_50), AERIE_ARUCO(DICT_4X4_100), AERIE_ARUCO(DICT_4X4_250), AERIE_ARUCO(DICT_4X4_1000),
    AERIE_ARUCO(DICT_5X5_50), AERIE_ARUCO(DICT_5X5_100), AERIE_ARUCO(DICT_5X5_250), AERIE_ARUCO(DICT_5X5_1000),
    AERIE_ARUCO(DICT_6X6_50), AERIE_ARUCO(DICT_6X6_100), AERIE_ARUCO(DICT_6X6_250), AERIE_ARUCO(DICT_6X6_1000),
    AERIE_ARUCO(DICT_7X7_50), AERIE_ARUCO(DICT_7X7_100), AERIE_ARUCO(DICT_7X7_250), AERIE_ARUCO(DICT_7X7_1000),
    AERIE_ARUCO(DICT_ARUCO_ORIGINAL), AERIE_ARUCO(DICT_APRILTAG_16h5), AERIE_ARUCO(DICT_APRILTAG_25h9),
    AERIE_ARUCO(DICT_APRILTAG_36h10), AERIE_ARUCO(DICT_APRILTAG_36h11),
};
#undef AERIE_ARUCO

std::string joined(const std::vector<std::string>& names) {
  std::string s;
  for (const auto& n : names) s += (s.empty() ? "" : ", ") + n;
  return s;
}

std::string unknown_family(FiducialKind kind, const std::string& family) {
  return "fiducial family '" + family + "' does not exist for " + to_string(kind) + " (known: " +
         joined(fiducial_families(kind)) + ")";
}

// The AprilTag family, owned (the library's families are heap tables).
struct FamilyHandle {
  apriltag_family_t* family = nullptr;
  void (*destroy)(apriltag_family_t*) = nullptr;
  explicit FamilyHandle(const std::string& name) {
    for (const auto& f : kAprilFamilies)
      if (name == f.name) {
        family = f.create();
        destroy = f.destroy;
        return;
      }
    throw std::invalid_argument(unknown_family(FiducialKind::AprilTag, name));
  }
  ~FamilyHandle() {
    if (family) destroy(family);
  }
  FamilyHandle(const FamilyHandle&) = delete;
  FamilyHandle& operator=(const FamilyHandle&) = delete;
};

cv::Ptr<cv::aruco::Dictionary> aruco_dictionary(const std::string& name) {
  for (const auto& [n, d] : kArucoDictionaries)
    if (name == n) return cv::aruco::getPredefinedDictionary(d);
  throw std::invalid_argument(unknown_family(FiducialKind::ArUco, name));
}

// What the board checks and the renderer need of a family, in cells of a tag's bitmap.
struct FamilyGeometry {
  int detected_cells = 0;   // side of the detected square
  int bitmap_cells = 0;     // side of the whole bitmap, quiet zone included where the family has one
  double free_half_cells = 0;  // half side of the centred square of the bitmap that holds no bit nor border
  int ncodes = 0;
};

FamilyGeometry april_geometry(const apriltag_family_t& f) {
  FamilyGeometry g;
  g.detected_cells = f.width_at_border;
  g.bitmap_cells = f.total_width;
  g.ncodes = static_cast<int>(f.ncodes);
  // A cell (i, j) intersects the centred square of half side h iff h > its distance to the
  // centre along both axes; the free centre is the smallest such distance over the cells used.
  const double c = f.total_width / 2.0;
  const int start = (f.total_width - f.width_at_border) / 2;
  auto cell_distance = [&](int i, int j) {
    auto d = [&](int k) { return std::max({k - c, c - (k + 1), 0.0}); };
    return std::max(d(i), d(j));
  };
  double free = c;
  for (uint32_t b = 0; b < f.nbits; ++b)
    free = std::min(free, cell_distance(static_cast<int>(f.bit_x[b]) + start, static_cast<int>(f.bit_y[b]) + start));
  for (int k = 0; k < f.width_at_border; ++k)  // the border's ring
    for (const auto& [i, j] : {std::pair{start + k, start}, {start + k, start + f.width_at_border - 1},
                               {start, start + k}, {start + f.width_at_border - 1, start + k}})
      free = std::min(free, cell_distance(i, j));
  g.free_half_cells = free;
  return g;
}

FamilyGeometry family_geometry(const FiducialBoard& board) {
  if (board.kind == FiducialKind::AprilTag) {
    const FamilyHandle h(board.family);
    return april_geometry(*h.family);
  }
  const auto d = aruco_dictionary(board.family);
  FamilyGeometry g;
  g.detected_cells = d->markerSize + 2;
  g.bitmap_cells = d->markerSize + 4;  // one white cell of quiet zone around the black border
  g.ncodes = d->bytesList.rows;
  return g;
}

// Checks the board (FiducialDetector's contract) and returns its family's geometry.
FamilyGeometry validate(const FiducialBoard& board) {
  const FamilyGeometry g = family_geometry(board);
  const std::string family = to_string(board.kind) + " " + board.family;
  if (board.tags.empty()) throw std::invalid_argument("fiducial board of " + family + " has no tags");
  for (size_t i = 0; i < board.tags.size(); ++i) {
    const FiducialTag& t = board.tags[i];
    const std::string name = "fiducial tag " + std::to_string(t.id);
    if (!(t.size > 0) || !std::isfinite(t.size))
      throw std::invalid_argument(name + ": size " + std::to_string(t.size) + " m must be > 0");
    if (!std::isfinite(t.x) || !std::isfinite(t.y)) throw std::invalid_argument(name + ": x and y must be finite");
    if (t.id < 0 || t.id >= g.ncodes)
      throw std::invalid_argument(name + ": no such id in " + family + " (ids 0.." + std::to_string(g.ncodes - 1) + ")");
    for (size_t j = 0; j < i; ++j) {
      const FiducialTag& o = board.tags[j];
      if (o.id == t.id) throw std::invalid_argument(name + " is on the board twice");
      const double a = t.size * g.bitmap_cells / g.detected_cells, b = o.size * g.bitmap_cells / g.detected_cells;
      const double dx = std::abs(t.x - o.x), dy = std::abs(t.y - o.y);
      if (!(dx < (a + b) / 2 - 1e-9 && dy < (a + b) / 2 - 1e-9)) continue;
      // Overlapping bitmaps are a nested board only when the smaller lies in the larger's free centre.
      const FiducialTag& out = a < b ? o : t;
      const double in_side = std::min(a, b);
      const double free = g.free_half_cells * out.size / g.detected_cells;
      if (dx + in_side / 2 <= free + 1e-9 && dy + in_side / 2 <= free + 1e-9) continue;
      std::ostringstream m;
      m << "fiducial tags " << o.id << " and " << t.id << " overlap (centres (" << o.x << ", " << o.y << ") and (" << t.x
        << ", " << t.y << ") m, bitmaps " << b << " and " << a << " m wide";
      if (free > 0) m << "; the free centre of tag " << out.id << " is " << 2 * free << " m wide";
      m << ")";
      throw std::invalid_argument(m.str());
    }
  }
  return g;
}

cv::Mat to_gray(const cv::Mat& image) {
  if (image.empty()) throw std::invalid_argument("fiducial detection: empty image");
  if (image.depth() != CV_8U) throw std::invalid_argument("fiducial detection: expected an 8-bit image");
  cv::Mat gray;
  if (image.channels() == 1) gray = image;
  else if (image.channels() == 3) cv::cvtColor(image, gray, cv::COLOR_BGR2GRAY);
  else if (image.channels() == 4) cv::cvtColor(image, gray, cv::COLOR_BGRA2GRAY);
  else throw std::invalid_argument("fiducial detection: expected a gray, BGR or BGRA image");
  return gray.isContinuous() ? gray : gray.clone();
}

double quad_area(const std::array<cv::Point2d, 4>& p) {
  double a = 0;
  for (int i = 0; i < 4; ++i) a += p[i].x * p[(i + 1) % 4].y - p[(i + 1) % 4].x * p[i].y;
  return std::abs(a) / 2;
}

}  // namespace

std::string to_string(FiducialKind kind) { return kind == FiducialKind::AprilTag ? "apriltag" : "aruco"; }

FiducialKind fiducial_kind_from_string(const std::string& name) {
  if (name == "apriltag") return FiducialKind::AprilTag;
  if (name == "aruco") return FiducialKind::ArUco;
  throw std::invalid_argument("unknown fiducial kind '" + name + "' (apriltag or aruco)");
}

std::vector<std::string> fiducial_families(FiducialKind kind) {
  std::vector<std::string> names;
  if (kind == FiducialKind::AprilTag)
    for (const auto& f : kAprilFamilies) names.emplace_back(f.name);
  else
    for (const auto& d : kArucoDictionaries) names.emplace_back(d.first);
  return names;
}

std::string to_string(FiducialMiss miss) {
  switch (miss) {
    case FiducialMiss::None: return "none";
    case FiducialMiss::NoTag: return "no_tag";
    case FiducialMiss::Reprojection: return "reprojection";
  }
  return "unknown";
}

std::array<Eigen::Vector3d, 4> tag_corners(const FiducialTag& t) {
  const double h = t.size / 2;
  return {Eigen::Vector3d(t.x - h, t.y + h, 0), Eigen::Vector3d(t.x + h, t.y + h, 0),
          Eigen::Vector3d(t.x + h, t.y - h, 0), Eigen::Vector3d(t.x - h, t.y - h, 0)};
}

struct FiducialDetector::Impl {
  std::unique_ptr<FamilyHandle> family;  // AprilTag
  apriltag_detector_t* detector = nullptr;
  cv::Ptr<cv::aruco::Dictionary> dictionary;  // ArUco
  cv::Ptr<cv::aruco::DetectorParameters> parameters;
  std::map<int, size_t> index;  // id -> position on the board
  ~Impl() {
    if (detector) apriltag_detector_destroy(detector);
  }
};

FiducialDetector::FiducialDetector(FiducialBoard board, FiducialOptions options)
    : board_(std::move(board)), options_(options), impl_(std::make_unique<Impl>()) {
  validate(board_);
  if (!(options_.max_reprojection_px > 0)) throw std::invalid_argument("fiducial max_reprojection_px must be > 0");
  if (!(options_.quad_decimate >= 1 && options_.quad_decimate <= 8))
    throw std::invalid_argument("fiducial quad_decimate must be in [1, 8]");
  if (options_.max_hamming < 0 || options_.max_hamming > 2) throw std::invalid_argument("fiducial max_hamming must be 0, 1 or 2");
  if (options_.threads < 1 || options_.threads > 64) throw std::invalid_argument("fiducial threads must be in [1, 64]");
  if (!(options_.corner_sigma_floor_px > 0)) throw std::invalid_argument("fiducial corner_sigma_floor_px must be > 0");
  for (size_t i = 0; i < board_.tags.size(); ++i) impl_->index[board_.tags[i].id] = i;
  if (board_.kind == FiducialKind::AprilTag) {
    impl_->family = std::make_unique<FamilyHandle>(board_.family);
    impl_->detector = apriltag_detector_create();
    apriltag_detector_add_family_bits(impl_->detector, impl_->family->family, options_.max_hamming);
    impl_->detector->quad_decimate = static_cast<float>(options_.quad_decimate);
    impl_->detector->quad_sigma = 0;
    impl_->detector->nthreads = options_.threads;
    impl_->detector->refine_edges = true;
  } else {
    impl_->dictionary = aruco_dictionary(board_.family);
    impl_->parameters = cv::aruco::DetectorParameters::create();
    impl_->parameters->cornerRefinementMethod = cv::aruco::CORNER_REFINE_SUBPIX;
    // Thresholding windows up to 63 px (OpenCV's default stops at 23): a marker filling the view
    // in the last metre has cells wider than 23 px, whose borders the small windows split.
    impl_->parameters->adaptiveThreshWinSizeMax = 63;
    impl_->parameters->adaptiveThreshWinSizeStep = 10;
  }
}

FiducialDetector::~FiducialDetector() = default;

std::vector<FiducialDetection> FiducialDetector::detect(const cv::Mat& image) {
  const cv::Mat gray = to_gray(image);
  std::vector<FiducialDetection> out;
  if (board_.kind == FiducialKind::AprilTag) {
    image_u8_t im{gray.cols, gray.rows, static_cast<int32_t>(gray.step[0]), const_cast<uint8_t*>(gray.ptr<uint8_t>())};
    zarray_t* found = apriltag_detector_detect(impl_->detector, &im);
    for (int i = 0; i < zarray_size(found); ++i) {
      apriltag_detection_t* d = nullptr;
      zarray_get(found, i, &d);
      FiducialDetection f;
      f.id = d->id;
      // p[] runs from the tag's (-1, 1) (bottom left, tag y down) counter-clockwise in the image.
      const int order[4] = {3, 2, 1, 0};
      for (int k = 0; k < 4; ++k) f.corners[k] = {d->p[order[k]][0], d->p[order[k]][1]};
      out.push_back(f);
    }
    apriltag_detections_destroy(found);
  } else {
    std::vector<std::vector<cv::Point2f>> corners;
    std::vector<int> ids;
    cv::aruco::detectMarkers(gray, impl_->dictionary, corners, ids, impl_->parameters);
    for (size_t i = 0; i < ids.size(); ++i) {
      FiducialDetection f;
      f.id = ids[i];
      for (int k = 0; k < 4; ++k) f.corners[k] = corners[i][k];  // top left, clockwise
      out.push_back(f);
    }
  }
  return out;
}

std::optional<FiducialPose> FiducialDetector::estimate(const cv::Mat& image, const camera::CameraModel& camera,
                                                       FiducialMiss* miss) {
  camera.validate("fiducial camera");
  if (!image.empty() && (image.cols != camera.width || image.rows != camera.height))
    throw std::invalid_argument("fiducial camera is " + std::to_string(camera.width) + "x" + std::to_string(camera.height) +
                                ", the image " + std::to_string(image.cols) + "x" + std::to_string(image.rows));
  return estimate(detect(image), camera, miss);
}

std::optional<FiducialPose> FiducialDetector::estimate(const std::vector<FiducialDetection>& detections,
                                                       const camera::CameraModel& camera, FiducialMiss* miss) const {
  camera.validate("fiducial camera");
  if (miss) *miss = FiducialMiss::None;
  // The board's tags seen exactly once, in the board's order.
  std::map<size_t, const FiducialDetection*> seen;
  std::map<size_t, int> times;
  for (const auto& d : detections)
    if (const auto it = impl_->index.find(d.id); it != impl_->index.end()) {
      seen[it->second] = &d;
      ++times[it->second];
    }
  FiducialPose pose;
  std::vector<cv::Point3d> object;
  std::vector<cv::Point2d> rays;  // undistorted, normalised (x/z, y/z)
  size_t largest = 0;
  double largest_area = -1;
  for (const auto& [i, d] : seen) {
    if (times[i] != 1) continue;
    pose.ids.push_back(d->id);
    pose.tags.push_back(*d);
    const auto corners = tag_corners(board_.tags[i]);
    for (int k = 0; k < 4; ++k) {
      object.emplace_back(corners[k].x(), corners[k].y(), 0);
      const Eigen::Vector3d r = camera.unproject({d->corners[k].x, d->corners[k].y});
      rays.emplace_back(r.x() / r.z(), r.y() / r.z());
    }
    if (const double a = quad_area(d->corners); a > largest_area) {
      largest_area = a;
      largest = pose.ids.size() - 1;
    }
  }
  if (pose.ids.empty()) {
    if (miss) *miss = FiducialMiss::NoTag;
    return std::nullopt;
  }
  const cv::Mat K = cv::Mat::eye(3, 3, CV_64F);
  const auto residual = [&](const cv::Mat& rvec, const cv::Mat& tvec, cv::Mat* jacobian) {
    std::vector<cv::Point2d> p;
    if (jacobian) cv::projectPoints(object, rvec, tvec, K, cv::noArray(), p, *jacobian);
    else cv::projectPoints(object, rvec, tvec, K, cv::noArray(), p);
    double s = 0;
    for (size_t k = 0; k < p.size(); ++k) {
      const double dx = (p[k].x - rays[k].x) * camera.fx, dy = (p[k].y - rays[k].y) * camera.fy;
      s += dx * dx + dy * dy;
    }
    return std::sqrt(s / static_cast<double>(p.size()));
  };

  // IPPE on the largest tag (its own centred frame), moved to the board frame: R_b = R_t,
  // t_b = t_t - R_t * c (c: the tag's centre on the board); the solution that fits every corner best.
  const FiducialTag& big = board_.tags[impl_->index.at(pose.ids[largest])];
  const FiducialTag local{big.id, big.size, 0, 0};
  std::vector<cv::Point3d> local_object;
  std::vector<cv::Point2d> local_rays(rays.begin() + 4 * static_cast<long>(largest), rays.begin() + 4 * static_cast<long>(largest) + 4);
  for (const auto& c : tag_corners(local)) local_object.emplace_back(c.x(), c.y(), 0);
  std::vector<cv::Mat> rvecs, tvecs;
  cv::solvePnPGeneric(local_object, local_rays, K, cv::noArray(), rvecs, tvecs, false, cv::SOLVEPNP_IPPE_SQUARE);
  for (size_t s = 0; s < rvecs.size(); ++s) {
    cv::Mat R;
    cv::Rodrigues(rvecs[s], R);
    tvecs[s] = tvecs[s] - R * (cv::Mat_<double>(3, 1) << big.x, big.y, 0);
  }
  // The other candidate (IPPE fails on an exactly fronto-parallel view): SQPnP on every corner.
  if (cv::Mat r, t; cv::solvePnP(object, rays, K, cv::noArray(), r, t, false, cv::SOLVEPNP_SQPNP)) {
    rvecs.push_back(r);
    tvecs.push_back(t);
  }
  cv::Mat rvec, tvec;
  double best = std::numeric_limits<double>::infinity();
  for (size_t s = 0; s < rvecs.size(); ++s) {
    const cv::Mat& t = tvecs[s];
    if (const double e = residual(rvecs[s], t, nullptr); e < best) {
      best = e;
      rvec = rvecs[s].clone();
      tvec = t;
    }
  }
  if (rvec.empty()) {
    if (miss) *miss = FiducialMiss::Reprojection;
    return std::nullopt;
  }
  cv::solvePnPRefineLM(object, rays, K, cv::noArray(), rvec, tvec);
  cv::Mat J;
  pose.reprojection_rms = residual(rvec, tvec, &J);
  if (!(pose.reprojection_rms <= options_.max_reprojection_px)) {
    if (miss) *miss = FiducialMiss::Reprojection;
    return std::nullopt;
  }
  cv::Mat R;
  cv::Rodrigues(rvec, R);
  for (int r = 0; r < 3; ++r) {
    pose.position[r] = tvec.at<double>(r);
    for (int c = 0; c < 3; ++c) pose.rotation(r, c) = R.at<double>(r, c);
  }
  pose.yaw = std::atan2(pose.rotation(1, 0), pose.rotation(0, 0));
  pose.quality = std::clamp(1 - pose.reprojection_rms / options_.max_reprojection_px, 0.0, 1.0);

  // sigma^2 (J^T J)^-1, J in pixels (the rows scaled by fx, fy), its first 6 columns: rvec, tvec.
  const int n = static_cast<int>(object.size()) * 2;
  Eigen::MatrixXd Jp(n, 6);
  for (int r = 0; r < n; ++r)
    for (int c = 0; c < 6; ++c) Jp(r, c) = J.at<double>(r, c) * (r % 2 == 0 ? camera.fx : camera.fy);
  const double dof_scale = n > 6 ? std::sqrt(static_cast<double>(n) / (n - 6)) : 1.0;
  const double sigma = std::max(pose.reprojection_rms * dof_scale, options_.corner_sigma_floor_px);
  pose.covariance = sigma * sigma * (Jp.transpose() * Jp).ldlt().solve(Eigen::Matrix<double, 6, 6>::Identity());

  double x0 = 1e300, y0 = 1e300, x1 = -1e300, y1 = -1e300;
  for (const auto& d : pose.tags)
    for (const auto& p : d.corners) {
      x0 = std::min(x0, p.x), y0 = std::min(y0, p.y), x1 = std::max(x1, p.x), y1 = std::max(y1, p.y);
    }
  pose.box = {x0, y0, x1 - x0, y1 - y0};
  return pose;
}

BoardImage render_board(const FiducialBoard& board, int pixels, double side_m) {
  const FamilyGeometry g = validate(board);
  if (pixels < 8 || pixels > 16384) throw std::invalid_argument("fiducial board image: pixels must be in [8, 16384]");
  double extent = 0, largest_cell = 0, smallest_cell = 1e300;
  for (const auto& t : board.tags) {
    const double cell = t.size / g.detected_cells, half = cell * g.bitmap_cells / 2;
    extent = std::max({extent, std::abs(t.x) + half, std::abs(t.y) + half});
    largest_cell = std::max(largest_cell, cell);
    smallest_cell = std::min(smallest_cell, cell);
  }
  if (side_m <= 0) side_m = 2 * (extent + largest_cell);
  if (extent > side_m / 2 + 1e-9)
    throw std::invalid_argument("fiducial board image of " + std::to_string(side_m) + " m: the tags reach " +
                                std::to_string(extent) + " m from the centre");
  BoardImage out;
  out.side_m = side_m;
  out.pixels_per_metre = pixels / side_m;
  if (smallest_cell * out.pixels_per_metre < 2)
    throw std::invalid_argument("fiducial board image: " + std::to_string(pixels) + " pixels give the smallest tag's cells " +
                                "fewer than 2 pixels (" + std::to_string(smallest_cell * out.pixels_per_metre) + ")");
  out.image = cv::Mat(pixels, pixels, CV_8UC1, cv::Scalar(255));

  // Larger tags first: a nested tag paints over its host's free centre.
  std::vector<const FiducialTag*> order;
  for (const auto& t : board.tags) order.push_back(&t);
  std::stable_sort(order.begin(), order.end(), [](const auto* a, const auto* b) { return a->size > b->size; });
  std::unique_ptr<FamilyHandle> family;
  cv::Ptr<cv::aruco::Dictionary> dictionary;
  if (board.kind == FiducialKind::AprilTag) family = std::make_unique<FamilyHandle>(board.family);
  else dictionary = aruco_dictionary(board.family);
  for (const FiducialTag* t : order) {
    cv::Mat bitmap(g.bitmap_cells, g.bitmap_cells, CV_8UC1, cv::Scalar(255));
    if (family) {
      image_u8_t* im = apriltag_to_image(family->family, t->id);
      for (int r = 0; r < im->height; ++r)
        for (int c = 0; c < im->width; ++c) bitmap.at<uint8_t>(r, c) = im->buf[r * im->stride + c];
      image_u8_destroy(im);
    } else {
      cv::Mat marker;
      cv::aruco::drawMarker(dictionary, t->id, g.detected_cells, marker, 1);
      marker.copyTo(bitmap(cv::Rect(1, 1, g.detected_cells, g.detected_cells)));
    }
    // Each pixel takes the cell under its centre (board x right, y up; image rows down).
    const double cell = t->size / g.detected_cells, half = cell * g.bitmap_cells / 2;
    const double ppm = out.pixels_per_metre, left = t->x - half, top = t->y + half;
    const int u0 = std::max(0, static_cast<int>(std::floor((left + side_m / 2) * ppm)));
    const int u1 = std::min(pixels - 1, static_cast<int>(std::ceil((t->x + half + side_m / 2) * ppm)));
    const int v0 = std::max(0, static_cast<int>(std::floor((side_m / 2 - top) * ppm)));
    const int v1 = std::min(pixels - 1, static_cast<int>(std::ceil((side_m / 2 - (t->y - half)) * ppm)));
    for (int v = v0; v <= v1; ++v) {
      const int row = static_cast<int>(std::floor((top - (side_m / 2 - (v + 0.5) / ppm)) / cell));
      if (row < 0 || row >= g.bitmap_cells) continue;
      for (int u = u0; u <= u1; ++u) {
        const int col = static_cast<int>(std::floor(((u + 0.5) / ppm - side_m / 2 - left) / cell));
        if (col >= 0 && col < g.bitmap_cells) out.image.at<uint8_t>(v, u) = bitmap.at<uint8_t>(row, col);
      }
    }
  }
  return out;
}

FiducialOptions fiducial_options(const util::Config& s) {
  FiducialOptions o;
  o.max_reprojection_px = s.get_in("max_reprojection_px", o.max_reprojection_px, 1e-3, 100.0);
  o.quad_decimate = s.get_in("quad_decimate", o.quad_decimate, 1.0, 8.0);
  o.max_hamming = s.get_in("max_hamming", o.max_hamming, 0, 2);
  o.threads = s.get_in("threads", o.threads, 1, 64);
  return o;
}

FiducialBoard fiducial_board(const util::Config& s, FiducialKind kind) {
  s.check_keys({"family", "tags", "max_reprojection_px", "quad_decimate", "max_hamming", "threads"});
  FiducialBoard b;
  b.kind = kind;
  b.family = s.get<std::string>("family", kind == FiducialKind::AprilTag ? "tag36h11" : "DICT_4X4_50");
  const YAML::Node tags = s.node()["tags"];
  if (!tags || !tags.IsSequence() || tags.size() == 0)
    throw std::runtime_error(s.origin() + ".tags: expected a list of tags ({id, size, x, y}; size in metres)");
  for (size_t i = 0; i < tags.size(); ++i) {
    const std::string where = s.origin() + ".tags[" + std::to_string(i) + "]";
    const YAML::Node t = tags[i];
    if (!t.IsMap()) throw std::runtime_error(where + ": expected {id, size, x, y}");
    for (const auto& kv : t) {
      const std::string k = kv.first.Scalar();
      if (k != "id" && k != "size" && k != "x" && k != "y")
        throw std::runtime_error(where + ": unknown key '" + k + "' (known: id, size, x, y)");
    }
    FiducialTag tag;
    try {
      if (!t["id"] || !t["size"]) throw std::runtime_error("needs id and size");
      tag.id = t["id"].as<int>();
      tag.size = t["size"].as<double>();
      tag.x = t["x"] ? t["x"].as<double>() : 0.0;
      tag.y = t["y"] ? t["y"].as<double>() : 0.0;
    } catch (const YAML::Exception& e) {
      throw std::runtime_error(where + ": " + e.what());
    } catch (const std::runtime_error& e) {
      throw std::runtime_error(where + ": " + e.what());
    }
    b.tags.push_back(tag);
  }
  try {
    validate(b);
  } catch (const std::invalid_argument& e) {
    throw std::runtime_error(s.origin() + ": " + e.what());
  }
  return b;
}

}  // namespace aerie::track
