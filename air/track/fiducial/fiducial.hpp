#pragma once
// Fiducials as a pose source for the landing (issue 50, section 3): AprilTag 3 (libapriltag) and
// ArUco (OpenCV contrib's cv::aruco) tags, single or as a board of several tags of different
// sizes (a large tag for altitude, small ones inside its free centre or beside it for the last
// metre), whose metric pose comes from whichever of the board's tags are seen.
//
// Method (docs/track.md, "Fiducials"): the detector's tag corners are undistorted through the
// camera model (common/camera: normalised rays, so any distortion model of the calibration is
// honoured); the initial pose is the best fit to every corner of IPPE's two solutions for the
// largest tag seen (Collins & Bartoli, IJCV 2014; cv::SOLVEPNP_IPPE_SQUARE) and SQPnP's on
// every corner (Terzakis & Lourakis, ECCV 2020; IPPE has no finite answer for an exactly
// fronto-parallel view), refined by Levenberg-Marquardt over the corners of every tag seen. The covariance of the pose is
// sigma^2 (J^T J)^-1 of that least-squares problem (J: the corners' Jacobian), sigma the RMS
// corner residual with a floor.
//
// Frames: the board frame has x to the right of the printed board, y to its top and z out of
// its face (towards the camera above it); its origin is the board's centre (the pad centre the
// landing aims at). A tag's size is the side of the square whose corners the detector finds
// (AprilTag: the outer edge of the black border, width_at_border cells; ArUco: the black square).
#include <Eigen/Core>
#include <opencv2/core.hpp>

#include <array>
#include <memory>
#include <optional>
#include <string>
#include <vector>

#include "common/camera/camera_model.hpp"
#include "common/util/config.hpp"

namespace aerie::track {

enum class FiducialKind { AprilTag, ArUco };
std::string to_string(FiducialKind kind);
FiducialKind fiducial_kind_from_string(const std::string& name);  // "apriltag" | "aruco", throws otherwise

struct FiducialTag {
  int id = 0;
  double size = 0;        // side of the detected square, metres
  double x = 0, y = 0;    // its centre in the board frame, metres
};

struct FiducialBoard {
  FiducialKind kind = FiducialKind::AprilTag;
  std::string family = "tag36h11";  // AprilTag family (tag36h11, tagStandard41h12, ...) or ArUco dictionary (DICT_4X4_50, ...)
  std::vector<FiducialTag> tags;
};

// The families a kind knows, for messages and --help.
std::vector<std::string> fiducial_families(FiducialKind kind);

struct FiducialOptions {
  double max_reprojection_px = 2.0;  // RMS of the corners against the fitted board; beyond it the pose is refused
  double quad_decimate = 1.0;        // AprilTag: quad detection on an image decimated by this (>= 1; faster, shorter range)
  int max_hamming = 1;               // AprilTag: bit errors corrected (0..2; 2 needs much memory for the large families)
  int threads = 1;                   // AprilTag: detector threads
  double corner_sigma_floor_px = 0.1;  // the corner noise assumed at least, for the covariance
};

// One tag found in an image: its corners in pixels (distorted, as seen) in the order top-left,
// top-right, bottom-right, bottom-left of the printed tag (clockwise in an image of its face).
struct FiducialDetection {
  int id = 0;
  std::array<cv::Point2d, 4> corners;
};

struct FiducialPose {
  Eigen::Vector3d position = Eigen::Vector3d::Zero();      // board origin, camera optical frame (m)
  Eigen::Matrix3d rotation = Eigen::Matrix3d::Identity();  // board axes in the camera frame
  double yaw = 0;                // atan2 of the image-y over the image-x component of the board's +x, (-pi, pi]
  double reprojection_rms = 0;   // px
  double quality = 0;            // 1 - reprojection_rms / max_reprojection_px, in [0, 1]
  // Covariance of (rotation vector, position), the rotation vector's perturbation applied on
  // the left (camera frame): rad^2, m^2.
  Eigen::Matrix<double, 6, 6> covariance = Eigen::Matrix<double, 6, 6>::Zero();
  std::vector<int> ids;          // the board's tags used, in the board's order
  std::vector<FiducialDetection> tags;  // their detections
  cv::Rect2d box;                // axis-aligned box of the used corners, pixels
};

// Why estimate() returned nothing.
enum class FiducialMiss { None, NoTag, Reprojection };
std::string to_string(FiducialMiss miss);

class FiducialDetector {
 public:
  // Throws std::invalid_argument naming the problem: an unknown family (listing the known ones),
  // no tags, a size <= 0, an id outside the family or twice, tags that overlap (a tag may lie
  // wholly inside another one's free centre, for the AprilTag families that have one).
  explicit FiducialDetector(FiducialBoard board, FiducialOptions options = {});
  ~FiducialDetector();
  FiducialDetector(const FiducialDetector&) = delete;
  FiducialDetector& operator=(const FiducialDetector&) = delete;

  const FiducialBoard& board() const { return board_; }
  const FiducialOptions& options() const { return options_; }

  // Every tag of the family in an 8-bit gray or BGR image (ids of other boards included).
  // Throws std::invalid_argument on an empty image.
  std::vector<FiducialDetection> detect(const cv::Mat& image);
  // The board's pose from the tags of it seen (an id seen twice is ignored). Throws
  // std::invalid_argument on an empty image or a camera that is unusable or of another size.
  std::optional<FiducialPose> estimate(const cv::Mat& image, const camera::CameraModel& camera,
                                       FiducialMiss* miss = nullptr);
  // The pose from detections already made (detect()).
  std::optional<FiducialPose> estimate(const std::vector<FiducialDetection>& detections,
                                       const camera::CameraModel& camera, FiducialMiss* miss = nullptr) const;

 private:
  struct Impl;
  FiducialBoard board_;
  FiducialOptions options_;
  std::unique_ptr<Impl> impl_;
};

// The four corners of a tag of the board in the board frame (z = 0), in FiducialDetection's order.
std::array<Eigen::Vector3d, 4> tag_corners(const FiducialTag& tag);

// A printable image of the board: square, centred on the board origin, `side_m` metres wide
// (<= 0: the smallest square holding every tag with its quiet zone), white around the tags.
struct BoardImage {
  cv::Mat image;                 // 8-bit gray
  double side_m = 0;             // metres the image spans (its width = its height)
  double pixels_per_metre = 0;
};
// AprilTag bitmaps come from the family's codes (apriltag_to_image), ArUco ones from
// cv::aruco::drawMarker. Throws std::invalid_argument on a board the detector refuses, a tag
// outside side_m or fewer than 2 pixels per cell of the smallest tag.
BoardImage render_board(const FiducialBoard& board, int pixels, double side_m = 0);

// Reads a "fiducial" section (docs/track.md, "Fiducials"): family, tags (a list of {id, size,
// x, y}), options (max_reprojection_px, quad_decimate, max_hamming, threads). Throws
// std::runtime_error naming the file and key; the board is validated (FiducialDetector's checks).
FiducialBoard fiducial_board(const util::Config& section, FiducialKind kind);
FiducialOptions fiducial_options(const util::Config& section);

}  // namespace aerie::track
