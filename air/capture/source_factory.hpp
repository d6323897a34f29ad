#pragma once
// Builds a FrameSource from its options (the `source:` section of config/capture.yaml).
#include <cstdint>
#include <memory>
#include <string>

#include "air/capture/frame_source.hpp"

namespace aerie::capture {

struct SimSourceOptions {
  uint64_t seed = 1;                  // world texture/layout seed
  std::string trajectory = "demo";    // "demo" (take-off, survey, approach, descent), "survey" or
                                      // "landing" (approach + descent, camera looking down)
  double speed = 0.8;                 // m/s along the trajectory
  int loops = 2;                      // survey: number of loops
  double noise_sigma = 0.0;           // image noise, gray levels
  int64_t start_utime = -1;           // utime of the first frame; -1 = wall clock at start
};

struct SourceOptions {
  std::string type = "sim";   // sim | v4l2 | video | folder | euroc | kitti
  std::string path;           // folder, file, or device ("/dev/video0" or "0")
  std::string right;          // v4l2: second device of a stereo pair
  std::string calib;          // v4l2: stereo calibration file/folder
  std::string timestamps;     // folder: timestamps file (seconds per line)
  std::string groundtruth;    // euroc: TUM body trajectory when the folder has no state_groundtruth_estimate0;
                              // kitti: a poses file (NN.txt); refused for the other sources
  double fps = 20.0;          // folder without timestamps / video without rate / v4l2 request / sim
  int width = 0, height = 0;  // v4l2: requested size; sim: rendered size (0 = default 376x240)
  bool color = false;         // read colour images (gray otherwise)
  SimSourceOptions sim;
};

// Throws std::runtime_error / std::invalid_argument naming the file, folder or option.
std::unique_ptr<FrameSource> make_source(const SourceOptions& options);

}  // namespace aerie::capture
