#include "tools/eval/stereo_dataset.hpp"

#include <opencv2/imgcodecs.hpp>
#include <opencv2/imgproc.hpp>

#include <algorithm>
#include <cmath>
#include <filesystem>
#include <fstream>
#include <sstream>
#include <stdexcept>

#include "common/camera/calibration_io.hpp"

namespace fs = std::filesystem;

namespace aerie::eval {
namespace {

cv::Mat read_gray(const fs::path& p) {
  cv::Mat m = cv::imread(p.string(), cv::IMREAD_GRAYSCALE);
  if (m.empty()) throw std::runtime_error(p.string() + ": cannot read image");
  return m;
}

class KittiSequence final : public StereoSequence {
 public:
  KittiSequence(const fs::path& dir, const std::string& groundtruth) {
    name_ = dir.filename().string();
    for (const auto& [l, r] : {std::pair{"image_0", "image_1"}, std::pair{"image_l", "image_r"}})
      if (fs::is_directory(dir / l) && fs::is_directory(dir / r)) {
        left_dir_ = dir / l;
        right_dir_ = dir / r;
      }
    if (left_dir_.empty())
      throw std::runtime_error(dir.string() + ": no image_0/image_1 or image_l/image_r folders (KITTI layout)");
    for (const auto& e : fs::directory_iterator(left_dir_))
      if (e.path().extension() == ".png") files_.push_back(e.path().filename().string());
    std::sort(files_.begin(), files_.end());
    if (files_.empty()) throw std::runtime_error(left_dir_.string() + ": no PNG images");
    const cv::Mat first = read_gray(left_dir_ / files_.front());
    const auto calib = camera::read_kitti_stereo((dir / "calib.txt").string(), first.cols, first.rows);
    rectifier_ = std::make_unique<camera::StereoRectifier>(calib);
    rig_ = rectifier_->rectified();
    std::vector<double> times;
    if (fs::exists(dir / "times.txt")) {
      std::ifstream in(dir / "times.txt");
      for (double t; in >> t;) times.push_back(t);
      if (times.size() < files_.size())
        throw std::runtime_error((dir / "times.txt").string() + ": fewer times than images");
    }
    for (size_t i = 0; i < files_.size(); ++i)
      utimes_.push_back(times.empty() ? static_cast<int64_t>(i) * 100000 : std::llround(times[i] * 1e6));
    // Ground truth of the left camera: KITTI poses are one line per frame, stamped here with
    // the frames' times (times.txt); TUM and EuRoC CSV files carry their own (seconds of times.txt).
    const fs::path gt = !groundtruth.empty() ? fs::path(groundtruth) : dir / "poses.txt";
    if (!groundtruth.empty() || fs::exists(gt)) {
      TrajectoryFormat format;
      ground_truth_ = read_trajectory(gt.string(), "", &format);
      if (format == TrajectoryFormat::KittiPoses) {
        if (ground_truth_.size() < files_.size())
          throw std::runtime_error(gt.string() + ": " + std::to_string(ground_truth_.size()) +
                                   " KITTI poses for " + std::to_string(files_.size()) + " images (one per frame)");
        ground_truth_.poses.resize(files_.size());
        ground_truth_.stamps.resize(files_.size());
        for (size_t i = 0; i < files_.size(); ++i) ground_truth_.stamps[i] = static_cast<double>(utimes_[i]) * 1e-6;
      }
    }
  }
  void load(size_t i, cv::Mat& left, cv::Mat& right) const override {
    rectifier_->rectify(read_gray(left_dir_ / files_.at(i)), read_gray(right_dir_ / files_.at(i)), left, right);
  }

