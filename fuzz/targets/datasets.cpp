// The dataset and tracking-sequence readers on the input as a file, every reader on every input:
// aerie-capture's timestamps, TUM, EuRoC ground-truth CSV and KITTI poses (air/capture/dataset_io.hpp),
// the evaluation's TUM, KITTI and by-content trajectory readers (tools/eval/trajectory.hpp), and
// the OTB groundtruth.txt boxes of tracking sequences (air/track/eval/sequence.hpp).
#include "air/capture/dataset_io.hpp"
#include "air/track/eval/sequence.hpp"
#include "fuzz/fuzz_support.hpp"
#include "tools/eval/trajectory.hpp"

using namespace aerie;

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
  fuzz::quiet();
  const std::string path = fuzz::temp_file("dataset.txt", data, size);
  fuzz::refusal_ok([&] { capture::read_timestamps(path); });
  fuzz::refusal_ok([&] { capture::read_tum(path); });
  fuzz::refusal_ok([&] { capture::read_euroc_groundtruth(path); });
  fuzz::refusal_ok([&] { capture::read_kitti_poses(path); });
  fuzz::refusal_ok([&] { eval::read_tum(path); });
  fuzz::refusal_ok([&] { eval::read_kitti_poses(path, path); });  // the file as poses and as times.txt
  fuzz::refusal_ok([&] { eval::read_trajectory(path); });
  fuzz::refusal_ok([&] { track::eval::read_boxes(path); });
  return 0;
}
