#include "air/capture/stereo_sequence_source.hpp"

#include <charconv>
#include <cmath>
#include <filesystem>
#include <fstream>
#include <map>

#include "air/capture/dataset_io.hpp"
#include "common/camera/calibration_io.hpp"

namespace aerie::capture {
namespace fs = std::filesystem;

namespace {

std::string size_str(const cv::Size& s) { return std::to_string(s.width) + "x" + std::to_string(s.height); }

// EuRoC cam*/data.csv: "#timestamp [ns],filename" then "ns,name.png" rows, in time order.
std::vector<std::pair<int64_t, std::string>> read_euroc_csv(const fs::path& csv) {
  std::ifstream in(csv);
  if (!in) throw std::runtime_error(csv.string() + ": cannot open file");
  std::vector<std::pair<int64_t, std::string>> rows;
  std::string line;
  for (int lineno = 1; std::getline(in, line); ++lineno) {
    if (!line.empty() && line.back() == '\r') line.pop_back();
    if (line.empty() || line[0] == '#') continue;
    const auto comma = line.find(',');
    int64_t ns = 0;
    const char* end = line.data() + (comma == std::string::npos ? line.size() : comma);
    const auto [p, ec] = std::from_chars(line.data(), end, ns);
    std::string name = comma == std::string::npos ? "" : line.substr(comma + 1);
    name.erase(0, name.find_first_not_of(' '));
    if (ec != std::errc() || p != end || name.empty())
      throw std::runtime_error(csv.string() + ":" + std::to_string(lineno) + ": expected 'timestamp_ns,filename'");
    rows.emplace_back(ns, name);
  }
  return rows;
}

fs::path first_existing(const fs::path& dir, std::initializer_list<const char*> names) {
  for (const char* n : names)
    if (fs::is_directory(dir / n)) return dir / n;
  return {};
}

}  // namespace

StereoSequence load_euroc(const std::string& dir, const std::string& gt_tum) {
  fs::path root(dir);
  std::error_code ec;
  if (!fs::is_directory(root, ec)) throw std::runtime_error(dir + ": EuRoC folder does not exist");
  if (!fs::exists(root / "cam0") && fs::exists(root / "mav0")) root /= "mav0";
  for (const char* cam : {"cam0", "cam1"})
    if (!fs::exists(root / cam / "data.csv"))
      throw std::runtime_error((root / cam / "data.csv").string() + ": missing (not an EuRoC ASL folder?)");

  StereoSequence s;
  s.calib = camera::read_euroc_stereo(root.string());
  s.description = "EuRoC ASL folder " + root.string();
  s.frame_id = "euroc";
  std::map<int64_t, std::string> cam1;
  for (auto& [ns, name] : read_euroc_csv(root / "cam1" / "data.csv")) cam1[ns] = std::move(name);
  for (const auto& [ns, name] : read_euroc_csv(root / "cam0" / "data.csv")) {
    s.left.push_back((root / "cam0" / "data" / name).string());
    const auto it = cam1.find(ns);
    s.right.push_back(it == cam1.end() ? "" : (root / "cam1" / "data" / it->second).string());
    s.utimes.push_back(ns / 1000);
  }
  if (s.left.empty()) throw std::runtime_error((root / "cam0" / "data.csv").string() + ": no frames");

  // Ground truth: body (IMU) pose in the world; the left camera is T_world_body * T_BS(cam0).
  Trajectory body;
  const fs::path asl_gt = root / "state_groundtruth_estimate0" / "data.csv";
  if (!gt_tum.empty()) {
    body = read_tum(gt_tum);
  } else if (fs::exists(asl_gt)) {
    body = read_euroc_groundtruth(asl_gt.string());
  }
  if (!body.empty()) {
    const auto T_body_cam0 = camera::read_euroc_camera((root / "cam0" / "sensor.yaml").string()).T_body_sensor;
    constexpr int64_t kMaxGapUs = 100'000;
    for (const int64_t t : s.utimes) {
      const auto T_world_body = interpolate(body, t, kMaxGapUs);
      s.gt.push_back(T_world_body ? std::optional(*T_world_body * T_body_cam0) : std::nullopt);
    }
  }
  return s;
}

StereoSequence load_kitti(const std::string& dir, const std::string& poses_file) {
  const fs::path root(dir);
  std::error_code ec;
  if (!fs::is_directory(root, ec)) throw std::runtime_error(dir + ": KITTI folder does not exist");
  const fs::path ldir = first_existing(root, {"image_0", "image_l"});
  const fs::path rdir = first_existing(root, {"image_1", "image_r"});
  if (ldir.empty() || rdir.empty())
    throw std::runtime_error(dir + ": needs image_0/ and image_1/ (or image_l/ and image_r/)");
  StereoSequence s;
  s.description = "KITTI folder " + root.string();
  s.frame_id = "kitti";
  s.left = list_images(ldir.string());
  s.right = list_images(rdir.string());
  if (s.left.empty()) throw std::runtime_error(ldir.string() + ": no images");
  if (s.left.size() != s.right.size())
    throw std::runtime_error(dir + ": " + std::to_string(s.left.size()) + " left images in " + ldir.string() + " but " +
                             std::to_string(s.right.size()) + " right images in " + rdir.string());
  const auto n = s.left.size();

  cv::Mat first;
  try {
    first = load_image(s.left[0], false);
  } catch (const FrameError& e) {
    throw std::runtime_error(e.what());
  }
  // calib.txt has no image size: the reader checks the principal point against the images'.
  s.calib = camera::read_kitti_stereo((root / "calib.txt").string(), first.cols, first.rows);
  const fs::path times = root / "times.txt";
  if (fs::exists(times)) {
    s.utimes = read_timestamps(times.string());
    if (s.utimes.size() != n)
      throw std::runtime_error(times.string() + ": " + std::to_string(s.utimes.size()) + " times for " +
                               std::to_string(n) + " frames");
  } else {
    for (size_t i = 0; i < n; ++i) s.utimes.push_back(static_cast<int64_t>(i) * 100'000);  // KITTI: 10 Hz
  }
  fs::path poses = poses_file;
  if (!poses.empty() && !fs::is_regular_file(poses, ec))
    throw std::runtime_error(poses.string() + ": KITTI poses file does not exist");
  if (poses.empty()) poses = root / "poses.txt";
  // KITTI's download layout: dataset/sequences/NN and dataset/poses/NN.txt.
  const fs::path canonical = fs::weakly_canonical(root, ec);
  const fs::path download = canonical.parent_path().parent_path() / "poses" / (canonical.filename().string() + ".txt");
  if (!fs::exists(poses, ec) && canonical.parent_path().filename() == "sequences" && fs::exists(download, ec))
    poses = download;
  if (fs::exists(poses, ec)) {
    const auto p = read_kitti_poses(poses.string());
    if (p.size() < n)
      throw std::runtime_error(poses.string() + ": " + std::to_string(p.size()) + " poses for " + std::to_string(n) +
                               " frames");
    s.gt.assign(p.begin(), p.begin() + static_cast<std::ptrdiff_t>(n));
  }
  return s;
}

StereoSequenceSource::StereoSequenceSource(StereoSequence seq, bool color)
    : seq_(std::move(seq)), color_(color), rectifier_(seq_.calib) {
  const cv::Matx33d R1 = rectifier_.R_left();
  Eigen::Matrix3d R;
  for (int i = 0; i < 9; ++i) R(i / 3, i % 3) = R1(i / 3, i % 3);
  T_raw_rect_ = geometry::SE3(Eigen::Matrix3d(R.transpose()), Eigen::Vector3d::Zero());  // p_raw = R1^T p_rect

  // The calibration must describe these images.
  try {
    const cv::Mat l = load_image(seq_.left[0], false);
    if (l.size() != seq_.calib.left.size())
      throw std::runtime_error("calibration " + seq_.calib.source + " is for " + size_str(seq_.calib.left.size()) +
                               " images but " + seq_.left[0] + " is " + size_str(l.size()));
    const auto it = std::find_if(seq_.right.begin(), seq_.right.end(), [](const auto& f) { return !f.empty(); });
    if (it != seq_.right.end()) {
      const cv::Mat r = load_image(*it, false);
      if (r.size() != seq_.calib.right.size())
        throw std::runtime_error("calibration " + seq_.calib.source + " is for " + size_str(seq_.calib.right.size()) +
                                 " images but " + *it + " is " + size_str(r.size()));
    }
  } catch (const FrameError& e) {
    throw std::runtime_error(e.what());
  }
}

std::string StereoSequenceSource::describe() const {
  const auto& r = rectifier_.rectified();
  return seq_.description + " (" + std::to_string(seq_.left.size()) + " stereo frames, " + size_str(r.size) +
         (rectifier_.is_identity() ? ", rectified" : ", rectified on the fly") +
         (seq_.gt.empty() ? "" : ", ground truth") + ")";
}

bool StereoSequenceSource::next(Frame& frame) {
  if (next_ >= frame_count()) return false;
  const auto i = static_cast<size_t>(next_++);
  if (seq_.right[i].empty())
    throw FrameError(seq_.left[i] + ": no right image with this timestamp in the right camera's list");
  const cv::Mat l = load_image(seq_.left[i], color_);
  const cv::Mat r = load_image(seq_.right[i], color_);
  frame = Frame{};
  frame.index = static_cast<int64_t>(i);
  frame.utime = seq_.utimes[i];
  try {
    rectifier_.rectify(l, r, frame.left, frame.right);
  } catch (const std::invalid_argument& e) {
    throw FrameError(seq_.left[i] + ": " + e.what());
  }
  if (!seq_.gt.empty() && seq_.gt[i]) frame.gt_pose = GroundTruthPose{*seq_.gt[i] * T_raw_rect_, seq_.frame_id};
  return true;
}

}  // namespace aerie::capture