 private:
  fs::path left_dir_, right_dir_;
  std::vector<std::string> files_;
  std::unique_ptr<camera::StereoRectifier> rectifier_;
};

class EurocSequence final : public StereoSequence {
 public:
  EurocSequence(const fs::path& dir, const std::string& groundtruth) {
    name_ = dir.filename().string();
    const fs::path mav0 = fs::exists(dir / "mav0") ? dir / "mav0" : dir;
    if (!fs::exists(mav0 / "cam0" / "data.csv"))
      throw std::runtime_error(dir.string() + ": no mav0/cam0/data.csv (EuRoC ASL layout)");
    const auto calib = camera::read_euroc_stereo(mav0.string());
    rectifier_ = std::make_unique<camera::StereoRectifier>(calib);
    rig_ = rectifier_->rectified();
    cam0_ = mav0 / "cam0" / "data";
    cam1_ = mav0 / "cam1" / "data";
    // Drive the sequence from cam0's list (the excerpt's cam1 list is longer than its images).
    std::ifstream in(mav0 / "cam0" / "data.csv");
    std::string line;
    while (std::getline(in, line)) {
      if (line.empty() || line[0] == '#') continue;
      const auto comma = line.find(',');
      if (comma == std::string::npos) throw std::runtime_error((mav0 / "cam0/data.csv").string() + ": malformed line");
      std::string file = line.substr(comma + 1);
      file.erase(std::remove_if(file.begin(), file.end(), ::isspace), file.end());
      if (!fs::exists(cam1_ / file)) continue;  // no right image: skip the pair
      utimes_.push_back(std::stoll(line.substr(0, comma)) / 1000);
      files_.push_back(file);
    }
    if (files_.empty()) throw std::runtime_error(dir.string() + ": no stereo pairs listed");

    // Ground truth: body (IMU) poses -> rectified left camera: T_w_rect = T_w_b T_b_cam0 T_cam0_rect.
    Trajectory body;
    if (!groundtruth.empty()) {
      TrajectoryFormat format;
      body = read_trajectory(groundtruth, "", &format);
      if (format == TrajectoryFormat::KittiPoses)
        throw std::runtime_error(groundtruth + ": KITTI poses have no timestamps; a EuRoC sequence needs TUM or "
                                 "EuRoC CSV ground truth of the body");
    }
    if (body.empty() && fs::is_directory(dir / "groundtruth"))
      for (const auto& e : fs::directory_iterator(dir / "groundtruth"))
        if (e.path().extension() == ".txt") body = read_tum(e.path().string());
    if (body.empty() && fs::exists(mav0 / "state_groundtruth_estimate0" / "data.csv"))
      body = read_euroc_csv((mav0 / "state_groundtruth_estimate0" / "data.csv").string());
    if (!body.empty()) {
      const auto cam0 = camera::read_euroc_camera((mav0 / "cam0" / "sensor.yaml").string());
      const cv::Matx33d R1 = rectifier_->R_left();
      Eigen::Matrix3d Rr;
      for (int r = 0; r < 3; ++r)
        for (int c = 0; c < 3; ++c) Rr(r, c) = R1(c, r);  // T_cam0_rect: rotation R1^T
      const geometry::SE3 T_b_rect = cam0.T_body_sensor * geometry::SE3(Rr, Eigen::Vector3d::Zero());
      for (size_t i = 0; i < body.size(); ++i) ground_truth_.push_back(body.stamps[i], body.poses[i] * T_b_rect);
    }
  }
  void load(size_t i, cv::Mat& left, cv::Mat& right) const override {
    rectifier_->rectify(read_gray(cam0_ / files_.at(i)), read_gray(cam1_ / files_.at(i)), left, right);
  }

 private:
  fs::path cam0_, cam1_;
  std::vector<std::string> files_;
  std::unique_ptr<camera::StereoRectifier> rectifier_;
};

}  // namespace

std::unique_ptr<StereoSequence> open_kitti(const std::string& dir, const std::string& groundtruth) {
  return std::make_unique<KittiSequence>(dir, groundtruth);
}
std::unique_ptr<StereoSequence> open_euroc(const std::string& dir, const std::string& groundtruth) {
  return std::make_unique<EurocSequence>(dir, groundtruth);
}

std::unique_ptr<StereoSequence> open_sequence(const std::string& spec, const std::string& groundtruth) {
  const auto colon = spec.find(':');
  const std::string kind = spec.substr(0, colon), dir = colon == std::string::npos ? "" : spec.substr(colon + 1);
  if (kind == "kitti") return open_kitti(dir, groundtruth);
  if (kind == "euroc") return open_euroc(dir, groundtruth);
  throw std::invalid_argument("dataset '" + spec + "': expected kitti:DIR or euroc:DIR");
}

}  // namespace aerie::eval
