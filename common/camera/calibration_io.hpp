#pragma once
// Calibration readers for the formats users bring: EuRoC/Kalibr sensor.yaml,
// KITTI calib.txt, and Aerie's own OpenCV-YAML stereo file (which it can also write).
// Every reader validates and throws std::runtime_error naming the file and field.
#include <string>

#include "common/camera/camera_model.hpp"

namespace aerie::camera {

// One EuRoC/Kalibr camera: intrinsics, distortion, resolution and T_BS (camera in body).
struct EurocCamera {
  CameraModel model;
  geometry::SE3 T_body_sensor;
};
EurocCamera read_euroc_camera(const std::string& sensor_yaml);

// mav0/cam0 and mav0/cam1 of an EuRoC ASL folder: T_right_left = inv(T_BS1) * T_BS0.
StereoCalibration read_euroc_stereo(const std::string& mav0_dir);

// KITTI odometry calib.txt (rectified projection matrices P0, P1 with or without
// "P0:" labels). KITTI images are rectified: no distortion, R = I, baseline -P1[0,3]/fx.
StereoCalibration read_kitti_stereo(const std::string& calib_txt, int width, int height);

// Aerie's stereo calibration in OpenCV FileStorage YAML (written by OpenCV, read with yaml-cpp):
//   width, height, left_K (3x3), left_D, left_model, right_K, right_D, right_model,
//   R (3x3), T (3x1): p_right = R * p_left + T (metres).
StereoCalibration read_opencv_stereo(const std::string& yaml);
void write_opencv_stereo(const StereoCalibration& calib, const std::string& yaml);

// Picks the reader from the path: a folder with cam0/sensor.yaml (or mav0/), a
// calib.txt, or a .yaml/.yml OpenCV file. width/height are needed for KITTI only.
StereoCalibration read_stereo_calibration(const std::string& path, int width = 0, int height = 0);

}  // namespace aerie::camera
