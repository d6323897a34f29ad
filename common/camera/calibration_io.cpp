#include "common/camera/calibration_io.hpp"

#include "common/util/files.hpp"

#include <yaml-cpp/yaml.h>

#include <cmath>
#include <filesystem>
#include <opencv2/core/persistence.hpp>
#include <sstream>
#include <stdexcept>

namespace aerie::camera {
namespace fs = std::filesystem;

namespace {

[[noreturn]] void fail(const std::string& file, const std::string& msg) {
  throw std::runtime_error(file + ": " + msg);
}

std::string read_text(const std::string& path) { return util::read_regular_file(path, "calibration file"); }

std::vector<double> yaml_doubles(const YAML::Node& root, const std::string& key, const std::string& file,
                                 size_t expected = 0) {
  const YAML::Node n = root[key];
  if (!n) fail(file, "missing field '" + key + "'");
  std::vector<double> v;
  try {
    v = n.as<std::vector<double>>();
  } catch (const YAML::Exception&) {
    fail(file, "field '" + key + "' is not a list of numbers");
  }
  if (expected && v.size() != expected)
    fail(file, "field '" + key + "' needs " + std::to_string(expected) + " numbers, got " + std::to_string(v.size()));
  return v;
}

// A YAML file as OpenCV writes it (EuRoC's sensor.yaml, our stereo file), read with yaml-cpp:
// OpenCV 4.6's own parser never returned on a 566-byte malformed file (fuzzing, docs/fuzz.md).
// Its "%YAML:1.0" directive, which yaml-cpp rejects, is dropped; "!!opencv-matrix" tags are
// ignored. The root must be a map.
YAML::Node load_opencv_yaml(const std::string& path) {
  std::string text = read_text(path);
  if (text.rfind("%YAML:", 0) == 0) text = text.substr(std::min(text.size(), text.find('\n') + 1));
  YAML::Node root;
  try {
    root = YAML::Load(text);
  } catch (const YAML::Exception& e) {
    fail(path, std::string("YAML parse error: ") + e.what());
  }
  if (!root.IsMap()) fail(path, "is not a map of fields");
  return root;
}

// An OpenCV matrix node {rows, cols, dt, data}: rows x cols numbers, row-major, at most 64 (OpenCV
// allocated what a corrupt `cols` declared, 48 GB, before reading the data).
Eigen::MatrixXd opencv_matrix(const YAML::Node& root, const std::string& key, const std::string& file) {
  const YAML::Node n = root[key];
  if (!n) fail(file, "missing field '" + key + "'");
  if (!n.IsMap()) fail(file, "field '" + key + "' is not a matrix (rows, cols, data)");
  int rows = 0, cols = 0;
  try {
    rows = n["rows"].as<int>();
    cols = n["cols"].as<int>();
  } catch (const YAML::Exception&) {
    fail(file, "field '" + key + "' needs integer rows and cols");
  }
  if (rows < 0 || cols < 0 || rows > 64 || cols > 64 || rows * cols > 64)
    fail(file, "field '" + key + "' is not a small matrix");
  if (rows * cols == 0) return Eigen::MatrixXd(rows, cols);  // e.g. no distortion coefficients
  const auto data = yaml_doubles(n, "data", file + ": " + key, static_cast<size_t>(rows * cols));
  Eigen::MatrixXd m(rows, cols);
  for (int i = 0; i < rows * cols; ++i) m(i / cols, i % cols) = data[static_cast<size_t>(i)];
  return m;
}

}  // namespace

EurocCamera read_euroc_camera(const std::string& sensor_yaml) {
  const YAML::Node root = load_opencv_yaml(sensor_yaml);
  EurocCamera cam;
  const std::string model = root["camera_model"] ? root["camera_model"].as<std::string>() : "";
  if (model != "pinhole") fail(sensor_yaml, "camera_model must be 'pinhole', got '" + model + "'");
  const auto res = yaml_doubles(root, "resolution", sensor_yaml, 2);
  const auto intr = yaml_doubles(root, "intrinsics", sensor_yaml, 4);
  for (int i = 0; i < 2; ++i)  // a size, not any double (4e56 would not fit an int)
    if (!(res[i] >= 1 && res[i] <= 65535 && res[i] == std::floor(res[i])))
      fail(sensor_yaml, "resolution must be two whole numbers in [1, 65535], got " + std::to_string(res[i]));
  cam.model.width = static_cast<int>(res[0]);
  cam.model.height = static_cast<int>(res[1]);
  cam.model.fx = intr[0];
  cam.model.fy = intr[1];
  cam.model.cx = intr[2];
  cam.model.cy = intr[3];
  const std::string dist = root["distortion_model"] ? root["distortion_model"].as<std::string>() : "none";
  try {
    cam.model.distortion = distortion_from_string(dist);
  } catch (const std::invalid_argument& e) {
    fail(sensor_yaml, e.what());
  }
  if (cam.model.distortion != Distortion::None)
    cam.model.coeffs = yaml_doubles(root, "distortion_coefficients", sensor_yaml);
  const YAML::Node tbs = root["T_BS"];
  if (!tbs) fail(sensor_yaml, "missing field 'T_BS'");
  const auto data = yaml_doubles(tbs, "data", sensor_yaml, 16);
  Eigen::Matrix4d T;
  for (int i = 0; i < 16; ++i) T(i / 4, i % 4) = data[i];
  cam.T_body_sensor = geometry::SE3(T);
  cam.model.validate(sensor_yaml);
  return cam;
}

StereoCalibration read_euroc_stereo(const std::string& mav0_dir) {
  fs::path root(mav0_dir);
  if (!fs::exists(root / "cam0") && fs::exists(root / "mav0")) root /= "mav0";
  const auto c0 = read_euroc_camera((root / "cam0" / "sensor.yaml").string());
  const auto c1 = read_euroc_camera((root / "cam1" / "sensor.yaml").string());
  StereoCalibration s;
  s.left = c0.model;
  s.right = c1.model;
  s.T_right_left = c1.T_body_sensor.inverse() * c0.T_body_sensor;
  s.source = (root / "cam{0,1}" / "sensor.yaml").string();
  s.validate();
  return s;
}

StereoCalibration read_kitti_stereo(const std::string& calib_txt, int width, int height) {
  std::istringstream in(read_text(calib_txt));
  std::vector<std::vector<double>> rows;
  std::string line;
  int lineno = 0;
  while (std::getline(in, line) && rows.size() < 2) {
    ++lineno;
    if (line.find_first_not_of(" \t\r") == std::string::npos) continue;
    const auto colon = line.find(':');
    if (colon != std::string::npos) {
      const std::string label = line.substr(0, colon);
      if (label != "P0" && label != "P1") continue;  // full KITTI files also hold P2, P3, Tr
      line = line.substr(colon + 1);
    }
    std::istringstream ss(line);
    std::vector<double> v;
    double x;
    while (ss >> x) v.push_back(x);
    if (v.size() != 12) fail(calib_txt, "line " + std::to_string(lineno) + ": expected 12 numbers of a 3x4 projection matrix, got " + std::to_string(v.size()));
    rows.push_back(v);
  }
  if (rows.size() < 2) fail(calib_txt, "needs the projection matrices P0 and P1");
  const auto& P0 = rows[0];
  const auto& P1 = rows[1];
  if (width <= 0 || height <= 0) fail(calib_txt, "the image size is needed to use a KITTI calibration");
  CameraModel cam;
  cam.width = width;
  cam.height = height;
  cam.fx = P0[0];
  cam.fy = P0[5];
  cam.cx = P0[2];
  cam.cy = P0[6];
  StereoCalibration s;
  s.left = cam;
  s.right = cam;
  s.right.cx = P1[2];
  s.right.cy = P1[6];
  const double baseline = -P1[3] / P1[0];
  // Rectified pair: the right camera sits at +baseline along x of the left one.
  s.T_right_left = geometry::SE3(Eigen::Matrix3d::Identity(), Eigen::Vector3d(-baseline, 0, 0));
  s.source = calib_txt;
  s.validate();
  return s;
}

StereoCalibration read_opencv_stereo(const std::string& yaml) {
  const YAML::Node root = load_opencv_yaml(yaml);
  auto scalar = [&](const char* key) {
    if (!root[key]) fail(yaml, std::string("missing field '") + key + "'");
    try {
      return root[key].as<int>();
    } catch (const YAML::Exception&) {
      fail(yaml, std::string("field '") + key + "' is not an integer");
    }
  };
  StereoCalibration s;
  s.source = yaml;
  const int w = scalar("width");
  const int h = scalar("height");
  auto camera = [&](const std::string& side) {
    CameraModel c;
    c.width = w;
    c.height = h;
    const Eigen::MatrixXd K = opencv_matrix(root, side + "_K", yaml);
    if (K.rows() != 3 || K.cols() != 3) fail(yaml, "field '" + side + "_K' must be a 3x3 matrix");
    c.fx = K(0, 0);
    c.fy = K(1, 1);
    c.cx = K(0, 2);
    c.cy = K(1, 2);
    std::string model = "none";
    if (root[side + "_model"]) {
      try {
        model = root[side + "_model"].as<std::string>();
        c.distortion = distortion_from_string(model);
      } catch (const std::exception&) {
        fail(yaml, "field '" + side + "_model' is not a distortion model: '" + model + "'");
      }
    }
    if (root[side + "_D"]) {
      const Eigen::MatrixXd D = opencv_matrix(root, side + "_D", yaml);
      c.coeffs.assign(D.data(), D.data() + D.size());
    }
    return c;
  };
  s.left = camera("left");
  s.right = camera("right");
  const Eigen::MatrixXd R = opencv_matrix(root, "R", yaml);
  const Eigen::MatrixXd T = opencv_matrix(root, "T", yaml);
  if (R.rows() != 3 || R.cols() != 3) fail(yaml, "field 'R' must be a 3x3 matrix");
  if (T.size() != 3) fail(yaml, "field 'T' must hold 3 numbers");
  s.T_right_left = geometry::SE3(Eigen::Matrix3d(R), Eigen::Vector3d(T(0), T(1), T(2)));
  s.validate();
  return s;
}

void write_opencv_stereo(const StereoCalibration& c, const std::string& yaml) {
  cv::FileStorage out(yaml, cv::FileStorage::WRITE);
  if (!out.isOpened()) fail(yaml, "cannot write file");
  out << "width" << c.left.width << "height" << c.left.height;
  out << "left_K" << cv::Mat(c.left.K()) << "left_D" << c.left.D() << "left_model" << to_string(c.left.distortion);
  out << "right_K" << cv::Mat(c.right.K()) << "right_D" << c.right.D() << "right_model" << to_string(c.right.distortion);
  cv::Mat R(3, 3, CV_64F), T(3, 1, CV_64F);
  const Eigen::Matrix3d Re = c.T_right_left.rotation_matrix();
  for (int i = 0; i < 9; ++i) R.at<double>(i / 3, i % 3) = Re(i / 3, i % 3);
  for (int i = 0; i < 3; ++i) T.at<double>(i) = c.T_right_left.translation()[i];
  out << "R" << R << "T" << T;
}

StereoCalibration read_stereo_calibration(const std::string& path, int width, int height) {
  const fs::path p(path);
  if (!fs::exists(p)) fail(path, "no such file or folder");
  if (fs::is_directory(p)) {
    if (fs::exists(p / "cam0" / "sensor.yaml") || fs::exists(p / "mav0" / "cam0" / "sensor.yaml"))
      return read_euroc_stereo(path);
    if (fs::exists(p / "calib.txt")) return read_kitti_stereo((p / "calib.txt").string(), width, height);
    fail(path, "folder holds neither cam0/sensor.yaml (EuRoC) nor calib.txt (KITTI)");
  }
  const auto ext = p.extension().string();
  if (ext == ".txt") return read_kitti_stereo(path, width, height);
  if (ext == ".yaml" || ext == ".yml") return read_opencv_stereo(path);
  fail(path, "unknown calibration format (expected a EuRoC folder, a KITTI calib.txt or an OpenCV .yaml)");
}

}  // namespace aerie::camera
