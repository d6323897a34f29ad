// The calibration readers (common/camera/calibration_io.hpp) on the input as a file: KITTI
// calib.txt, EuRoC/Kalibr sensor.yaml and Aerie's OpenCV-YAML stereo file, every reader on
// every input (each refuses the others' formats). What a reader returns must pass validate(),
// as its contract says.
#include "common/camera/calibration_io.hpp"
#include "fuzz/fuzz_support.hpp"

using namespace aerie;

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
  fuzz::quiet();
  const std::string path = fuzz::temp_file("calibration.yaml", data, size);
  fuzz::refusal_ok([&] { camera::read_kitti_stereo(path, 1241, 376).validate(); });
  fuzz::refusal_ok([&] { camera::read_euroc_camera(path).model.validate("sensor.yaml"); });
  fuzz::refusal_ok([&] { camera::read_opencv_stereo(path).validate(); });
  return 0;
}
