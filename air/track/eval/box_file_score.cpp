#include "air/track/eval/box_file_score.hpp"

#include <iomanip>
#include <sstream>
#include <stdexcept>

#include "air/track/eval/sequence.hpp"

namespace aerie::track::eval {

BoxFileScore score_box_file(const std::filesystem::path& boxes, const std::filesystem::path& groundtruth) {
  const auto predicted = read_boxes(boxes), truth = read_boxes(groundtruth);
  if (predicted.size() != truth.size())
    throw std::runtime_error(boxes.string() + ": " + std::to_string(predicted.size()) + " boxes for " +
                             std::to_string(truth.size()) + " frames in " + groundtruth.string() +
                             ": a box file needs one row per frame (NaN,NaN,NaN,NaN for a frame without a box; "
                             "aerie-log export writes one row per source frame)");
  BoxFileScore s;
  s.rows = static_cast<int>(truth.size());
  s.score = score(predicted, truth);
  for (size_t i = 0; i < truth.size(); ++i) s.missing += is_valid_box(truth[i]) && !is_valid_box(predicted[i]);
  return s;
}

std::string to_json(const BoxFileScore& s) {
  std::ostringstream os;
  os << std::setprecision(10);
  auto list = [&os](const std::vector<double>& v) {
    os << '[';
    for (size_t i = 0; i < v.size(); ++i) os << (i ? ", " : "") << v[i];
    os << ']';
  };
  os << "{\"rows\": " << s.rows << ", \"frames\": " << s.score.frames << ", \"missing\": " << s.missing
     << ", \"success_auc\": " << s.score.auc << ", \"precision_20px\": " << s.score.precision20
     << ", \"mean_centre_error_px\": " << s.score.mean_centre_error << ", \"iou_thresholds\": ";
  list(success_thresholds());
  os << ", \"success\": ";
  list(s.score.success);
  os << ", \"centre_error_thresholds_px\": ";
  list(precision_thresholds());
  os << ", \"precision\": ";
  list(s.score.precision);
  os << '}';
  return os.str();
}

}  // namespace aerie::track::eval
