// The calibration readers (common/camera/calibration_io.hpp) on the input as a file: KITTI
// calib.txt, EuRoC/Kalibr sensor.yaml and Aerie's OpenCV-YAML stereo file, every reader on
// every input (each refuses the others' formats; each validates what it returns). A stereo
// calibration a reader accepted then builds the rectifier, as aerie-capture and the dataset
// readers do, up to 2^19 pixels (KITTI's 1241 x 376 included; its maps cost per pixel, and
// CameraModel::validate bounds the size): an exception there is a refusal at start-up, a crash
// or a sanitizer report is a finding.
#include "common/camera/calibration_io.hpp"
#include "common/camera/rectification.hpp"
#include "fuzz/fuzz_support.hpp"

using namespace aerie;

namespace {

void rectify(const camera::StereoCalibration& calib) {
  if (int64_t{calib.left.width} * calib.left.height > (1 << 19)) return;
  try {
    camera::StereoRectifier rectifier(calib);
  } catch (const std::exception&) {
  }
}

}  // namespace

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
  fuzz::quiet();
  const std::string path = fuzz::temp_file("calibration.yaml", data, size);
  fuzz::refusal_ok([&] { rectify(camera::read_kitti_stereo(path, 1241, 376)); });
  fuzz::refusal_ok([&] { camera::read_euroc_camera(path).model.validate("sensor.yaml"); });
  fuzz::refusal_ok([&] { rectify(camera::read_opencv_stereo(path)); });
  return 0;
}
